"""Contact onsets and releases inside a rejected step.

A penalty force k max(reach - s, 0) is continuous where a contact starts or ends, but its
rate jumps (by ~k v / m): a step across such a kink is rejected again and again while the
controller shrinks it. Here the gap (reach - s) of every candidate pair is followed along
the quintic Hermite interpolant of the rejected step (positions only: cheap, and accurate
because the kink barely disturbs positions), and the first sign change is found by
bisection, so that the retried step ends right after the kink.

A pair is "valid" where its force law applies (foot on the link or segment, the convex
wedge, the segment a pin may press on) and in contact where it is valid and its gap is
positive: the same tests as the force kernels, from model/contact/gaps.py, on points placed by
model/vehicle/kinematics.py.
"""

import math

from numba import njit
from numba.extending import overload

from ...model.contact.gaps import (
    ground_distance,
    link_frame,
    pin_cap_weight,
    pin_ground_selection,
    pin_segment_valid,
    point_on_link,
    segment_coords,
)
from ...model.contact.laws import GEOMETRY_CONTINUOUS
from ...model.contact.laws_jit import ramps_in
from ...model.core import fixed_math as fm
from ...model.core.bundles import ClosedEventWork
from ...model.core.indices import (
    ARMS_LENGTH,
    ARMS_REACH,
    G_REACH,
    K_CORNER_LINK,
    K_CORNER_PIN,
    K_GUIDE_LINK,
    K_GUIDE_PIN,
    K_PIN_GROUND,
    K_TEETH,
    K_WHEEL_LINK,
    K_WHEEL_PIN,
    LP_SPROCKET_X,
    LP_SPROCKET_Y,
    LP_TOOTH_DAMPING,
    N_KINDS,
    NB_COUNT,
    P_CONTACT_DAMPING,
    P_CONTACT_GEOMETRY,
    P_DAMPING_RAMP,
    P_PAD_GROUND,
    P_SOIL,
    PN_NQ,
    Q_ARM,
    Q_PITCH,
    Q_X,
    Q_Y,
    SEG_LENGTH,
)
from ...model.core.indices_jit import q_idler, q_pin, q_sprocket
from ...model.core.jit import BORROW, INLINE, KERNEL
from ...model.dynamics.closed_track_jit import guide_offset, place_closed
from ...model.ground.soil_jit import KINK_TOL, N_KINKS, soil_kink
from ...model.vehicle.kinematics import body_offset, place, wheel_offset
from ...model.vehicle.teeth_jit import pin_on_teeth, tooth_shape
from .hermite import coordinate, quintic_basis

BISECTIONS = 24


def _is_closed(ev):
    return getattr(ev, "instance_class", None) is ClosedEventWork


@njit(**INLINE)
def _paper_pin_at(b, w, step, nq, m, n_links):
    """Position of pin b along the step (pins 0 and n_links ride on the chassis)."""
    if b == 0 or b == n_links:
        e = 0 if b == 0 else 1
        th = coordinate(w, step, Q_PITCH, nq)
        rx, ry = body_offset(fm.cos(th), fm.sin(th), m.ends[e, 0], m.ends[e, 1])
        return coordinate(w, step, Q_X, nq) + rx, coordinate(w, step, Q_Y, nq) + ry
    k = q_pin(m.arms.shape[0], b)
    return coordinate(w, step, k, nq), coordinate(w, step, k + 1, nq)


@njit(**INLINE)
def _closed_pin_at(b, w, step, nq, m, n_links):
    """Position of pin row b of the closed loop along the step (row 0 is pin n_links, row
    n_links + 1 pin 1: the loop wraps round)."""
    if b == 0:
        b = n_links
    elif b > n_links:
        b -= n_links
    k = q_pin(m.arms.shape[0], b)
    return coordinate(w, step, k, nq), coordinate(w, step, k + 1, nq)


def _pin_at(b, w, step, nq, m, n_links, ev):
    """_paper_pin_at or _closed_pin_at by the layout (the type of ev): a paper-layout run
    never compiles the closed layout's event code."""
    raise NotImplementedError("compiled only")


