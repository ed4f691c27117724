"""The daemon: a process that loads what the commands need once, then forks a copy of itself
for each command handed to it (client.py), until IDLE seconds pass without one.

It must have a single thread whenever it forks (a fork of a threaded process may inherit a
lock another thread held): so it sets the libraries' threads off before it loads them
(warming.single_threaded_libraries), never imports rerun (its import starts threads; each
copy that records imports it), and checks its thread count before it serves. A copy runs the
command as the command's own process would (cli.command) in the command's folder, with its
environment and its terminal, in a process group of its own: a Ctrl-C passed on by the
command is a SIGINT to that group, the copy and the workers it forked, as a terminal would
send it."""

import fcntl
import io
import json
import os
import signal
import socket
import struct
import sys
import tempfile
import time
import traceback
from pathlib import Path

from ..startup import threads as thread_count
from ..study.warming import TINY

IDLE = float(os.environ.get("TRACKBENCH_DAEMON_IDLE", 900.0))   # s without a command, then it leaves
TICK = 0.5      # s: how often it looks at its socket file (removed: it leaves) and its copies
LOOK = 5.0      # s: how often it looks at the package's sources and the libraries (5 ms a look)
MAX_REQUEST = 1 << 20   # bytes
# the kinds of model whose kernels a daemon holds (where numba's cache has them), as scenario dicts
KINDS = ({}, {"track": {"layout": "closed"}, "preset": "damped", "drive": {"kind": "speed"}})
# what rerun imports that starts no thread (a third of its import): loaded here, once; with
# the progress display and the command line's conversion of values (pydantic), loaded late
RERUN_LIBRARIES = ("psutil", "PIL.Image", "attr", "attrs", "typing_extensions", "colorsys", "asyncio")


def main(path, code):
    """Load, listen at ``path`` (the socket named by the key of the command that started it),
    serve; remove the socket when leaving. ``code``: that command's address.stamp(), the sources
    and libraries it ran: should they have changed since, this daemon would not be what its
    key says, and it does not start. A daemon that cannot fork safely says why once (then no
    daemon is started for its key again); a failed start is tried again a minute later."""
    from .address import stamp
    from .client import PATHS, starting, unusable
    paths = json.loads(os.environ.pop(PATHS, "null"))
    if stamp(paths) != code:
        return
    left = _preload()   # an exception leaves the start's mark: no new start for a minute
    threads = thread_count()
    if threads != 1:
        Path(unusable(Path(path))).write_text(f"{threads} threads after loading the libraries "
                                              "(a process that forks needs one)\n")
        Path(starting(Path(path))).unlink(missing_ok=True)
        return
    listener, inode = _listen(path)
    _describe(path)
    Path(starting(Path(path))).unlink(missing_ok=True)
    _serve(listener, path, inode, left, paths, code)


def _preload():
    """What `trackbench run` and `study run` load: the command line, the package, xarray,
    pandas, netCDF4, the writers of the summary, and the compiled kernels of the paper's model
    and of the closed track where numba's cache has them. Returns the kinds left to load."""
    from ..startup import without_dask_arrays
    without_dask_arrays()   # a daemon serves no dask study (address.eligible)
    import netCDF4  # noqa: F401
    import pandas
    import xarray  # noqa: F401

    from trackbench import cli, single_run  # noqa: F401
    from trackbench.study import executors, progress, runner, summary  # noqa: F401
    for name in ("pyarrow", "rich.progress", "typer._adapters") + RERUN_LIBRARIES:   # where installed
        try:
            __import__(name)
        except ImportError:
            pass
    table = pandas.DataFrame({"a": [1.0], "b": ["x"]})   # the summary's writers load their parts
    table.to_csv(io.StringIO())
    try:
        table.to_parquet(io.BytesIO())
    except ImportError:
        pass
    return warm_kinds(list(KINDS))


def warm_kinds(kinds):
    """Load each kind's kernels from numba's cache with a tiny run of it, its summary and its
    netCDF file (HDF5's set-up). Never compile: a daemon compiling for a minute unasked would
    take a core from the user's next commands; a kind not in the cache yet is left for later
    (a command may compile it meanwhile). Returns the kinds left."""
    import trackbench
    from trackbench.output import write_netcdf
    from trackbench.quantities import run_summary
    left = []
    for kind in kinds:
        try:
            with _cached_only():
                ds = trackbench.simulate(trackbench.Scenario.from_dict({**kind, **TINY}))
            run_summary(ds)
            with tempfile.TemporaryDirectory() as tmp:
                write_netcdf(ds, os.path.join(tmp, "warm.nc"))
        except Exception:  # noqa: BLE001  (not cached, or not runnable here: the command will say)
            left.append(kind)
    return left


class _Uncached(Exception):
    pass


