"""The ground's memories, moved only after an accepted step: the soil's deepest sinkage and
touchdown points (soil_jit.remember_sinkage; along the step's interpolant before it:
solvers/common/sinkage.py) and the bristles' anchors
(grip.remember_grip). A rejected step leaves no trace in either."""

from numba import njit

from ..core.indices import P_SOIL
from ..core.jit import BORROW, INLINE
from .grip import remember_grip, uses_bristle
from .soil_jit import remember_sinkage


@njit(**INLINE)
def has_ground_memory(par):
    """Soft soil or bristle friction: the ground keeps something from step to step."""
    return par[P_SOIL] != 0.0 or uses_bristle(par)


@njit(**BORROW)
def remember_ground(m, w):
    """Move the memories to the evaluation ``w`` (Work, or the solver's EndOfStep: the fields
    apos, sink and grip) at the end of an accepted step."""
    remember_sinkage(m, w)
    remember_grip(m, w)