@overload(_pin_at, jit_options=KERNEL)
def _pin_at_impl(b, w, step, nq, m, n_links, ev):
    if _is_closed(ev):
        return lambda b, w, step, nq, m, n_links, ev: _closed_pin_at(b, w, step, nq, m, n_links)
    return lambda b, w, step, nq, m, n_links, ev: _paper_pin_at(b, w, step, nq, m, n_links)


def _place_ends(y0, y1, nq, m, ev):
    """Pins, wheels (and idler and rollers) at both ends of the step into ev."""
    raise NotImplementedError("compiled only")


@overload(_place_ends, jit_options=KERNEL)
def _place_ends_impl(y0, y1, nq, m, ev):
    if _is_closed(ev):
        def closed(y0, y1, nq, m, ev):
            place_closed(y0[:nq], m, ev.pins0, ev.wheels0, ev.arm, ev.guides0)
            place_closed(y1[:nq], m, ev.pins1, ev.wheels1, ev.arm, ev.guides1)
        return closed

    def paper(y0, y1, nq, m, ev):
        place(y0[:nq], m.par, m.arms, m.ends, ev.pins0, ev.wheels0, ev.arm)
        place(y1[:nq], m.par, m.arms, m.ends, ev.pins1, ev.wheels1, ev.arm)
    return paper


def _guide_at(j, w, step, nq, m, ev):
    """Centre of guide j (idler, roller) along the step (closed layout only)."""
    raise NotImplementedError("compiled only")


@overload(_guide_at, jit_options=KERNEL)
def _guide_at_impl(j, w, step, nq, m, ev):
    if _is_closed(ev):
        def closed(j, w, step, nq, m, ev):
            th = coordinate(w, step, Q_PITCH, nq)
            sl = coordinate(w, step, q_idler(m.arms.shape[0], ev.pins0.shape[0] - 1), nq)
            rx, ry, _, _ = guide_offset(j, sl, m, fm.cos(th), fm.sin(th))
            return coordinate(w, step, Q_X, nq) + rx, coordinate(w, step, Q_Y, nq) + ry
        return closed
    return lambda j, w, step, nq, m, ev: (0.0, 0.0)


def _guide_end(j, e, ev):
    """Centre of guide j at end e of the step (closed layout only)."""
    raise NotImplementedError("compiled only")


@overload(_guide_end, jit_options=KERNEL)
def _guide_end_impl(j, e, ev):
    if _is_closed(ev):
        def closed(j, e, ev):
            g = ev.guides0 if e == 0 else ev.guides1
            return g[j, 0], g[j, 1]
        return closed
    return lambda j, e, ev: (0.0, 0.0)


@njit(**INLINE)
def _teeth_gap(px, py, q, lp, shape):
    """r_pin - distance of the pin at (px, py) to the tooth profile (in contact where > 0:
    model/sprocket.py; shape its tooth_shape), q = (x, y, pitch, sprocket angle psi) of
    chassis and sprocket; the axis placed as loop.py places it."""
    x, y, th, psi = q
    ax, ay = body_offset(fm.cos(th), fm.sin(th), lp[LP_SPROCKET_X], lp[LP_SPROCKET_Y])
    return pin_on_teeth(px - (x + ax), py - (y + ay), th + psi, shape)[0]


def _teeth_gap_at(b, t, step, nq, m, n_links, ev):
    """_teeth_gap of pin b at fraction t of the step (closed layout only)."""
    raise NotImplementedError("compiled only")


@overload(_teeth_gap_at, jit_options=KERNEL)
def _teeth_gap_at_impl(b, t, step, nq, m, n_links, ev):
    if _is_closed(ev):
        def closed(b, t, step, nq, m, n_links, ev):
            w = quintic_basis(t)
            px, py = _closed_pin_at(b, w, step, nq, m, n_links)
            q = (coordinate(w, step, Q_X, nq), coordinate(w, step, Q_Y, nq), coordinate(w, step, Q_PITCH, nq),
                 coordinate(w, step, q_sprocket(m.arms.shape[0], n_links), nq))
            return _teeth_gap(px, py, q, m.loop, tooth_shape(m.loop))
        return closed
    return lambda b, t, step, nq, m, n_links, ev: -1.0


