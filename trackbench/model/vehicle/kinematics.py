"""Kinematics, written once: chassis pitch and arm angles -> road-wheel centres, track
ends and their velocities. The right-hand sides, the event location and the output all
place the wheels and pins through these functions, so they agree to the last bit."""


import numpy as np
from numba import njit

from ..core import fixed_math as fm
from ..core.bundles import ARM_COLS, ARM_COS, ARM_SIN
from ..core.indices import ARMS_LENGTH, ARMS_PX, ARMS_PY, Q_ARM, Q_PITCH, Q_X, Q_Y
from ..core.indices_jit import q_pin
from ..core.jit import INLINE, KERNEL


@njit(**INLINE)
def body_offset(c, s, bx, by):
    """R(theta) (bx, by): a body point relative to the chassis mass centre, in the world."""
    return c * bx - s * by, s * bx + c * by


@njit(**INLINE)
def wheel_offset(c, s, arms, i, la, cb, sb):
    """Road-wheel centre of arm i relative to the chassis mass centre: pivot + l e_i,
    e_i = (cos beta_i, sin beta_i), beta_i = pitch + phi_i."""
    px, py = body_offset(c, s, arms[i, ARMS_PX], arms[i, ARMS_PY])
    return px + la * cb, py + la * sb


@njit(**INLINE)
def _free_pins(coords, nw, last, out):
    """The free pins' coordinates (or velocities: coords = q') into out[1:last + 1]."""
    for b in range(1, last + 1):
        k = q_pin(nw, b)
        out[b, 0] = coords[k]
        out[b, 1] = coords[k + 1]


@njit(**INLINE)
def place_wheels(q, par, arms, wc, arm):
    """Road-wheel centres of configuration q into wc; cos and sin of each arm's absolute
    angle into arm (Work.arm columns). Returns (cos, sin) of the pitch."""
    s, c = fm.sincos(q[Q_PITCH])
    for i in range(arms.shape[0]):
        la = arms[i, ARMS_LENGTH]
        beta = q[Q_PITCH] + q[Q_ARM + i]
        sb, cb = fm.sincos(beta)
        arm[i, ARM_COS] = cb
        arm[i, ARM_SIN] = sb
        rx, ry = wheel_offset(c, s, arms, i, la, cb, sb)
        wc[i, 0] = q[Q_X] + rx
        wc[i, 1] = q[Q_Y] + ry
    return c, s


@njit(**INLINE)
def wheel_velocities(qd, par, arms, wv, arm, c, s):
    """Road-wheel centre velocities (after place_wheels)."""
    om = qd[Q_PITCH]
    for i in range(arms.shape[0]):
        la = arms[i, ARMS_LENGTH]
        cb = arm[i, ARM_COS]
        sb = arm[i, ARM_SIN]
        rx, ry = wheel_offset(c, s, arms, i, la, cb, sb)
        wv[i, 0] = qd[Q_X] - om * ry - qd[Q_ARM + i] * la * sb
        wv[i, 1] = qd[Q_Y] + om * rx + qd[Q_ARM + i] * la * cb


@njit(**INLINE)
def place(q, par, arms, ends, apos, wc, arm):
    """Pin and wheel-centre positions of configuration q into apos and wc (the paper's
    layout: pins 0 and n_links on the chassis); cos and sin of each arm's absolute angle
    into arm. Returns (cos, sin) of the pitch."""
    n_links = apos.shape[0] - 1
    c, s = place_wheels(q, par, arms, wc, arm)
    for e in range(2):
        b = 0 if e == 0 else n_links
        rx, ry = body_offset(c, s, ends[e, 0], ends[e, 1])
        apos[b, 0] = q[Q_X] + rx
        apos[b, 1] = q[Q_Y] + ry
    _free_pins(q, arms.shape[0], n_links - 1, apos)
    return c, s


@njit(**INLINE)
def positions(q, qd, par, arms, ends, apos, avel, wc, wv, arm):
    """Positions (place) and velocities of the pins and wheel centres."""
    c, s = place(q, par, arms, ends, apos, wc, arm)
    n_links = avel.shape[0] - 1
    om = qd[Q_PITCH]
    wheel_velocities(qd, par, arms, wv, arm, c, s)
    for e in range(2):
        b = 0 if e == 0 else n_links
        rx, ry = body_offset(c, s, ends[e, 0], ends[e, 1])
        avel[b, 0] = qd[Q_X] - om * ry
        avel[b, 1] = qd[Q_Y] + om * rx
    _free_pins(qd, arms.shape[0], n_links - 1, avel)
    return c, s


@njit(**KERNEL)
def place_samples(qs, par, arms, ends, pins, wheels):
    """place() for every row of qs (output samples): pins (n, n_pins, 2), wheels (n, n_wheels, 2)."""
    arm = np.empty((arms.shape[0], ARM_COLS + 1))
    for k in range(qs.shape[0]):
        place(qs[k], par, arms, ends, pins[k], wheels[k], arm)
