"""Every force on the track and the wheels at one configuration: link tensions, wheel-track
and ground-track contacts, in the order the right-hand sides need them."""

from numba import njit

from ...status import GROUND_CANDIDATES
from ..contact.neighbours import refresh_neighbours
from ..contact.track_contacts import wheel_contacts
from ..core.indices import C_EVALUATIONS, C_OVERFLOW, D_DISSIPATION, D_POWER, D_STATUS, P_MIN_APPROACH
from ..core.indices_jit import diag_tension
from ..core.jit import INLINE
from ..ground.ground_contact import ground_contacts
from ..vehicle.links import link_tensions


@njit(**INLINE)
def track_loads(w, m, diag):
    """All forces of the track model for the pin and wheel kinematics in w (fpin is
    overwritten, tension first): tension and contact forces on the pins (w.fpin, pins 0
    and n_links included), contact forces on the wheels (w.fwheel), energies, power and
    status in diag. Gravity is left to the caller."""
    apos, wc, par = w.apos, w.wc, m.par
    mem = (m.v0, w.pair_seen, w.pair_rate, m.counters, par[P_MIN_APPROACH])
    diag[D_STATUS] = 0.0
    diag[D_POWER] = 0.0
    diag[D_DISSIPATION] = 0.0
    m.counters[C_EVALUATIONS] += 1
    refresh_neighbours(apos, wc, m.guides, m)  # m.guides: no rows, as no idler or rollers
    if m.counters[C_OVERFLOW]:   # a pin's candidate row overflowed: its contacts are incomplete
        diag[D_STATUS] = GROUND_CANDIDATES
    link_tensions(apos, w.avel, par, w.lk, w.fpin, diag, diag_tension(wc.shape[0]))
    wheel_contacts(w, m, diag, mem)
    ground_contacts(w, m, diag, mem)
