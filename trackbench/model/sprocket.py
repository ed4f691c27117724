"""The drive sprocket's tooth profile and its contact with the track pins (closed layout).

The profile is a disc of the tip radius with N circular seats cut into its rim: seat k is
a circle of radius r_g centred at angle angle + 2 pi k / N, at r_p + (r_g - r_pin) from
the axis, so that a pin seated at the bottom of a seat has its centre on the pitch circle
(radius r_p: the circle the track's pins wrap around);
the tips are the arcs of the tip circle between seats, and each seat meets the tip circle
at two corners. A pin is a circle of radius r_pin; its penetration into the profile is
r_pin minus the distance of its centre from the profile's solid, found on the nearest seat
(the seat wall, or a corner where the wall's nearest point lies beyond the tip circle) or
the tip arc. That distance is continuous in the pin's position, so the contact energy is
continuous wherever the pin goes (the same property as the continuous track geometry).
"""

import math

from numba import njit

from .jit import INLINE
from .layout import (LP_PIN_RADIUS, LP_PITCH_RADIUS, LP_SEAT_RADIUS, LP_TEETH, LP_TIP_RADIUS)


@njit(**INLINE)
def seat_centre_radius(pitch_radius, seat_radius, pin_radius):
    """Distance of the seat centres from the axis: a seated pin's centre on the pitch circle."""
    return pitch_radius + seat_radius - pin_radius


@njit(**INLINE)
def _corner(dx, dy, r, ux, uy, rp, rg, rt):
    """The nearer of the two corners of the seat in direction (ux, uy) (where its circle,
    centred rp from the axis, meets the tip circle) to the point (dx, dy), all relative to
    the axis: (distance, its unit direction towards the point)."""
    a = (rp * rp + rt * rt - rg * rg) / (2.0 * rp)      # along u
    b = math.sqrt(max(rt * rt - a * a, 0.0))           # across u
    best = math.inf
    nx = ny = 0.0
    for sgn in (-1.0, 1.0):
        cx = a * ux - sgn * b * uy
        cy = a * uy + sgn * b * ux
        ex = dx - cx
        ey = dy - cy
        d = math.sqrt(ex * ex + ey * ey)
        if d < best:
            best = d
            nx, ny = ex / d, ey / d
    return best, nx, ny


@njit(**INLINE)
def pin_on_sprocket(dx, dy, angle, lp):
    """A pin at (dx, dy) from the sprocket axis, the sprocket turned by angle (CCW):
    (penetration, nx, ny, inside). The penetration is r_pin minus the distance to the
    profile (contact where > 0), (nx, ny) the unit direction that pushes the pin out of
    it; inside is True where the pin's centre lies inside a tooth (it went through)."""
    n = lp[LP_TEETH]
    rg = lp[LP_SEAT_RADIUS]
    rt = lp[LP_TIP_RADIUS]
    rpin = lp[LP_PIN_RADIUS]
    rp = seat_centre_radius(lp[LP_PITCH_RADIUS], rg, rpin)
    r = math.sqrt(dx * dx + dy * dy)
    if r >= rt + rpin or r == 0.0:
        return -1.0, 0.0, 0.0, False
    pitch = 2.0 * math.pi / n
    k = math.floor((math.atan2(dy, dx) - angle) / pitch + 0.5)   # the nearest seat
    ga = angle + k * pitch
    ux = math.cos(ga)
    uy = math.sin(ga)
    ex = dx - rp * ux
    ey = dy - rp * uy
    d = math.sqrt(ex * ex + ey * ey)
    if d < rg:                          # in the seat's circle
        if d == 0.0:
            return rpin - rg, -ux, -uy, False
        wx = rp * ux + rg * ex / d       # the wall point in line with the pin
        wy = rp * uy + rg * ey / d
        if wx * wx + wy * wy <= rt * rt:
            return rpin - (rg - d), -ex / d, -ey / d, False
        dist, nx, ny = _corner(dx, dy, r, ux, uy, rp, rg, rt)
        return rpin - dist, nx, ny, False
    if r <= rt:
        return rpin, dx / r, dy / r, True   # inside a tooth
    # beyond the tip circle: the tip arc in line with the pin, unless that point is in the seat
    tx = rt * dx / r - rp * ux
    ty = rt * dy / r - rp * uy
    if tx * tx + ty * ty >= rg * rg:
        return rpin - (r - rt), dx / r, dy / r, False
    dist, nx, ny = _corner(dx, dy, r, ux, uy, rp, rg, rt)
    return rpin - dist, nx, ny, False


def pitch_radius(link_pitch, teeth):
    """r_p = p / (2 sin(pi / N)): the seats of an N-tooth sprocket one pitch apart."""
    return link_pitch / (2.0 * math.sin(math.pi / teeth))


def profile(teeth, pitch_radius, seat_radius, tip_radius, pin_radius, angle=0.0, per_arc=12):
    """The tooth profile as a closed polyline (n, 2) about the axis, for drawing."""
    import numpy as np
    rg, rt = seat_radius, tip_radius
    rp = pitch_radius + seat_radius - pin_radius
    pitch = 2.0 * math.pi / teeth
    a = (rp * rp + rt * rt - rg * rg) / (2.0 * rp)
    half_tip = math.atan2(math.sqrt(max(rt * rt - a * a, 0.0)), a)     # seat corner, seen from the axis
    pts = []
    for k in range(teeth):
        g = angle + k * pitch
        gx, gy = rp * math.cos(g), rp * math.sin(g)
        # seat arc: from the corner at g - half_tip round the inside to g + half_tip
        c0 = math.atan2(rt * math.sin(g - half_tip) - gy, rt * math.cos(g - half_tip) - gx)
        c1 = math.atan2(rt * math.sin(g + half_tip) - gy, rt * math.cos(g + half_tip) - gx)
        if c1 > c0:
            c1 -= 2.0 * math.pi
        for t in np.linspace(c0, c1, per_arc):
            pts.append((gx + rg * math.cos(t), gy + rg * math.sin(t)))
        for t in np.linspace(g + half_tip, g + pitch - half_tip, max(2, per_arc // 3)):
            pts.append((rt * math.cos(t), rt * math.sin(t)))
    pts.append(pts[0])
    return np.array(pts)