@njit(**INLINE)
def _wheel_at(i, w, step, nq, m):
    th = coordinate(w, step, Q_PITCH, nq)
    beta = th + coordinate(w, step, Q_ARM + i, nq)
    rx, ry = wheel_offset(fm.cos(th), fm.sin(th), m.arms, i, m.arms[i, ARMS_LENGTH], fm.cos(beta),
                          fm.sin(beta))
    return coordinate(w, step, Q_X, nq) + rx, coordinate(w, step, Q_Y, nq) + ry


@njit(**INLINE)
def _inner(kind):
    """A round body pressing the track from inside (road wheel, idler, roller)?"""
    return kind == K_WHEEL_LINK or kind == K_WHEEL_PIN or kind == K_GUIDE_LINK or kind == K_GUIDE_PIN


@njit(**INLINE)
def _on_pin(kind):
    return kind == K_WHEEL_PIN or kind == K_CORNER_PIN or kind == K_GUIDE_PIN


@njit(**INLINE)
def _reach(kind, i, m):
    if kind == K_WHEEL_LINK or kind == K_WHEEL_PIN:
        return m.arms[i, ARMS_REACH]   # wheel radius + pad h_w, the station's own
    if kind == K_GUIDE_LINK or kind == K_GUIDE_PIN:
        return m.guides[i, G_REACH]
    return m.par[P_PAD_GROUND]


@njit(**INLINE)
def _pair(kind, p, a, bb, c, reach, par):
    """(valid, reach - s) of point p against the link a -> bb (link kinds) or against the
    cap of pin a after the link c -> a where it acts (pin kinds, gaps.pin_cap_weight);
    points are (x, y) tuples."""
    tx, ty, length = link_frame(a[0], a[1], bb[0], bb[1])
    if not _on_pin(kind):
        d0, s = point_on_link(p[0], p[1], a[0], a[1], tx, ty)
        if kind == K_CORNER_LINK:
            s = -s  # a corner is measured along the outer normal
        return 0.0 <= d0 <= length and s > 0.0, reach - s
    ux, uy, _ = link_frame(c[0], c[1], a[0], a[1])
    dx = p[0] - a[0]
    dy = p[1] - a[1]
    weight = pin_cap_weight(p[0], p[1], a[0], a[1], ux, uy, tx, ty, _inner(kind),
                            par[P_CONTACT_GEOMETRY] == GEOMETRY_CONTINUOUS)
    return weight != 0, reach - math.sqrt(dx * dx + dy * dy)


@njit(**INLINE)
def _pin_ground(px, py, sj, m, row):
    """(valid, h_g - s) of a pin at P on segment sj, by the kernel's selection rule."""
    hg = m.par[P_PAD_GROUND]
    if m.par[P_CONTACT_GEOMETRY] == GEOMETRY_CONTINUOUS:   # one contact with the nearest point
        return True, hg - ground_distance(px, py, m.seg, m.nbr, row)[0]
    inside, n_below, best = pin_ground_selection(px, py, m.seg, m.nbr, row, hg)
    lam, s, _ = segment_coords(px, py, m.seg, sj)
    return pin_segment_valid(lam, s, m.seg[sj, SEG_LENGTH], inside, n_below, best), hg - s


@njit(**INLINE)
def _probe_at(kind, i, w, step, nq, m, ev):
    """The wheel, idler, roller or corner of a pair along the step."""
    if kind == K_WHEEL_LINK or kind == K_WHEEL_PIN:
        return _wheel_at(i, w, step, nq, m)
    if kind == K_GUIDE_LINK or kind == K_GUIDE_PIN:
        return _guide_at(i, w, step, nq, m, ev)
    return m.corners[i, 0], m.corners[i, 1]


