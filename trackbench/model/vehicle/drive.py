"""The drive of the closed layout: the torque it puts on the sprocket (forward positive:
the direction that moves the vehicle towards +x) and the rate of its controller's state;
and the drawbar on the chassis, as a vehicle engineer's drawbar test pulls it back.

The drawbar is a horizontal force at a chassis-fixed hitch: a constant load, plus, with the
towing rig, a dashpot from a carriage running at drive.target. The rig sets the slip: the
speed drive then holds the sprocket's pitch speed at drive.target / (1 - slip) while the
carriage holds the chassis near drive.target, whatever thrust that takes."""

from numba import njit

from ..core.indices import (
    DRIVE_SPEED,
    DRIVE_TORQUE,
    LP_CURVE,
    LP_DRAWBAR_LOAD,
    LP_DRIVE_KIND,
    LP_DRIVE_TORQUE,
    LP_GAIN_I,
    LP_GAIN_P,
    LP_HITCH_X,
    LP_HITCH_Y,
    LP_PITCH_RADIUS,
    LP_RIG_DAMPING,
    LP_RIG_SLIP,
    LP_TARGET,
    LP_TORQUE_LIMIT,
)
from ..core.jit import INLINE
from .kinematics import body_offset


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


@njit(**INLINE)
def held_speed(lp, vx, omega):
    """The speed the speed drive compares with drive.target: the chassis speed vx, or
    under the towing rig the sprocket's pitch speed omega r_p times (1 - slip), so that
    with the chassis at drive.target the slip is the rig's."""
    slip = lp[LP_RIG_SLIP]
    if slip > 0.0:
        return omega * lp[LP_PITCH_RADIUS] * (1.0 - slip)
    return vx


@njit(**INLINE)
def has_drawbar(lp):
    return lp[LP_DRAWBAR_LOAD] != 0.0 or lp[LP_RIG_SLIP] > 0.0


@njit(**INLINE)
def drawbar_force(lp, vx_hitch):
    """Horizontal force of the drawbar on the hitch moving at vx_hitch (forward positive:
    a load pulls back, so it is negative)."""
    f = -lp[LP_DRAWBAR_LOAD]
    if lp[LP_RIG_SLIP] > 0.0:
        f -= lp[LP_RIG_DAMPING] * (vx_hitch - lp[LP_TARGET])
    return f


@njit(**INLINE)
def drawbar_on_chassis(lp, vx, om, c, s):
    """The drawbar's generalised force on the chassis' x and pitch and its power, at chassis
    speed vx and pitch rate om (c, s: the pitch's cos and sin). Its power enters dW/dt, so
    the work-based energy residual still checks the integration."""
    rx, ry = body_offset(c, s, lp[LP_HITCH_X], lp[LP_HITCH_Y])
    v_hitch = vx - om * ry
    f = drawbar_force(lp, v_hitch)
    return f, -ry * f, f * v_hitch
