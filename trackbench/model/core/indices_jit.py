"""indices.py's index functions, compiled for the kernels (indices.py itself imports no
numba: scenario and study validation and the command line use it)."""

from numba import njit

from . import indices as _L
from .jit import SCALAR

pin_offset = njit(**SCALAR)(_L.pin_offset)
q_pin = njit(**SCALAR)(_L.q_pin)
n_coordinates = njit(**SCALAR)(_L.n_coordinates)
n_state = njit(**SCALAR)(_L.n_state)
nq_of = njit(**SCALAR)(_L.nq_of)
bristle_state = njit(**SCALAR)(_L.bristle_state)
z_arm = njit(**SCALAR)(_L.z_arm)
z_pin = njit(**SCALAR)(_L.z_pin)
diag_tension = njit(**SCALAR)(_L.diag_tension)
q_sprocket = njit(**SCALAR)(_L.q_sprocket)
q_idler = njit(**SCALAR)(_L.q_idler)
