"""What the study workers' fork server loads once, before it forks any worker.

`study run` starts a fork server (multiprocessing's "forkserver": a fresh Python process
started from the command, not a fork of it) with this module as its preload. Importing it
imports the package, numpy, numba, xarray, pandas, netCDF4 and rerun, loads the compiled
kernels from the numba cache by running a 1 ms simulation, and writes and reads back one
small netCDF file (HDF5's set-up and the zstd filter plugin), all in a temporary folder. Each
worker is then a fork of this process: it starts with all of that done instead of redoing it
(about 2 s a worker).

Why forking it is safe: the fork server runs a single thread from start to fork. numba's
compiled code here uses no threading layer (no parallel=True), so it starts no thread; no
file is left open; no rerun recording stream (which runs threads) is created here, only its
module imported; BLAS is limited to one thread (OPENBLAS_NUM_THREADS=1, set by the command
before the server starts, so no BLAS thread pool exists). THREADS_AT_FORK records the
number of threads the process had at the end of the preload (1), and a worker can report
it. The command itself, which may run threads (the progress display, dask's scheduler), is
never forked.
"""

import os

THREADS_AT_FORK = None


def _threads():
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return None


def warm():
    """Load everything a run needs; errors are left for the real runs to report."""
    import tempfile
    from pathlib import Path

    import netCDF4
    import pandas  # noqa: F401  (imported by the summary of a run's results)
    import rerun  # noqa: F401  (import only: a recording stream starts threads)
    import xarray

    import trackbench
    from trackbench.replay import record  # noqa: F401
    from trackbench.study import executors  # noqa: F401

    xarray.backends.list_engines()
    ds = trackbench.simulate(trackbench.Scenario.paper(duration=1e-3, output_interval=1e-3))
    executors.run_summary(ds)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "warm.nc"
        trackbench.output.write_netcdf(ds, path)
        with netCDF4.Dataset(path) as f:
            f.getncattr("status")


try:
    warm()
except Exception:  # noqa: BLE001  (warming is an optimisation only)
    pass
THREADS_AT_FORK = _threads()
