"""What a process that runs the model does to start sooner (`trackbench run`, the study
workers' server): no dask arrays where none are held. Plain module: no numba."""

import os
import sys


def without_dask_arrays():
    """Where dask is installed, xarray imports dask.array (0.3-0.4 s) at the first Variable it
    builds, only to ask whether the data are dask arrays. A process that holds numpy arrays
    only (a run, a study's pool worker) answers that itself: a None in sys.modules makes the
    import fail as if dask were not installed, and xarray then says no, which is so. Not where
    dask.distributed is loaded (the dask executor's workers): dask may need its arrays there."""
    if "distributed" not in sys.modules:
        sys.modules.setdefault("dask.array", None)


def single_threaded_libraries(env=None):
    """One BLAS thread per worker: the workers already fill the cores, and idle OpenBLAS
    threads spin (seen at ~6 % of a core per worker); no jemalloc background thread in
    pyarrow. In ``env`` (default: this process's) for a process to be started, since the
    libraries read them as they load: a process that forks workers (the fork server, the
    daemon) then has a single thread when it forks (study/preload.py)."""
    env = os.environ if env is None else env
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        env.setdefault(var, "1")
    env.setdefault("JE_ARROW_MALLOC_CONF", "background_thread:false")


def threads():
    """This process's threads, any kind (numba's, BLAS', Python's): a process may fork safely
    with one only. None where the system does not say (no /proc)."""
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return None


def die_with_parent():
    """This process is killed (SIGKILL) when its parent ends, however it ends (Linux; elsewhere
    nothing): the fork server with the command, a worker with the fork server, so that a command
    killed from a script leaves nothing running. A parent already gone: leave now."""
    import ctypes
    import signal
    parent = os.getppid()
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL))   # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:
        os._exit(1)
