"""layout.py's index functions, compiled for the kernels (layout itself imports no
numba: scenario and study validation and the command line use it)."""

from numba import njit

from . import layout as _L
from .jit import INLINE

pin_offset = njit(**INLINE)(_L.pin_offset)
q_pin = njit(**INLINE)(_L.q_pin)
n_coordinates = njit(**INLINE)(_L.n_coordinates)
n_state = njit(**INLINE)(_L.n_state)
nq_of = njit(**INLINE)(_L.nq_of)
z_arm = njit(**INLINE)(_L.z_arm)
z_pin = njit(**INLINE)(_L.z_pin)
diag_tension = njit(**INLINE)(_L.diag_tension)
