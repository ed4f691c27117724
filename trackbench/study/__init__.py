"""Parameter studies: TOML grids run in parallel, kept as netCDF, resumable, summarised with pandas.
The parts load on first use (study file validation needs none of the heavy libraries)."""

_LAZY = {
    "run_study": "runner", "StudyError": "spec", "load_study": "spec", "StudyLocked": "store",
    "open_run": "summary", "open_limits": "limits", "open_study": "summary", "open_study_dataset": "summary",
}

__all__ = sorted(_LAZY)


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module 'trackbench.study' has no attribute {name!r}")
    import importlib
    value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    globals()[name] = value
    return value
