"""How a study runs: runner.py (the study's waves of runs), executors.py (a process pool or
dask: one run in a worker, its result checked), progress.py (the live bar)."""
