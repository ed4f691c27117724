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
# what rerun imports that starts no thread (a third of its import): loaded here, once; with
# the progress display and the command line's conversion of values (pydantic), loaded late
RERUN_LIBRARIES = ("psutil", "PIL.Image", "attr", "attrs", "typing_extensions", "colorsys", "asyncio")


def main(path):
    """Load, listen at ``path`` (the socket named by the key of the command that started it),
    serve; remove the socket when leaving."""
    from .client import starting, unusable
    why = None
    try:
        _preload()
        threads = len(os.listdir("/proc/self/task"))
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
    _serve(listener, path, inode)


def _preload():
    """What `trackbench run` and `study run` load: the command line, the package, xarray,
    pandas, netCDF4, and the compiled kernels of the paper's model and of the closed track,
    with a tiny run of each written to a netCDF file (HDF5's set-up)."""
    from ..startup import without_dask_arrays
    without_dask_arrays()   # a daemon serves no dask study (address.eligible)
    import netCDF4  # noqa: F401
    import pandas  # noqa: F401
    import xarray  # noqa: F401

    import trackbench
    from trackbench import cli, single_run  # noqa: F401
    from trackbench.output import write_netcdf
    from trackbench.quantities import run_summary
    from trackbench.study import executors, progress, runner, summary  # noqa: F401
    short = {"duration": 1e-3, "output_interval": 1e-3}
    closed = {"track": {"layout": "closed"}, "preset": "damped", "drive": {"kind": "speed"}, **short}
    for sc in (trackbench.Scenario.paper(**short), trackbench.Scenario.from_dict(closed)):
        ds = trackbench.simulate(sc)
        run_summary(ds)
        with tempfile.TemporaryDirectory() as tmp:
            write_netcdf(ds, os.path.join(tmp, "warm.nc"))
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


def _serve(listener, path, inode):
    from .address import stamp
    copies, idle_since, code, looked = set(), time.monotonic(), stamp(), time.monotonic()
    listener.settimeout(TICK)
    while True:
        _reap(copies)
        if copies:
            idle_since = time.monotonic()
        try:
            conn, _ = listener.accept()
        except socket.timeout:
            if not _still_ours(path, inode) or (not copies and time.monotonic() - idle_since > IDLE):
                break
            if not copies and time.monotonic() - looked > LOOK:
                looked = time.monotonic()
                if stamp() != code:   # edited or upgraded: no command will be handed to it again
                    break
            continue
        with conn:
            request, fds = _receive(conn)
            if request is not None:
                pid = os.fork()
                if pid == 0:
                    _copy(conn, listener, request, fds, path)   # never returns
                copies.add(pid)
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
