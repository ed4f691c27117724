"""The warm process: `trackbench run` and `study run` served by a process that has its
libraries imported and the model's compiled kernels loaded already.

What a command costs before its first step is its start: Python, numba and the kernels
from numba's cache, xarray and pandas, netCDF4, rerun (about 1.5 s on a 0.01 s run). The
first such command runs as usual and then leaves a warm process behind (address.py names
it by the code and the settings it was started with); the next one hands it its arguments,
its current folder, its environment and its terminal, and the warm process forks a copy of
itself that runs the command exactly as the command would have run it, in the same
process layout. The warm process leaves after IDLE seconds without a command.

  client.py    the command's side (standard library only: it decides in milliseconds)
  address.py   which warm process serves which command, and where it listens
  serving.py   the warm process: its preload, its listening loop, the copy it forks
"""
