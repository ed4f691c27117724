"""Step-size control shared by the compiled time loops (reduced.py, lee_loop.py): the
standard controller of Hairer, Norsett & Wanner (II.4), plus the retry that ends just
after a contact switch located in a rejected step (events.py)."""

import numpy as np
from numba import njit

from ...model.core import fixed_math as fm
from ...model.core.indices import S_H_MAX, S_H_MIN, S_N_OUT, S_REJECTED, S_RHS, S_STATUS, S_STEPS, S_T_FINAL
from ...model.core.jit import BORROW, INLINE
from ...status import MAX_STEPS, STEP_SIZE_UNDERFLOW, SUCCESSFUL

SAFETY = 0.9
FAC_MIN = 0.2
FAC_MAX = 10.0   # growth after an accepted step (1 right after a rejection)
# The PI controller's exponent on the previous accepted step's error (Gustafsson's; Hairer &
# Wanner II.4 (4.13), the value of their DOPRI5 code): the closed track's explicit pairs use it
# (registry: controls), the paper's layout keeps the plain controller its golden runs pin.
PI_BETA = 0.04
ERR_OLD_MIN = 1e-4   # the previous error's floor (theirs): one tiny error does not fling h up


@njit(**INLINE)
def loop_start():
    """A time loop's counters at t = 0: (t, steps, rejected, smallest and largest accepted
    step, growth limit, at_switch: the step being tried ends just after a located contact
    switch)."""
    return 0.0, 0, 0, np.inf, 0.0, FAC_MAX, False


@njit(**INLINE)
def counted(h, steps, h_lo, h_hi):
    """(steps, h_lo, h_hi) after accepting a step of size h."""
    return steps + 1, min(h_lo, h), max(h_hi, h)


@njit(**BORROW)
def before_step(t, h, t_end, steps, rejected, max_steps, h_min):
    """(status, h): stop on too many attempts or a vanishing step; clip h to t_end."""
    if steps + rejected >= max_steps:
        return MAX_STEPS, h
    if h < h_min:
        return STEP_SIZE_UNDERFLOW, h
    if t + h > t_end:
        h = t_end - t
    return SUCCESSFUL, h


@njit(**BORROW)
def after_rejection(h, err, expo, th, h_min):
    """(h, at_switch) for the retry of a step rejected with error norm err (NaN allowed):
    end just after the contact switch at fraction th of the step if one was located
    (th < 1), else the usual shrink."""
    if err == err and err > 0.0:
        if th < 1.0 and th * h > h_min:
            return h * th, True
        return h * max(FAC_MIN, SAFETY * fm.pow(err, expo)), False
    return h * FAC_MIN, False


@njit(**BORROW)
def after_acceptance(h, err, expo, fac_max, h_max):
    """The next step after an accepted one."""
    if err == 0.0:
        fac = fac_max
    else:
        fac = min(fac_max, SAFETY * fm.pow(err, expo))
    return min(h * fac, h_max)


@njit(**BORROW)
def after_acceptance_pi(h, err, err_old, expo, beta, fac_max, h_max):
    """The next step after an accepted one by the PI controller (beta > 0): err^(expo +
    0.75 beta) x err_old^beta, the previous accepted step's error err_old >= ERR_OLD_MIN;
    beta = 0: after_acceptance, bit for bit."""
    if beta == 0.0:
        return after_acceptance(h, err, expo, fac_max, h_max)
    fac = SAFETY * fm.pow(max(err, 1e-10), expo + 0.75 * beta) * fm.pow(err_old, beta)
    return min(h * min(fac_max, fac), h_max)


@njit(**BORROW)
def finish_stats(stats, status, t, steps, rejected, n_rhs, n_out, h_lo, h_hi):
    """The run's figures into stats (indices.S_*)."""
    stats[S_STATUS] = status
    stats[S_T_FINAL] = t
    stats[S_STEPS] = steps
    stats[S_REJECTED] = rejected
    stats[S_RHS] = n_rhs
    stats[S_N_OUT] = n_out
    stats[S_H_MIN] = h_lo
    stats[S_H_MAX] = h_hi
