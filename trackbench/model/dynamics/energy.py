"""The energy bookkeeping, written once: the compiled loops call these on scalars, the
output on arrays of samples.

- The paper's balance (its Fig. 18): kinetic + elastic (torsion bars, links, pads) +
  gravity potential. It jumps where the contact potential does (docs/model.md).
- The work-based residual: kinetic + torsion + tension + gravity - W, where W is the
  work of every contact force and damper (integrated as a state): continuous, it
  measures the integration error; with dampers the dissipated energy is part of W.
"""

from numba import njit

from ..core.jit import INLINE


@njit(**INLINE)
def paper_balance(kinetic, torsion, tension, pad_wheel, pad_ground, gravity):
    return kinetic + torsion + tension + pad_wheel + pad_ground + gravity


@njit(**INLINE)
def work_residual(kinetic, torsion, tension, gravity, work):
    return kinetic + torsion + tension + gravity - work
