"""The ground's memory, moved only after an accepted step: the soil's deepest sinkage and
touchdown points (soil_jit.remember_sinkage; along the step's interpolant before it:
solvers/common/sinkage.py). A rejected step leaves no trace in it. (The bristle friction
keeps no memory: its deflections are states of the ODE, grip.py.)"""

from numba import njit

from ..core.indices import P_SOIL
from ..core.jit import BORROW, INLINE
from .soil_jit import remember_sinkage


@njit(**INLINE)
def has_ground_memory(par):
    """Soft soil: the ground keeps something from step to step."""
    return par[P_SOIL] != 0.0


@njit(**BORROW)
def remember_ground(m, w):
    """Move the memory to the evaluation ``w`` (Work, or the solver's EndOfStep: the fields
    apos and sink) at the end of an accepted step."""
    remember_sinkage(m, w)
