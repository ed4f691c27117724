"""The figures as PNG files: one run's (run_figures.py: the paper's Figs. 8-18, the closed
track's drive, the soil's traction) and a study's (study_figures.py), sharing plot_common.py.

    plot_run(ds_or_path, out_dir, times=None) -> [PNG paths]   # times: default_times(ds)
    plot_study(study_dir, out_dir) -> [PNG paths]      # one figure per grid axis (+ drawbar pull
                                                       #   against slip for drawbar studies)

matplotlib is an optional dependency (extra "plot"); it is imported only when a figure is drawn.
"""

from trackbench.figures.plot_common import (
    PAPER_TIMES,
    SOIL_DENT,
    axis_label,
    find_timeseries,
    load_run,
    parameter_unit,
    run_label,
    value_label,
)
from trackbench.figures.run_figures import (
    _arrow_scale,
    choose_times,
    default_times,
    draw_configuration,
    plot_configuration,
    plot_run,
)
from trackbench.figures.study_figures import _groups, plot_study, remove_stale, study_axes

__all__ = [
    "PAPER_TIMES",
    "SOIL_DENT",
    "axis_label",
    "find_timeseries",
    "load_run",
    "parameter_unit",
    "run_label",
    "value_label",
    "_arrow_scale",
    "choose_times",
    "default_times",
    "draw_configuration",
    "plot_configuration",
    "plot_run",
    "_groups",
    "plot_study",
    "remove_stale",
    "study_axes",
]
