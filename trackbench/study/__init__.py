"""Parameter studies: TOML grids run in parallel, kept as netCDF, resumable, summarised with pandas.
What a study is (spec/), how it runs (execute/), how it is read (read/), and its results
folder's layout (store.py). The parts load on first use (study file validation needs none of
the heavy libraries)."""

_LAZY = {
    "run_study": "execute.runner", "StudyError": "spec.rules", "load_study": "spec.study_file",
    "StudyLocked": "store", "open_run": "read.opening", "open_limits": "read.opening",
    "open_study": "read.opening", "open_study_dataset": "read.opening",
}

__all__ = sorted(_LAZY)


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module 'trackbench.study' has no attribute {name!r}")
    import importlib
    value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    globals()[name] = value
    return value
