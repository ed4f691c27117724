"""Visual replay of runs: rerun recordings (record), the paper's figures and study
plots (plots, needs matplotlib), and `trackbench view` (view). Shared drawing: geometry.

    from trackbench.outputs.recording.record import write_recording, maybe_write_recording
    from trackbench.figures.plots import plot_run, plot_study
"""
