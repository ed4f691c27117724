"""Parameter studies: TOML grids run in parallel, kept as netCDF, resumable, summarised with pandas."""

from .runner import run_study
from .spec import StudyError, load_study
from .store import StudyLocked
from .summary import open_run, open_study, open_study_dataset

__all__ = ["StudyError", "StudyLocked", "load_study", "open_run", "open_study", "open_study_dataset",
           "run_study"]