@njit(**BORROW)   # called, not inlined: each inlined copy cost ~25 s of compile time
def _gap_at(kind, i, b, t, step, nq, m, n_links, ev, kink=-1):
    """(valid, gap) of one candidate pair at fraction t of the step: kind K_*, i the wheel,
    guide or corner (the pin for K_PIN_GROUND and K_TEETH), b the link or pin (the segment
    for K_PIN_GROUND). kink >= 0 (soft soil, K_PIN_GROUND): the pin's sinkage minus the
    depth of that kink of the soil's pressure law instead."""
    if kind == K_TEETH:
        return True, _teeth_gap_at(i, t, step, nq, m, n_links, ev)
    w = quintic_basis(t)
    if kind == K_PIN_GROUND:
        px, py = _pin_at(i, w, step, nq, m, n_links, ev)
        valid, g = _pin_ground(px, py, b, m, m.nbr_rows[K_PIN_GROUND] + i)
        if kink >= 0:
            g = soil_kink(px, g, kink, m.par, m.rut)
        return valid, g
    p = _probe_at(kind, i, w, step, nq, m, ev)
    a = _pin_at(b, w, step, nq, m, n_links, ev)
    bb = _pin_at(b + 1, w, step, nq, m, n_links, ev)
    c = a
    if _on_pin(kind):
        c = _pin_at(b - 1, w, step, nq, m, n_links, ev)
    return _pair(kind, p, a, bb, c, _reach(kind, i, m), m.par)


@njit(**INLINE)
def _probe_end(kind, i, e, m, ev):
    """_probe_at at end e of the step, from the points placed there."""
    if kind == K_WHEEL_LINK or kind == K_WHEEL_PIN:
        wheels = ev.wheels0 if e == 0 else ev.wheels1
        return wheels[i, 0], wheels[i, 1]
    if kind == K_GUIDE_LINK or kind == K_GUIDE_PIN:
        return _guide_end(i, e, ev)
    return m.corners[i, 0], m.corners[i, 1]


@njit(**INLINE)
def _gap_end(kind, i, b, e, m, ev):
    """_gap_at at end e of the step, from the points placed there."""
    pins = ev.pins0 if e == 0 else ev.pins1
    if kind == K_PIN_GROUND:
        return _pin_ground(pins[i, 0], pins[i, 1], b, m, m.nbr_rows[K_PIN_GROUND] + i)
    p = _probe_end(kind, i, e, m, ev)
    bp = b - 1 if _on_pin(kind) else b
    bn = b + 1 if b + 1 < pins.shape[0] else 1      # the closed loop: pin 1 follows pin n_links
    return _pair(kind, p, (pins[b, 0], pins[b, 1]), (pins[bn, 0], pins[bn, 1]), (pins[bp, 0], pins[bp, 1]),
                 _reach(kind, i, m), m.par)


@njit(**BORROW)
def _bisect(kind, i, b, g0, level, step, nq, m, n_links, ev, kink=-1):
    """Upper end of the bracket where the gap (or the soil's kink function) crosses level
    (just after the kink)."""
    lo = 0.0
    hi = 1.0
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        _, gm = _gap_at(kind, i, b, mid, step, nq, m, n_links, ev, kink)
        if (gm > level) == (g0 > level):
            lo = mid
        else:
            hi = mid
    return hi


@njit(**INLINE)
def _switch(pair, g0, g1, valid, ramp, step, nq, m, ev, best):
    """best, or the fraction of the step just after the gap of pair = (kind, i, b) crosses
    zero (a contact starts or ends) or, for a dashpot that ramps in (ramp >= 0), the
    ramp's depth, if earlier. Pairs whose validity (foot on link, wedge, acting segment)
    changes are left alone."""
    level = 0.0 if (g0 > 0.0) != (g1 > 0.0) else ramp
    if valid and level >= 0.0 and (g0 > level) != (g1 > level):
        kind, i, b = pair
        return min(best, _bisect(kind, i, b, g0, level, step, nq, m, ev.pins0.shape[0] - 1, ev))
    return best


def _teeth_switch(step, nq, m, ev, best):
    """_switch for every pin against the sprocket's teeth (closed layout; best unchanged
    for the paper's)."""
    raise NotImplementedError("compiled only")


