"""trackbench: dynamics of high-mobility tracked vehicles (K. Lee, KSME Int. J., 2000)."""

from . import _jitcache
from .version import __version__

_jitcache.configure()  # before any compiled kernel is defined

# the heavy parts (numba, xarray, pandas) load on first use: the command line's help and
# the validation of scenarios and study files stay fast
from .run.simulate import simulate  # noqa: E402  (light until called)
from .scenario import Scenario, ScenarioError  # noqa: E402  (light: no compiler)

_LAZY = {
    "open_study": ("study.read.opening", "open_study"),
    "open_study_dataset": ("study.read.opening", "open_study_dataset"),
    "open_limits": ("study.read.opening", "open_limits"),
}

__all__ = ["Scenario", "ScenarioError", "simulate", "open_study", "open_study_dataset", "open_limits",
           "__version__"]


def __getattr__(name: str) -> object:
    if name not in _LAZY:
        raise AttributeError(f"module 'trackbench' has no attribute {name!r}")
    import importlib
    module, attr = _LAZY[name]
    value = getattr(importlib.import_module(f".{module}", __name__), attr)
    globals()[name] = value
    return value
