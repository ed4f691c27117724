"""What every solver does at an accepted step: update the peaks, so that no impulse
between output samples is missed."""

import numpy as np
from numba import njit

from ...model.core.indices import (
    D_CHASSIS_AY,
    D_CORNER_FORCE,
    D_DRIVE_TORQUE,
    D_E_GRAVITY,
    D_E_KINETIC,
    D_E_PAD_GROUND,
    D_E_PAD_WHEEL,
    D_E_TENSION,
    D_E_TORSION,
    D_GROUND_FY,
    D_IDLER_FORCE,
    D_MAX_TENSION,
    D_MIN_TENSION,
    D_OBSTACLE_FORCE,
    D_WHEEL,
    PK_AY_MAX,
    PK_AY_MIN,
    PK_DRIVE_TORQUE,
    PK_ENERGY_BALANCE,
    PK_ENERGY_RESIDUAL,
    PK_FIRST_COMPRESSION,
    PK_FIRST_CORNER,
    PK_FIRST_OBSTACLE,
    PK_GROUND_FY,
    PK_IDLER_FORCE,
    PK_SWITCH,
    PK_TENSION_MAX,
    PK_TENSION_MIN,
    PK_VX_MIN,
    PK_WHEEL_FY,
)
from ...model.core.jit import BORROW, INLINE
from ...model.dynamics.energy import paper_balance, work_residual

# The step-size controller grows a step at most 10x (FAC_MAX), so neighbouring steps
# more unequal than this follow a rejection: a contact switch, a kink or a jump the error
# estimate caught. A parabola through such samples can overshoot by many times the
# change over the short step (a wheel-5 peak of 4.06 MN where the samples reach 1.8 MN).
STEP_RATIO = 12.0


# the quantities tracked from diag besides the wheel forces: peak row, diag slot, +1 for
# a maximum / -1 for a minimum
_ROWS = (PK_GROUND_FY, PK_TENSION_MAX, PK_TENSION_MIN, PK_AY_MAX, PK_AY_MIN, PK_DRIVE_TORQUE, PK_IDLER_FORCE)
_SLOTS = (
    D_GROUND_FY,
    D_MAX_TENSION,
    D_MIN_TENSION,
    D_CHASSIS_AY,
    D_CHASSIS_AY,
    D_DRIVE_TORQUE,
    D_IDLER_FORCE,
)
_SIGNS = (1.0, 1.0, -1.0, 1.0, -1.0, 1.0, 1.0)


@njit(**BORROW)
def energy_balance(diag):
    """The paper's balance: kinetic + elastic (torsion, tension, pads) + gravity potential."""
    return paper_balance(diag[D_E_KINETIC], diag[D_E_TORSION], diag[D_E_TENSION], diag[D_E_PAD_WHEEL],
                         diag[D_E_PAD_GROUND], diag[D_E_GRAVITY])


@njit(**BORROW)
def energy_residual(diag, work):
    """Kinetic + torsion + tension + gravity - work of the contact forces (continuous)."""
    return work_residual(diag[D_E_KINETIC], diag[D_E_TORSION], diag[D_E_TENSION], diag[D_E_GRAVITY], work)


@njit(**BORROW)
def init_peaks(peaks):
    peaks[:, 0] = -np.inf
    peaks[:, 1] = np.nan
    peaks[:, 2:] = np.nan  # history of the last two samples: f, t, f, t
    peaks[PK_TENSION_MIN, 0] = np.inf
    peaks[PK_AY_MIN, 0] = np.inf
    peaks[PK_VX_MIN, 0] = np.inf
    peaks[PK_FIRST_CORNER, 0] = 0.0
    peaks[PK_FIRST_OBSTACLE, 0] = 0.0
    peaks[PK_FIRST_COMPRESSION, 0] = 0.0
    peaks[PK_ENERGY_BALANCE, 0] = 0.0
    peaks[PK_ENERGY_RESIDUAL, 0] = 0.0
    peaks[PK_SWITCH, :] = -1.0


@njit(**INLINE)
def _first(peaks, k, happened, t):
    """Row k holds 1 and the time of the first accepted step at which it happened."""
    if peaks[k, 0] == 0.0 and happened:
        peaks[k, 0] = 1.0
        peaks[k, 1] = t


