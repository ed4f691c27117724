"""The drive sprocket's tooth profile and its contact with the track pins (closed layout).

Each gap between two teeth is a seat and two flanks: the seat is the inner half of a
circle of radius r_g centred at r_s = r_p + (r_g - r_pin) from the axis (so a pin seated
at its bottom has its centre on the pitch circle r_p, the circle the track's pins wrap);
from the ends of that half circle the flanks run outwards, flaring by the flank angle
alpha (the pressure angle: a flank pushes a loaded pin out by F tan alpha, which the
track's tension holds in), up to the tip circle; the teeth's tops are arcs of the tip
circle. A pin is a circle of radius r_pin; its penetration is r_pin minus the distance of
its centre to the profile (seat arc, flank, tip arc or a tip corner of the nearest gap).
That distance is continuous in the pin's position, so the contact energy is continuous
wherever the pin goes (as the continuous track geometry's).
"""

import math

from numba import njit

from ..core import fixed_math as fm
from ..core.indices import (
    LP_FLANK_ANGLE,
    LP_PIN_RADIUS,
    LP_PITCH_RADIUS,
    LP_SEAT_RADIUS,
    LP_SHAPE,
    LP_TEETH,
    LP_TIP_RADIUS,
)
from ..core.jit import INLINE
from . import teeth as _teeth

seat_centre_radius = njit(**INLINE)(_teeth.seat_centre_radius)
flank_length = njit(**INLINE)(_teeth.flank_length)


@njit(**INLINE)
def _nearer(best, bx, by, px, py, qx, qy):
    """The nearer of the current nearest point (bx, by) at squared distance best and the
    point q, to p."""
    d = (px - qx) ** 2 + (py - qy) ** 2
    if d < best:
        return d, qx, qy
    return best, bx, by


@njit(**INLINE)
def tooth_shape(lp):
    """The profile's constants, once per profile rather than once per pin (they took most
    of the teeth's time; closed_track.closed_vector stores them in the LP_* vector, where
    the contact kernel reads them, stored_shape): (r_g, r_t, r_pin, r_s, pitch angle, the
    flank's direction cos and sin alpha, tan alpha, the flank's length, then the tip arc's
    ends, the flank's corner and the half pitch, as cos and sin of their angles)."""
    rg = lp[LP_SEAT_RADIUS]
    rt = lp[LP_TIP_RADIUS]
    rpin = lp[LP_PIN_RADIUS]
    alpha = lp[LP_FLANK_ANGLE]
    rs = seat_centre_radius(lp[LP_PITCH_RADIUS], rg, rpin)
    pitch = 2.0 * math.pi / lp[LP_TEETH]
    sa, ca = fm.sincos(alpha)
    t_end = flank_length(rs, rg, rt, ca, sa)        # the flank from (0, rg) along (cos, sin) alpha
    s_corner, c_corner = fm.sincos(fm.atan2(rg + t_end * sa, rs + t_end * ca))
    s_half, c_half = fm.sincos(0.5 * pitch)
    return rg, rt, rpin, rs, pitch, ca, sa, fm.tan(alpha), t_end, c_corner, s_corner, c_half, s_half


@njit(**INLINE)
def stored_shape(lp):
    """tooth_shape(lp) as closed_track.closed_vector stored it in lp (LP_SHAPE on): the
    contact kernel reads the constants instead of computing them in every evaluation."""
    s = LP_SHAPE
    return (lp[s], lp[s + 1], lp[s + 2], lp[s + 3], lp[s + 4], lp[s + 5], lp[s + 6], lp[s + 7], lp[s + 8],
            lp[s + 9], lp[s + 10], lp[s + 11], lp[s + 12])


@njit(**INLINE)
def _tip_point(ox, oy, shape):
    """Nearest point to (ox, oy) (seen from the axis, the gap along x, oy >= 0) of the tooth
    top: the tip circle's arc from the flank's corner to the half pitch."""
    rt = shape[1]
    cc, sc, ch, sh = shape[9], shape[10], shape[11], shape[12]
    ro = math.sqrt(ox * ox + oy * oy)
    if ro == 0.0 or cc * oy - sc * ox < 0.0:      # at an angle before the corner
        return rt * cc, rt * sc
    if ch * oy - sh * ox > 0.0:                   # beyond the half pitch
        return rt * ch, rt * sh
    return rt * ox / ro, rt * oy / ro


@njit(**INLINE)
def _gap_nearest(a, b, shape):
    """Nearest point of the profile to the point (a, b) in the frame of the nearest gap (a
    along the gap's centre line from its seat centre, b across it, b >= 0: by symmetry one
    side), as (squared distance, a, b) of that point; shape: tooth_shape."""
    rg, rs, ca, sa, t_end = shape[0], shape[3], shape[5], shape[6], shape[8]
    best, na, nb = math.inf, 0.0, 0.0
    r = math.sqrt(a * a + b * b)
    if a <= 0.0 and r > 0.0:        # the seat's half circle
        best, na, nb = _nearer(best, na, nb, a, b, rg * a / r, rg * b / r)
    best, na, nb = _nearer(best, na, nb, a, b, 0.0, rg)
    t = min(max(a * ca + (b - rg) * sa, 0.0), t_end)   # along the flank
    best, na, nb = _nearer(best, na, nb, a, b, t * ca, rg + t * sa)
    tx, ty = _tip_point(rs + a, b, shape)
    best, na, nb = _nearer(best, na, nb, a, b, tx - rs, ty)
    return best, na, nb


@njit(**INLINE)
def _in_gap(a, b, rg, tan_alpha):
    """Is the point (a, b >= 0) inside the gap's seat or between its flanks?"""
    if a <= 0.0:
        return a * a + b * b < rg * rg
    return b < rg + a * tan_alpha


@njit(**INLINE)
def pin_on_teeth(dx, dy, angle, shape):
    """A pin at (dx, dy) from the sprocket axis, the sprocket turned by angle (CCW):
    (penetration, nx, ny, inside). The penetration is r_pin minus the distance to the
    profile (contact where > 0), (nx, ny) the unit direction that pushes the pin out of
    it; inside is True where the pin's centre lies inside a tooth (it went through).
    shape: tooth_shape."""
    rg, rt, rpin, rs, pitch, tan_alpha = shape[0], shape[1], shape[2], shape[3], shape[4], shape[7]
    r2 = dx * dx + dy * dy
    if r2 >= (rt + rpin) * (rt + rpin):   # most pins: far from the teeth
        return -1.0, 0.0, 0.0, False
    k = math.floor((fm.atan2(dy, dx) - angle) / pitch + 0.5)   # the nearest gap
    ga = angle + k * pitch
    uy, ux = fm.sincos(ga)
    a = dx * ux + dy * uy - rs
    b = -dx * uy + dy * ux
    side = 1.0 if b >= 0.0 else -1.0
    b = abs(b)
    inside = r2 < rt * rt and not _in_gap(a, b, rg, tan_alpha)
    d2, na, nb = _gap_nearest(a, b, shape)
    dist = math.sqrt(d2)
    if inside or dist == 0.0:
        return rpin + dist, 0.0, 0.0, inside
    ea = (a - na) / dist
    eb = side * (b - nb) / dist
    return rpin - dist, ea * ux - eb * uy, ea * uy + eb * ux, False


@njit(**INLINE)
def pin_on_sprocket(dx, dy, angle, lp):
    """pin_on_teeth for one pin, the profile from lp (LP_*)."""
    return pin_on_teeth(dx, dy, angle, tooth_shape(lp))
