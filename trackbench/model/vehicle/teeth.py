"""The sprocket's tooth geometry in plain Python (scenario validation and the drawings use
it without the compiler; model/vehicle/teeth_jit.py compiles the two formulas for the contact
kernel, whose docstring describes the profile)."""

import math


def pitch_radius(link_pitch, teeth):
    """r_p = p / (2 sin(pi / N)): the seats of an N-tooth sprocket one pitch apart."""
    from ..core.fixed_math import sin  # numba: loaded when first needed
    return link_pitch / (2.0 * sin(math.pi / teeth))


def seat_centre_radius(pitch_radius, seat_radius, pin_radius):
    """Distance of the seat centres from the axis: a seated pin's centre on the pitch circle."""
    return pitch_radius + seat_radius - pin_radius


def flank_length(rs, rg, rt, cos_alpha, sin_alpha):
    """Length of a flank at angle alpha from the seat's half circle to the tip circle."""
    b = rs * cos_alpha + rg * sin_alpha
    return -b + math.sqrt(max(b * b - (rs * rs + rg * rg - rt * rt), 0.0))


def profile(teeth, pitch_radius, seat_radius, tip_radius, pin_radius, angle=0.0, per_arc=12,
            flank_angle=math.radians(15.0)):
    """The tooth profile as a closed polyline (n, 2) about the axis, for drawing (the C
    library's sines do); angles in rad."""
    import numpy as np
    rg, rt, al = seat_radius, tip_radius, flank_angle
    rs = pitch_radius + seat_radius - pin_radius
    pitch = 2.0 * math.pi / teeth
    t_end = flank_length(rs, rg, rt, math.cos(al), math.sin(al))
    corner = math.atan2(rg + t_end * math.sin(al), rs + t_end * math.cos(al))
    local = []          # one gap and the tooth top after it, in the gap's frame (x along the gap)
    for t in np.linspace(t_end, 0.0, max(2, per_arc // 3)):          # flank on the -b side, inwards
        local.append((rs + t * math.cos(al), -(rg + t * math.sin(al))))
    for f in np.linspace(-0.5 * math.pi, 0.5 * math.pi, per_arc)[1:-1]:   # the seat's inner half circle
        local.append((rs - rg * math.cos(f), rg * math.sin(f)))
    for t in np.linspace(0.0, t_end, max(2, per_arc // 3)):          # flank on the +b side, outwards
        local.append((rs + t * math.cos(al), rg + t * math.sin(al)))
    for f in np.linspace(corner, pitch - corner, per_arc)[1:-1]:     # tooth top
        local.append((rt * math.cos(f), rt * math.sin(f)))
    local = np.array(local)
    pts = []
    for k in range(teeth):
        g = angle + k * pitch
        c, s = math.cos(g), math.sin(g)
        pts.append(np.column_stack([c * local[:, 0] - s * local[:, 1], s * local[:, 0] + c * local[:, 1]]))
    pts = np.vstack(pts)
    return np.vstack([pts, pts[:1]])

