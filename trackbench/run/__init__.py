"""The run layer: scenario -> model -> solver -> outputs. assemble.py builds what a run is made
of, simulate.py runs it in memory, stream.py runs it to its file as it goes (the same pipeline,
its samples handed over chunk by chunk)."""