class _cached_only:
    """While active, numba's start of a compilation (it loads from its cache without one)
    raises _Uncached instead."""

    def __enter__(self):
        from numba.core import event

        class Refuse(event.Listener):
            def on_start(self, ev):
                raise _Uncached(str(ev.data))

            def on_end(self, ev):
                pass

        self.listener = Refuse()
        event.register("numba:compile", self.listener)
        return self

    def __exit__(self, *exc):
        from numba.core import event
        event.unregister("numba:compile", self.listener)
        return False


def _describe(path):
    """PATH.json beside the socket: who this daemon is (`trackbench daemon status` reads it)."""
    import trackbench
    info = {"pid": os.getpid(), "started": time.time(), "python": sys.executable,
            "package": os.path.dirname(trackbench.__file__), "version": trackbench.__version__}
    tmp = f"{path}.{os.getpid()}.json.tmp"
    with open(tmp, "w") as f:
        json.dump(info, f)
    os.replace(tmp, _beside(path, ".json"))


def _beside(path, suffix):
    return os.path.splitext(os.fspath(path))[0] + suffix


def _log(path, request, code, started):
    """One line a command in PATH.log: when it ended, the copy's pid, its status, seconds, argv."""
    line = json.dumps({"ended": time.time(), "pid": os.getpid(), "exit": code,
                       "seconds": round(time.monotonic() - started, 3), "argv": request.get("argv")})
    try:
        with open(_beside(path, ".log"), "a") as f:
            f.write(line + "\n")
    except OSError:
        pass


def _listen(path):
    """A socket bound at ``path`` (built under another name and renamed: a command connects to
    a daemon that is ready or to none), and its inode."""
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    tmp = f"{path}.{os.getpid()}.tmp"
    listener.bind(tmp)
    os.chmod(tmp, 0o600)
    listener.listen(16)
    os.rename(tmp, path)
    return listener, os.stat(path).st_ino


class _Idle:
    """What the daemon does between commands: it leaves when its socket is gone, after IDLE
    seconds, or once its sources or libraries changed (no command will be handed to it again);
    after a command, it loads the kinds that command may have compiled."""

    def __init__(self, path, inode, left, paths, code):
        self.path, self.inode, self.left, self.paths, self.code = path, inode, left, paths, code
        self.since = self.looked = time.monotonic()
        self.served = False

    def busy(self):
        self.since, self.served = time.monotonic(), True

    def leave(self):
        from .address import stamp
        now = time.monotonic()
        if not _still_ours(self.path, self.inode) or now - self.since > IDLE:
            return True
        if now - self.looked > LOOK:
            self.looked = now
            if stamp(self.paths) != self.code:
                return True
        if self.left and self.served:
            self.served, self.left = False, warm_kinds(self.left)
            return thread_count() != 1   # it could no longer fork safely
        return False


def _serve(listener, path, inode, left, paths, code):
    copies, idle = set(), _Idle(path, inode, left, paths, code)
    listener.settimeout(TICK)
    while True:
        _reap(copies)
        if copies:
            idle.busy()
        try:
            conn, _ = listener.accept()
        except socket.timeout:
            if not copies and idle.leave():
                break
            continue
        with conn:
            request, fds = _receive(conn)
            if request is not None:
                pid = os.fork()
                if pid == 0:
                    _copy(conn, listener, request, fds, path)   # never returns
                copies.add(pid)
                idle.busy()
            for fd in fds:
                os.close(fd)
    if _still_ours(path, inode):
        os.unlink(path)
    try:
        with open(_beside(path, ".json")) as f:
            mine = json.load(f).get("pid") == os.getpid()
    except (OSError, ValueError):
        mine = False
    if mine:   # not a newer daemon's of the same key
        for suffix in (".json", ".log"):
            Path(_beside(path, suffix)).unlink(missing_ok=True)


def _reap(copies):
    for pid in list(copies):
        try:
            done, _ = os.waitpid(pid, os.WNOHANG)
        except ChildProcessError:
            done = pid
        if done:
            copies.discard(pid)


def _still_ours(path, inode):
    """Is ``path`` still this daemon's socket (not removed by `trackbench daemon stop`)?"""
    try:
        return os.stat(path).st_ino == inode
    except OSError:
        return False


def _receive(conn):
    """(request, its three descriptors) from a command of this user; (None, fds) otherwise. The
    descriptors come only once this daemon has said it is ready: a command that gave up on a
    daemon that did not answer (stopped) has sent none, so none is held here for it."""
    conn.settimeout(5.0)
    fds = []
    try:
        uid = struct.unpack("3i", conn.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, 12))[1]
        size = struct.unpack("!I", _exactly(conn, 4))[0]
        if uid != os.getuid() or size > MAX_REQUEST:
            return None, fds
        request = json.loads(_exactly(conn, size))
        conn.sendall(b"ready\n")
        _, fds, _, _ = socket.recv_fds(conn, 1, 3)
        return (request if len(fds) == 3 else None), fds
    except (OSError, ValueError, struct.error):
        return None, fds