@njit(**INLINE)
def _max(peaks, k, v, t):
    if v > peaks[k, 0]:
        peaks[k, 0] = v
        peaks[k, 1] = t


@njit(**INLINE)
def _up(peaks, k, v, t, t_switch):
    """Running maximum of a quantity sampled at every accepted step. A local maximum at
    the previous step is refined by the parabola through the last three samples, so a
    smooth peak is found to O(h^3) rather than to the step spacing (O(h^2)). Not when the
    previous step ended at a located contact switch (t_switch): there the quantity has a
    kink, its extreme is the sample itself, and a parabola would overshoot it; nor across
    steps more unequal than STEP_RATIO; nor at a flat top (a sample equal to its neighbour:
    a quantity held at a limit, the drive's torque at drive.torque_limit), where a parabola
    through the corner into the limit rises above it."""
    if v > peaks[k, 0]:
        peaks[k, 0] = v
        peaks[k, 1] = t
    f0, t0, f1, t1 = peaks[k, 2], peaks[k, 3], peaks[k, 4], peaks[k, 5]
    if (f1 > f0 and f1 > v and t1 != t_switch and t0 < t1 < t
            and (t - t1) <= STEP_RATIO * (t1 - t0) <= STEP_RATIO ** 2 * (t - t1)):
        d01 = (f1 - f0) / (t1 - t0)
        d12 = (v - f1) / (t - t1)
        a = (d12 - d01) / (t - t0)
        if a < 0.0:
            ts = 0.5 * (t0 + t1) - d01 / (2.0 * a)
            if t0 <= ts <= t:
                fs = f0 + d01 * (ts - t0) + a * (ts - t0) * (ts - t1)
                if fs > peaks[k, 0]:
                    peaks[k, 0] = fs
                    peaks[k, 1] = ts
    peaks[k, 2] = f1
    peaks[k, 3] = t1
    peaks[k, 4] = v
    peaks[k, 5] = t


@njit(**BORROW)
def update_peaks(peaks, t, diag, vx, work, e_ref, r_ref, at_switch):
    """e_ref, r_ref: energy balance and residual at t = 0; at_switch: this step was
    shortened to end just after a located contact switch (solvers/common/events.py)."""
    ts = peaks[PK_SWITCH, 1]  # the last sample at a switch before this one (see _up)
    nw = peaks.shape[0] - PK_WHEEL_FY
    if peaks[PK_FIRST_COMPRESSION, 0] == 0.0 and diag[D_MIN_TENSION] < 0.0:
        # the crossing time, linear between the last two steps (history holds -T_min)
        f0 = -peaks[PK_TENSION_MIN, 4]
        t0 = peaks[PK_TENSION_MIN, 5]
        tc = t
        if f0 > 0.0 and t0 < t:
            tc = t0 + f0 / (f0 - diag[D_MIN_TENSION]) * (t - t0)
        peaks[PK_FIRST_COMPRESSION, 0] = 1.0
        peaks[PK_FIRST_COMPRESSION, 1] = tc
    # one call site of the inlined _up (each inlined copy costs compile time); a minimum
    # is the maximum of -v, with the row's value and history kept negated meanwhile
    for j in range(nw + len(_ROWS) + 1):  # wheels, the rows above, chassis vx
        if j < nw:
            k = PK_WHEEL_FY + j
            v = diag[D_WHEEL + 2 * j + 1]
            sign = 1.0
        elif j < nw + len(_ROWS):
            k = _ROWS[j - nw]
            v = diag[_SLOTS[j - nw]]
            sign = _SIGNS[j - nw]
        else:
            k = PK_VX_MIN
            v = vx
            sign = -1.0
        peaks[k, 0] *= sign
        _up(peaks, k, sign * v, t, ts)
        peaks[k, 0] *= sign
    _max(peaks, PK_ENERGY_BALANCE, abs(energy_balance(diag) - e_ref), t)
    _max(peaks, PK_ENERGY_RESIDUAL, abs(energy_residual(diag, work) - r_ref), t)
    _first(peaks, PK_FIRST_CORNER, diag[D_CORNER_FORCE] > 0.0, t)
    _first(peaks, PK_FIRST_OBSTACLE, diag[D_OBSTACLE_FORCE] > 0.0, t)
    if at_switch:
        peaks[PK_SWITCH, 1] = t