@overload(_teeth_switch, jit_options=KERNEL)
def _teeth_switch_impl(step, nq, m, ev, best):
    if _is_closed(ev):
        def closed(step, nq, m, ev, best):
            y0, _, y1, _, _ = step
            i_s = q_sprocket(m.arms.shape[0], ev.pins0.shape[0] - 1)
            # the teeth's own dashpot (loop.py _teeth), viscous where set
            ramp = m.par[P_DAMPING_RAMP] if m.loop[LP_TOOTH_DAMPING] > 0.0 else -1.0
            shape = tooth_shape(m.loop)
            q0 = (y0[Q_X], y0[Q_Y], y0[Q_PITCH], y0[i_s])
            q1 = (y1[Q_X], y1[Q_Y], y1[Q_PITCH], y1[i_s])
            for b in range(1, ev.pins0.shape[0]):
                g0 = _teeth_gap(ev.pins0[b, 0], ev.pins0[b, 1], q0, m.loop, shape)
                g1 = _teeth_gap(ev.pins1[b, 0], ev.pins1[b, 1], q1, m.loop, shape)
                best = _switch((K_TEETH, b, 0), g0, g1, True, ramp, step, nq, m, ev, best)
            return best
        return closed
    return lambda step, nq, m, ev, best: best


@njit(**BORROW)
def first_contact_switch(y0, f0, y1, f1, h, m, ev):
    """Smallest t in (0, 1] at which some candidate contact starts or ends along the
    step's interpolant - or, with the viscous law, reaches the end of its dashpot's ramp,
    a kink of the same kind, or on soft soil a pin crosses a kink of the soil's pressure
    law (_soil_switch); 2.0 if none. ev: EventWork (the paper's layout) or ClosedEventWork
    (the closed one: the idler, rollers and teeth as well)."""
    nq = m.pins[PN_NQ]
    _place_ends(y0, y1, nq, m, ev)
    step = (y0, f0, y1, f1, h)
    ramp = m.par[P_DAMPING_RAMP] if ramps_in(int(m.par[P_CONTACT_DAMPING])) else -1.0
    soil = m.par[P_SOIL] != 0.0
    best = 2.0
    for kind in range(N_KINDS):
        for row in range(m.nbr_rows[kind], m.nbr_rows[kind + 1]):
            i = row - m.nbr_rows[kind]
            for j in range(m.nbr[row, NB_COUNT]):
                b = m.nbr[row, 1 + j]
                valid = True
                g0 = 0.0
                g1 = 0.0
                for e in range(2):   # one inlined copy of _gap_end for both ends
                    v, g = _gap_end(kind, i, b, e, m, ev)
                    valid = valid and v
                    if e == 0:
                        g0 = g
                    else:
                        g1 = g
                best = _switch((kind, i, b), g0, g1, valid, ramp, step, nq, m, ev, best)
                if soil and kind == K_PIN_GROUND and valid and (g0 > 0.0 or g1 > 0.0):
                    best = _soil_switch(i, b, (g0, g1), best, step, nq, m, ev)
    return _teeth_switch(step, nq, m, ev, best)


@njit(**BORROW)
def _soil_switch(i, b, sinkage, best, step, nq, m, ev):
    """min(best, the smallest t at which pin i on soft soil (on segment b) crosses a kink of
    the soil's pressure law, soil_force.soil_kink). A pin left on its loading curve by the
    last step (z = z_m) counts as above z_m: the kink is where it comes back below. Only a
    crossing before best is bisected (most steps hold several: one look at best first)."""
    n_links = ev.pins0.shape[0] - 1
    for kink in range(N_KINKS):
        f0 = soil_kink(ev.pins0[i, 0], sinkage[0], kink, m.par, m.rut)
        f1 = soil_kink(ev.pins1[i, 0], sinkage[1], kink, m.par, m.rut)
        if (f0 > -KINK_TOL) == (f1 > -KINK_TOL):
            continue
        if best < 1.0:
            _, f_best = _gap_at(K_PIN_GROUND, i, b, best, step, nq, m, n_links, ev, kink)
            if (f_best > -KINK_TOL) == (f0 > -KINK_TOL):
                continue
        best = min(best, _bisect(K_PIN_GROUND, i, b, f0, -KINK_TOL, step, nq, m, n_links, ev, kink))
    return best