def _exactly(conn, n):
    data = b""
    while len(data) < n:
        more = conn.recv(min(n - len(data), 65536))
        if not more:
            raise ValueError("the command closed its connection")
        data += more
    return data


class _Refused(Exception):
    """The copy cannot be the command's process (a limit or a priority it cannot take on)."""


def _copy(conn, listener, request, fds, path):
    """The daemon's copy that runs one command, then exits with its status (never returns into
    the daemon's loop: whatever happens, it ends in os._exit)."""
    code, started, ran = 1, time.monotonic(), False
    try:
        try:
            listener.close()
            conn.settimeout(None)
            os.setpgid(0, 0)
            _take_on(request)
            for i, fd in enumerate(fds):
                os.dup2(fd, i)
                os.close(fd)
            _as_the_command(request)
            conn.sendall(f"pid {os.getpid()}\n".encode())
            ran = True
            _interrupt_on(conn)
            from .. import cli
            code = cli.command(request["argv"])
        except _Refused as e:   # the command runs in its own process instead
            conn.sendall(f"refused: {e}\n".encode())
        except SystemExit as e:
            code = e.code if isinstance(e.code, int) else int(e.code is not None)
            if isinstance(e.code, str):   # as the interpreter says it
                print(e.code, file=sys.stderr)
        except BaseException:  # noqa: BLE001  (whatever it was, the command hears a status)
            traceback.print_exc()
        finally:
            for sig in (signal.SIGINT, signal.SIGIO):   # a second Ctrl-C cannot cut the ending short
                signal.signal(sig, signal.SIG_IGN)
            if ran:
                _log(path, request, code, started)
                _end(conn, code)
    finally:
        os._exit(code)


def _take_on(request):
    """The command's process attributes: its cgroup (else refused), umask, nice level (never
    higher a priority than the daemon's), processors, resource limits and ignored signals."""
    import resource
    try:
        with open("/proc/self/cgroup") as f:
            if f.read() != request.get("cgroup", ""):
                raise _Refused("the command runs in another cgroup")
    except OSError:
        pass
    os.umask(int(request["umask"]))
    nice, now = int(request["nice"]), os.getpriority(os.PRIO_PROCESS, 0)
    if nice < now:
        raise _Refused(f"the command's nice level {nice} is below the daemon's {now}")
    os.setpriority(os.PRIO_PROCESS, 0, nice)
    try:
        os.sched_setaffinity(0, request["cpus"])
        for name, limit in request["limits"].items():
            if hasattr(resource, name):
                resource.setrlimit(getattr(resource, name), tuple(limit))
    except (OSError, ValueError) as e:
        raise _Refused(f"its processors or resource limits: {e}") from None
    signal.signal(signal.SIGINT, signal.default_int_handler)
    for sig in request.get("ignored", []):
        signal.signal(sig, signal.SIG_IGN)


def _as_the_command(request):
    """The command's folder, environment and standard streams (line-buffered on a terminal)."""
    os.chdir(request["cwd"])
    os.environ.clear()
    os.environ.update(request["env"])
    tempfile.tempdir = None
    from ..study import warming
    warming.WARM_PROCESS = True
    sys.argv = ["trackbench", *request["argv"]]
    for fd, name in ((1, "stdout"), (2, "stderr")):   # buffered: a short write is written whole
        stream = open(fd, "w", buffering=1 if fd == 2 or os.isatty(fd) else -1, encoding="utf-8",
                      errors="backslashreplace", closefd=False)
        setattr(sys, name, stream)
        setattr(sys, f"__{name}__", stream)
    sys.stdin = sys.__stdin__ = io.TextIOWrapper(io.FileIO(0, "r", closefd=False), encoding="utf-8")


def _interrupt_on(conn):
    """A byte from the command (its Ctrl-C) or its end (killed, or gone before this copy began)
    interrupts this copy and every process it started, as a Ctrl-C would: SIGIO on the socket,
    SIGINT to the group."""
    def heard(*_):
        try:
            conn.recv(64, socket.MSG_DONTWAIT)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            pass
        os.killpg(0, signal.SIGINT)

    signal.signal(signal.SIGIO, heard)
    fd = conn.fileno()
    fcntl.fcntl(fd, fcntl.F_SETOWN, os.getpid())
    fcntl.fcntl(fd, fcntl.F_SETFL, fcntl.fcntl(fd, fcntl.F_GETFL) | os.O_ASYNC)
    from ..study import warming
    warming.INHERITED[:] = [fd]   # forked workers close it: the command's end is this copy's
    heard()   # SIGIO says what changes: a command already gone is seen here


def _end(conn, code):
    from ..study import warming
    try:
        warming.stop_server()   # a pool forked for the command: its workers end with it
    except Exception:  # noqa: BLE001
        pass
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    try:
        conn.sendall(f"exit {code}\n".encode())
    except OSError:
        pass
