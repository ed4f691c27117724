"""Visual replay of runs: rerun recordings (record), the paper's figures and study
plots (plots, needs matplotlib), and `trackbench view` (view). Shared drawing: geometry.

    from trackbench.replay.record import write_recording, maybe_write_recording
    from trackbench.replay.plots import plot_run, plot_study
"""
