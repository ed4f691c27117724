"""trackbench: dynamics of high-mobility tracked vehicles (K. Lee, KSME Int. J., 2000)."""

__version__ = "0.1.0"

from . import _jitcache  # noqa: E402

_jitcache.configure()  # before any compiled kernel is defined

from .scenario import Scenario, ScenarioError  # noqa: E402
from .simulate import simulate  # noqa: E402
from .study.summary import open_study, open_study_dataset  # noqa: E402

__all__ = ["Scenario", "ScenarioError", "simulate", "open_study", "open_study_dataset", "__version__"]
