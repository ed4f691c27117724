"""What a process that runs the model does to start sooner (`trackbench run`, the study
workers' server): no dask arrays where none are held. Plain module: no numba."""

import sys


def without_dask_arrays():
    """Where dask is installed, xarray imports dask.array (0.3-0.4 s) at the first Variable it
    builds, only to ask whether the data are dask arrays. A process that holds numpy arrays
    only (a run, a study's pool worker) answers that itself: a None in sys.modules makes the
    import fail as if dask were not installed, and xarray then says no, which is so. Not where
    dask.distributed is loaded (the dask executor's workers): dask may need its arrays there."""
    if "distributed" not in sys.modules:
        sys.modules.setdefault("dask.array", None)
