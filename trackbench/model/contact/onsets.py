"""The approach-speed memory of the laws that need it (the laws by restitution): each
contact's speed at its onset, remembered after an accepted step."""

from numba import njit

from ..core.indices import C_EVALUATIONS, P_CONTACT_DAMPING, P_MIN_APPROACH
from ..core.jit import BORROW
from .laws_jit import needs_approach_speed


@njit(**BORROW)
def remember_onsets(m, w):
    """After an accepted step (the last evaluation was at its end state): pairs in contact
    there keep the approach speed of their onset, a pair that came into contact in the
    step takes its compression rate now (the event location ends such a step just after
    the onset), a pair out of contact forgets it. Only the laws that need it use it;
    memory is never touched inside a step, so a rejected step leaves no trace."""
    if not needs_approach_speed(int(m.par[P_CONTACT_DAMPING])):
        return
    v0, seen, rates = m.v0, w.pair_seen, w.pair_rate
    now = m.counters[C_EVALUATIONS]
    v_min = m.par[P_MIN_APPROACH]
    for row in range(v0.shape[0]):
        for p in range(v0.shape[1]):
            if seen[row, p] != now:
                v0[row, p] = 0.0
            elif v0[row, p] <= 0.0:
                v0[row, p] = max(rates[row, p], v_min)


@njit(**BORROW)
def onset_in_step(m, w):
    """Did a pair come into contact in the step just tried (in contact at its end, the
    last evaluation, with no approach speed remembered yet)? Only for the laws that
    need it: the solver then ends the step at the located onset, so that the
    approach speed taken there does not depend on where the step happened to end."""
    if not needs_approach_speed(int(m.par[P_CONTACT_DAMPING])):
        return False
    v0, seen = m.v0, w.pair_seen
    now = m.counters[C_EVALUATIONS]
    for row in range(v0.shape[0]):
        for p in range(v0.shape[1]):
            if seen[row, p] == now and v0[row, p] <= 0.0:
                return True
    return False
