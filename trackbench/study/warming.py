"""The workers' fork server from the command's side: its start and stop, what the command
tells it to warm (preload.py) and where the server says that it compiles: the one protocol
both sides share, light enough for the command to import (no numba).

The command starts the server before it reads the study file (the server's imports, about
a second, then overlap the validation and the expansion of the runs), so the server cannot
be told on its command line which kinds of model the runs need: it is told LATER, through
warm_file(), which the command writes (announce) once it knows the runs, and which the
server waits for after its imports."""

import json
import os
import weakref
from pathlib import Path

from ..startup import single_threaded_libraries, threads

WARM = "TRACKBENCH_WARM"    # the server's spec (JSON): {"scenarios": [...]} or {"file": path}; "flag"
MAX_WARM = 4
LATER = "later"             # start_workers(warm=LATER): the kinds come through warm_file()
TINY = {"duration": 1e-3, "output_interval": 1e-3}   # the run that loads a kind's kernels


def warm_kinds(scenarios):
    """One scenario dict of each kind of compiled model among a study's runs (solver, track
    layout and method each compile their own time loop; the soil, friction and contact
    options are flags inside it), at most MAX_WARM."""
    kinds = {}
    for d in scenarios:
        kinds.setdefault((d.get("solver"), d.get("track", {}).get("layout"), d.get("method")), d)
    return list(kinds.values())[:MAX_WARM]


def _tmp(kind):
    import tempfile
    return Path(tempfile.gettempdir()) / f"trackbench-{kind}-{os.getpid()}.json"


def compile_flag():
    """The file where this command's fork server says that it compiles (the progress shows it)."""
    return _tmp("compiling")


def warm_file():
    """The file through which this command tells a server started with LATER what to warm."""
    return _tmp("warm")


def spec(warm):
    """The server's WARM spec for start_workers(warm=...): a list of scenario dicts, or LATER."""
    if warm == LATER:
        warm_file().unlink(missing_ok=True)   # a file of an earlier process of the same pid
        return {"file": str(warm_file()), "flag": str(compile_flag())}
    return {"scenarios": warm, "flag": str(compile_flag())}


def announce(scenarios):
    """Tell the server what to warm (a list of scenario dicts; [] for nothing) when it waits for
    it (started with LATER); a no-op otherwise, or once said."""
    said = json.loads(os.environ.get(WARM) or "{}")
    path = said.get("file")
    if not path or os.path.exists(path):
        return
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "w") as f:
        json.dump({"scenarios": scenarios}, f)
    os.replace(tmp, path)   # whole or not at all: the server reads it as soon as it appears


def _told_later():
    """Was the server of this process started with LATER (it waits for warm_file())?"""
    return "file" in json.loads(os.environ.get(WARM) or "{}")


def forget():
    """Remove this command's files of the protocol (at its end). A server started again later
    in this process (a long-lived one: a notebook, tests) then warms the paper's model instead
    of waiting for a file no one will write."""
    for p in (compile_flag(), warm_file()):
        p.unlink(missing_ok=True)
    if _told_later():
        os.environ.pop(WARM, None)


PRELOAD = "trackbench.study.preload"


WARM_PROCESS = False   # True in the daemon's copy of itself (daemon/serving.py): it is warm
_POOL = []             # the pool forked from it at the command's start (start_workers)
_FORKED = weakref.WeakSet()   # the pools forked so (give_back keeps them between a search's waves)
INHERITED = []         # descriptors of the copy its forked workers close (the command's socket)


def _context():
    """The workers' multiprocessing context: a fork server preloaded with PRELOAD, or spawn
    where the platform has no fork server. (The daemon's copy forks its first pool itself:
    start_workers.)"""
    import multiprocessing
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    ctx = multiprocessing.get_context("forkserver")
    ctx.set_forkserver_preload([PRELOAD])
    return ctx


def start_workers(executor="local", scheduler=None, warm=None, workers=None):
    """Start the fork server now (it loads in its own process while the command does its own
    set-up); a no-op when it runs already, with spawn, or for a remote dask scheduler. warm:
    scenario dicts whose models the server loads (or compiles, once for all workers, saying so
    in compile_flag()) before it forks a worker, or LATER (the command says which
    through warming.announce, once it has read the study); default: the paper's. Once the
    server runs, a list is announced to it (when it waits for one). In the daemon's copy of
    itself, the pool of ``workers`` local workers is forked from it instead, now, while it
    has a single thread (take_pool)."""
    single_threaded_libraries()
    if _POOL:
        return
    if WARM_PROCESS and executor == "local" and not scheduler and workers and threads() == 1:
        import multiprocessing
        _POOL.append(_forked_pool(multiprocessing.get_context("fork"), workers))
        return
    if warm is not None and warm != LATER and _told_later():
        announce(warm)
    elif warm is not None:
        os.environ[WARM] = json.dumps(spec(warm))
    if scheduler:
        return
    ctx = _context()
    if ctx.get_start_method() == "forkserver":
        if executor == "dask":   # its nannies start worker processes from the same server
            ctx.set_forkserver_preload(["distributed", PRELOAD])
        from multiprocessing import forkserver
        forkserver.ensure_running()


def _forked_pool(ctx, workers):
    from concurrent.futures import ProcessPoolExecutor
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_forked_worker,
                               initargs=(os.getpid(),))
    pool.submit(int)   # a fork pool forks all its workers at its first task: now (not waited for)
    _FORKED.add(pool)
    return pool


def _forked_worker(parent):
    """A forked worker's start. It holds both ends of its pool's queues, so it would wait for
    work forever once the command is gone (killed): the kernel ends it with the command
    instead (Linux). Then it imports rerun (the one library the daemon cannot hold: its import
    starts threads) while the command reads the study."""
    import ctypes
    import signal
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL))   # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent:   # gone before the request took effect
        os._exit(1)
    for fd in INHERITED:
        try:
            os.close(fd)
        except OSError:
            pass
    try:
        import rerun  # noqa: F401
    except ImportError:
        pass


def take_pool(workers):
    """The pool start_workers forked (for at most ``workers`` workers: for as many as there
    were runs to do), once; else None."""
    return _POOL.pop() if _POOL and _POOL[0]._max_workers <= workers else None


def give_back(pool, idle):
    """At the end of a wave: a forked pool left ``idle`` waits for the next wave (a search's);
    any other pool is shut down."""
    if idle and pool in _FORKED:
        _POOL.append(pool)
    else:
        pool.shutdown(wait=True, cancel_futures=True)


def _server_pid():
    """The pid of the fork server this process started, or None."""
    from multiprocessing import forkserver
    return getattr(forkserver._forkserver, "_forkserver_pid", None)


def stop_server():
    """Stop the fork server this process started (a command with nothing to run, or bad input
    found after it started): it would otherwise finish its preload, a second of a core, for no
    worker. Waited for, and multiprocessing told (its ForkServer._stop, which its own tests
    use): a pool started later in this process then starts a new server instead of connecting
    to the dying one."""
    import signal
    from multiprocessing import forkserver
    while _POOL:
        _POOL.pop().shutdown(wait=False, cancel_futures=True)
    pid = _server_pid()
    if pid is not None:
        try:
            os.kill(pid, signal.SIGTERM)
            forkserver._forkserver._stop()
        except (ProcessLookupError, ChildProcessError):
            pass
    forget()
