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

IDLE = float(os.environ.get("TRACKBENCH_DAEMON_IDLE", 900.0))   # s without a command, then it leaves
TICK = 0.5      # s: how often it looks at its socket file (removed: it leaves) and its copies
LOOK = 5.0      # s: how often it looks at the package's sources and the libraries (5 ms a look)
MAX_REQUEST = 1 << 20   # bytes
# the kinds of model whose kernels a daemon holds (where numba's cache has them), as scenario dicts
KINDS = ({}, {"track": {"layout": "closed"}, "preset": "damped", "drive": {"kind": "speed"}})
TINY = {"duration": 1e-3, "output_interval": 1e-3}
# what rerun imports that starts no thread (a third of its import): loaded here, once; with
# the progress display and the command line's conversion of values (pydantic), loaded late
RERUN_LIBRARIES = ("psutil", "PIL.Image", "attr", "attrs", "typing_extensions", "colorsys", "asyncio")


def main(path):
    """Load, listen at ``path`` (the socket named by the key of the command that started it),
    serve; remove the socket when leaving."""
    from .client import starting, unusable
    why = None
    try:
        left = _preload()
        threads = _threads()
        if threads != 1:
            why = f"{threads} threads after loading the libraries (a fork needs one)"
        else:
            _describe(path)
            listener, inode = _listen(path)
    except Exception as e:  # noqa: BLE001  (no daemon then: commands run in their own processes)
        why = f"{type(e).__name__}: {e}"
    finally:
        Path(starting(Path(path))).unlink(missing_ok=True)
    if why is not None:   # said once: the commands of this key start no daemon again
        Path(unusable(Path(path))).write_text(why + "\n")
        return
    _serve(listener, path, inode, left)


def _threads():
    return len(os.listdir("/proc/self/task"))


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

    def __init__(self, path, inode, left):
        from .address import stamp
        self.path, self.inode, self.left, self.code = path, inode, left, stamp()
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
            if stamp() != self.code:
                return True
        if self.left and self.served:
            self.served, self.left = False, warm_kinds(self.left)
            return _threads() != 1   # it could no longer fork safely
        return False


def _serve(listener, path, inode, left):
    copies, idle = set(), _Idle(path, inode, left)
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
    """(request, its three descriptors) from a command of this user; (None, fds) otherwise."""
    conn.settimeout(5.0)
    try:
        uid = struct.unpack("3i", conn.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, 12))[1]
        data, fds, _, _ = socket.recv_fds(conn, 65536, 3)
        if uid != os.getuid() or len(data) < 4 or len(fds) != 3:
            return None, fds
        size = struct.unpack("!I", data[:4])[0]
        data = data[4:]
        while len(data) < min(size, MAX_REQUEST):
            more = conn.recv(65536)
            if not more:
                return None, fds
            data += more
        return json.loads(data[:size]), fds
    except (OSError, ValueError, struct.error):
        return None, []


def _copy(conn, listener, request, fds, path):
    """The daemon's copy that runs one command, then exits with its status."""
    code, started = 1, time.monotonic()
    try:
        listener.close()
        conn.settimeout(None)
        os.setpgid(0, 0)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        for i, fd in enumerate(fds):
            os.dup2(fd, i)
            os.close(fd)
        _as_the_command(request)
        conn.sendall(f"pid {os.getpid()}\n".encode())
        _interrupt_on(conn)
        from .. import cli
        code = cli.command(request["argv"])
    except SystemExit as e:
        code = e.code if isinstance(e.code, int) else int(e.code is not None)
    except BaseException:  # noqa: BLE001  (whatever it was, the command hears a status)
        traceback.print_exc()
    finally:
        _log(path, request, code, started)
        _end(conn, code)


def _as_the_command(request):
    """The command's folder, environment and standard streams (line-buffered on a terminal)."""
    os.chdir(request["cwd"])
    os.environ.clear()
    os.environ.update(request["env"])
    tempfile.tempdir = None
    from ..study import warming
    warming.WARM_PROCESS = True
    sys.argv = ["trackbench", *request["argv"]]
    for fd, name in ((1, "stdout"), (2, "stderr")):
        raw = io.FileIO(fd, "w", closefd=False)
        stream = io.TextIOWrapper(raw, encoding="utf-8", errors="backslashreplace",
                                  line_buffering=os.isatty(fd), write_through=fd == 2)
        setattr(sys, name, stream)
        setattr(sys, f"__{name}__", stream)
    sys.stdin = sys.__stdin__ = io.TextIOWrapper(io.FileIO(0, "r", closefd=False), encoding="utf-8")


def _interrupt_on(conn):
    """A byte from the command (its Ctrl-C) or its end (killed) interrupts this copy and every
    process it started, as a Ctrl-C would: SIGIO on the socket, SIGINT to the group."""
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
    signal.signal(signal.SIGIO, signal.SIG_IGN)
    try:
        conn.sendall(f"exit {code}\n".encode())
    except OSError:
        pass
    os._exit(code)
