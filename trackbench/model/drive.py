"""The drive of the closed layout: the torque it puts on the sprocket (forward positive:
the direction that moves the vehicle towards +x) and the rate of its controller's state."""

from numba import njit

from .jit import INLINE
from .layout import (DRIVE_SPEED, DRIVE_TORQUE, LP_CURVE, LP_DRIVE_KIND, LP_DRIVE_TORQUE, LP_GAIN_I, LP_GAIN_P,
                     LP_TARGET, LP_TORQUE_LIMIT)


@njit(**INLINE)
def _curve(lp, omega):
    """Torque of the torque-speed curve at forward sprocket speed omega: linear between
    its points, constant beyond the first and the last."""
    n = int(lp[LP_CURVE])
    x0 = lp[LP_CURVE + 1]
    if omega <= x0:
        return lp[LP_CURVE + 2]
    for k in range(1, n):
        x1 = lp[LP_CURVE + 1 + 2 * k]
        if omega <= x1:
            y0 = lp[LP_CURVE + 2 * k]
            y1 = lp[LP_CURVE + 2 + 2 * k]
            return y0 + (y1 - y0) * (omega - x0) / (x1 - x0)
        x0 = x1
    return lp[LP_CURVE + 2 * n]


@njit(**INLINE)
def drive_torque(lp, speed, omega, integral):
    """(torque, d integral / dt) at chassis speed `speed` (m/s), forward sprocket speed omega
    (rad/s) and the PI controller's integral of the speed error (m). The speed drive is a
    PI controller whose integral stops while the torque limit clips it the same way
    (anti-windup)."""
    kind = lp[LP_DRIVE_KIND]
    if kind == DRIVE_TORQUE:
        if lp[LP_CURVE] > 0:
            return _curve(lp, omega), 0.0
        return lp[LP_DRIVE_TORQUE], 0.0
    if kind == DRIVE_SPEED:
        err = lp[LP_TARGET] - speed
        raw = lp[LP_GAIN_P] * err + lp[LP_GAIN_I] * integral
        limit = lp[LP_TORQUE_LIMIT]
        if raw > limit:
            return limit, min(err, 0.0)
        if raw < -limit:
            return -limit, max(err, 0.0)
        return raw, err
    return 0.0, 0.0
