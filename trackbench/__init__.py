"""trackbench: dynamics of high-mobility tracked vehicles (K. Lee, KSME Int. J., 2000)."""

__version__ = "0.1.0"

from .scenario import Scenario, ScenarioError  # noqa: E402
from .simulate import simulate  # noqa: E402

__all__ = ["Scenario", "ScenarioError", "simulate", "__version__"]
from .study.summary import open_study, open_study_dataset  # noqa: E402
__all__ += ["open_study", "open_study_dataset"]
