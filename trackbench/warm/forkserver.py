"""The workers' fork server from the command's side: its start and stop, and the pool
factory a study takes (ForkServerPools). What it is told to warm: protocol.py; what it loads:
preload.py."""

import json
import os
from contextlib import contextmanager

from trackbench.warm.protocol import (
    LATER,
    WARM,
    _told_later,
    announce,
    compile_flag,
    forget,
    spec,
    warm_kinds,
)
from trackbench.warm.startup import die_with_parent, single_threaded_libraries

PRELOAD = "trackbench.warm.preload"


def _context():
    """The workers' multiprocessing context: a fork server preloaded with PRELOAD, or spawn
    where the platform has no fork server."""
    import multiprocessing
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    ctx = multiprocessing.get_context("forkserver")
    ctx.set_forkserver_preload([PRELOAD])
    return ctx


def start_workers(executor="local", scheduler=None, warm=None):
    """Start the fork server now (it loads in its own process while the command does its own
    set-up); a no-op when it runs already, with spawn, or for a remote dask scheduler. warm:
    scenario dicts whose models the server loads (or compiles, once for all workers, saying so
    in compile_flag()) before it forks a worker, or LATER (the command says which through
    announce, once it has read the study); default: the paper's. Once the server runs, a list
    is announced to it (when it waits for one)."""
    single_threaded_libraries()
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


def _forked_worker():
    """Pool initializer of the fork server's workers: each ends with the server."""
    die_with_parent()


def _warm_spawned():
    """Pool initializer of spawned workers (no fork server): they end with the command; the
    fork server's preload, run in the worker itself (importing preload.py warms the process),
    and rerun's set-up, which the fork server leaves out. Warming is an optimisation only: a
    real run reports errors."""
    die_with_parent()
    try:
        from trackbench.warm import preload
        preload.warm_recording()
    except Exception:  # noqa: BLE001
        pass


class ForkServerPools:
    """The study's pool factory (study/execute/executors.PoolFactory) of the command line:
    workers forked from a fork server that loaded the runs' kinds of model once."""

    compile_flag = staticmethod(compile_flag)

    def prepare(self, scenarios, executor="local", scheduler=None):
        """The first wave's runs are known: the server loads their kinds while this process sets up."""
        start_workers(executor, scheduler, warm=warm_kinds(scenarios))

    def pool(self, workers):
        from concurrent.futures import ProcessPoolExecutor
        start_workers()
        ctx = _context()
        start = _warm_spawned if ctx.get_start_method() == "spawn" else _forked_worker
        return ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=start)

    def dask_context(self):
        """How a LocalCluster's nannies start their workers: from the same server."""
        start_workers("dask")
        return _context().get_start_method()

    def close(self):
        """The study is done: the server goes before the command does, so that nothing of the
        command outlives it (left alone, the server notices the command's end a moment after)."""
        stop_server()


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
    pid = _server_pid()
    if pid is not None:
        try:
            os.kill(pid, signal.SIGTERM)
            forkserver._forkserver._stop()
        except (ProcessLookupError, ChildProcessError):
            pass
    _stop_resource_tracker()
    forget()


def _stop_resource_tracker():
    """multiprocessing's resource tracker (started by the pool's locks) stopped and waited for,
    as its own tests do, instead of leaving it to notice the command's end."""
    from multiprocessing import resource_tracker
    stop = getattr(resource_tracker._resource_tracker, "_stop", None)
    if stop is not None:
        try:
            stop()
        except (OSError, ChildProcessError):
            pass


@contextmanager
def started_early(executor="local", scheduler=None):
    """The server started before the command reads the study file (its imports, a second,
    overlap the validation and the expansion of the runs); yields tell(scenarios), by which the
    command says which runs there are to do once it knows. Stopped again when the block
    raises (bad input) or there is nothing to run: it would otherwise load for no worker."""
    start_workers(executor, scheduler, warm=LATER)
    todo = []

    def tell(scenarios):
        todo[:] = list(scenarios)
        announce(warm_kinds(todo))

    try:
        yield tell
    except BaseException:
        stop_server()
        raise
    if not todo:
        stop_server()
