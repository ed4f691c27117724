"""What the study workers' fork server loads once, before it forks any worker.

`study run` starts a fork server (multiprocessing's "forkserver": a fresh Python process
started from the command, not a fork of it) with this module as its preload, first thing,
before it reads the study file. Importing it imports the package, numpy, numba, xarray,
pandas and netCDF4 (while the command validates and expands the study), then loads the
compiled kernels of the kinds of model the command announces (warming.py) from the numba
cache by running a 1 ms simulation of each, and writes one small netCDF file (HDF5's
set-up and the zstd filter plugin) in a temporary folder. Each worker is then a fork of this
process: it starts with all of that done instead of redoing it. Should the command be gone
before the preload ends (Ctrl-C), the server stops instead of loading for nobody.

Why forking it is safe: the fork server has a single thread from start to fork, and a
fork of a single-threaded process cannot inherit a lock held by another thread. numba's
compiled code here uses no threading layer (no parallel=True), so it starts no thread; no
file is left open. Three libraries would start threads, so the command sets, before the
server starts: OPENBLAS_NUM_THREADS=1 (no BLAS thread pool) and
JE_ARROW_MALLOC_CONF=background_thread:false (pyarrow, which pandas imports, would start
jemalloc's background thread); and rerun is not imported here: its import starts a tokio
runtime with worker threads, so each worker imports it at its first recording. THREADS_AT_FORK
records the thread count at the end of the preload (1; a test checks it through a worker).
The command itself, which may run threads (the progress display, dask's scheduler), is
never forked.
"""

import os

from trackbench.warm.startup import die_with_parent, threads

die_with_parent()       # the server ends with the command, even a command that is killed
THREADS_AT_FORK = None
PARENT = os.getppid()   # the command that started the server


def _orphaned():
    """The command is gone (Ctrl-C, a resumed study with nothing to run): the preload stops,
    instead of loading for nobody."""
    if os.getppid() != PARENT:
        os._exit(0)


def warm():
    """Load everything a run needs; errors are left for the real runs to report."""
    import tempfile
    from pathlib import Path

    from trackbench.warm.startup import without_dask_arrays
    without_dask_arrays()   # the pool's workers hold numpy arrays only
    import netCDF4  # noqa: F401
    import pandas  # noqa: F401  (the summary of a run's results)
    import xarray  # noqa: F401

    from trackbench.outputs.files.netcdf import write_netcdf
    from trackbench.outputs.quantities import run_summary

    _orphaned()
    ds = None
    for sc in _kinds():
        _orphaned()
        ds = _load(sc) or ds
    _orphaned()
    if ds is None:
        return
    run_summary(ds)
    with tempfile.TemporaryDirectory() as tmp:
        write_netcdf(ds, Path(tmp) / "warm.nc")


def _kinds():
    """The scenarios to warm: the study's kinds of model (warming.WARM), else the paper's."""
    import json

    import trackbench
    from trackbench.warm.protocol import TINY as short
    from trackbench.warm.protocol import WARM
    spec = json.loads(os.environ.get(WARM) or "{}")
    kinds = _announced(spec["file"]) if spec.get("file") else spec.get("scenarios") or [None]
    for d in kinds:
        try:
            sc = (
                trackbench.Scenario.paper(**short)
                if d is None
                else trackbench.Scenario.from_dict({**d, **short})
            )
        except Exception:  # noqa: BLE001  (the real run reports it)
            continue
        yield sc, spec.get("flag")


WAIT = 120.0   # s: the longest a server waits for the command to say what to warm


def _announced(path):
    """The scenarios the command announces in ``path`` once it has read the study (warming.py):
    the server waits for them (its imports are done by then); [] for nothing; the paper's
    when the command says nothing within WAIT seconds."""
    import json
    import time
    t0 = time.monotonic()
    while time.monotonic() - t0 < WAIT:
        _orphaned()
        try:
            with open(path) as f:
                return json.load(f)["scenarios"]
        except (OSError, ValueError, KeyError):
            time.sleep(0.005)
    return [None]


def _load(kind):
    """A 1 ms run of the scenario: its compiled model loaded from the cache, or compiled once
    here for every worker (saying so in the flag file, which the command's progress shows)."""
    import trackbench
    from trackbench._jitcache import CompileNotice
    sc, flag = kind
    try:
        with CompileNotice(None, flag=flag):
            return trackbench.simulate(sc)
    except Exception:  # noqa: BLE001
        return None


def warm_recording():
    """rerun's set-up (a tiny recording in a temporary folder), for spawned workers only: its
    import starts threads, which a fork server must not have."""
    import tempfile
    from pathlib import Path

    import trackbench
    from trackbench.outputs.recording.record import write_recording

    ds = trackbench.simulate(trackbench.Scenario.paper(duration=1e-3, output_interval=1e-3))
    with tempfile.TemporaryDirectory() as tmp:
        write_recording(ds, Path(tmp) / "warm.rrd")


def facts():
    """What a worker inherited (for tests and diagnosis): its pid, the fork server's thread
    count at the end of the preload, how many compiled signatures the time loop has, and
    whether dask's arrays are loaded."""
    import sys

    from trackbench.solvers.rk.rk_loop import integrate

    return {
        "pid": os.getpid(),
        "threads_at_fork": THREADS_AT_FORK,
        "loop_signatures": len(integrate.signatures),
        "dask_arrays": sys.modules.get("dask.array") is not None,
    }


try:
    warm()
except Exception:  # noqa: BLE001  (warming is an optimisation only)
    pass
THREADS_AT_FORK = threads()
