"""Contact onsets and releases inside a rejected step.

A penalty force k max(reach - s, 0) is continuous where a contact starts or ends, but its
rate jumps (by ~k v / m): a step across such a kink is rejected again and again while the
controller shrinks it. Here the gap (reach - s) of every candidate pair is followed along
the quintic Hermite interpolant of the rejected step (positions only: cheap, and accurate
because the kink barely disturbs positions), and the first sign change is found by
bisection, so that the retried step ends right after the kink.

A pair is "valid" where its force law applies (foot on the link or segment, the convex
wedge, the segment a pin may press on) and in contact where it is valid and its gap is
positive: the same tests as the force kernels, from model/gaps.py, on points placed by
model/kinematics.py.
"""

import math

from numba import njit

from ..model.gaps import (ground_distance, link_frame, pin_cap_weight, pin_ground_selection, pin_segment_valid, point_on_link,
                          segment_coords)
from ..model.contact_laws import DAMPING_VISCOUS, GEOMETRY_CONTINUOUS
from ..model.jit import BORROW, INLINE, KERNEL
from ..model.soil_force import KINK_TOL, N_KINKS, soil_kink
from ..model.kinematics import body_offset, place, wheel_offset
from ..model.index import nq_of, q_pin
from ..model.layout import (
    K_CORNER_LINK, K_CORNER_PIN, K_PIN_GROUND, K_WHEEL_LINK, K_WHEEL_PIN, N_EVENT_KINDS, NB_COUNT, P_ARM_LENGTH, P_CONTACT_DAMPING, P_CONTACT_GEOMETRY, P_DAMPING_RAMP, SEG_LENGTH, P_PAD_GROUND, P_PAD_WHEEL, P_SOIL, P_WHEEL_RADIUS, Q_ARM, Q_PITCH, Q_X, Q_Y,
)
from .hermite import coordinate, quintic_basis

BISECTIONS = 24


@njit(**INLINE)
def _pin_at(b, w, step, nq, m, n_links):
    """Position of pin b along the step (pins 0 and n_links ride on the chassis)."""
    if b == 0 or b == n_links:
        e = 0 if b == 0 else 1
        th = coordinate(w, step, Q_PITCH, nq)
        rx, ry = body_offset(math.cos(th), math.sin(th), m.ends[e, 0], m.ends[e, 1])
        return coordinate(w, step, Q_X, nq) + rx, coordinate(w, step, Q_Y, nq) + ry
    k = q_pin(m.arms.shape[0], b)
    return coordinate(w, step, k, nq), coordinate(w, step, k + 1, nq)


@njit(**INLINE)
def _wheel_at(i, w, step, nq, m):
    th = coordinate(w, step, Q_PITCH, nq)
    beta = th + coordinate(w, step, Q_ARM + i, nq)
    rx, ry = wheel_offset(math.cos(th), math.sin(th), m.arms, i, m.par[P_ARM_LENGTH], math.cos(beta),
                          math.sin(beta))
    return coordinate(w, step, Q_X, nq) + rx, coordinate(w, step, Q_Y, nq) + ry


@njit(**INLINE)
def _reach(kind, par):
    if kind == K_WHEEL_LINK or kind == K_WHEEL_PIN:
        return par[P_WHEEL_RADIUS] + par[P_PAD_WHEEL]
    return par[P_PAD_GROUND]


@njit(**INLINE)
def _pair(kind, p, a, bb, c, par):
    """(valid, reach - s) of point p against the link a -> bb (link kinds) or against the
    cap of pin a after the link c -> a where it acts (pin kinds, gaps.pin_cap_weight);
    points are (x, y) tuples."""
    reach = _reach(kind, par)
    tx, ty, length = link_frame(a[0], a[1], bb[0], bb[1])
    if kind == K_WHEEL_LINK or kind == K_CORNER_LINK:
        d0, s = point_on_link(p[0], p[1], a[0], a[1], tx, ty)
        if kind == K_CORNER_LINK:
            s = -s  # a corner is measured along the outer normal
        return 0.0 <= d0 <= length and s > 0.0, reach - s
    ux, uy, _ = link_frame(c[0], c[1], a[0], a[1])
    dx = p[0] - a[0]
    dy = p[1] - a[1]
    weight = pin_cap_weight(p[0], p[1], a[0], a[1], ux, uy, tx, ty, kind == K_WHEEL_PIN,
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


@njit(**BORROW)   # called, not inlined: each inlined copy cost ~25 s of compile time
def _gap_at(kind, i, b, t, step, nq, m, n_links, kink):
    """(valid, gap) of one candidate pair at fraction t of the step: kind K_*, i the wheel
    or corner (the pin for K_PIN_GROUND), b the link or pin (the segment for K_PIN_GROUND).
    kink >= 0 (soft soil, K_PIN_GROUND): the pin's sinkage minus that kink's depth instead."""
    w = quintic_basis(t)
    if kind == K_PIN_GROUND:
        px, py = _pin_at(i, w, step, nq, m, n_links)
        valid, g = _pin_ground(px, py, b, m, m.nbr_rows[K_PIN_GROUND] + i)
        if kink >= 0:
            g = soil_kink(px, g, kink, m.par, m.rut)
        return valid, g
    if kind == K_WHEEL_LINK or kind == K_WHEEL_PIN:
        p = _wheel_at(i, w, step, nq, m)
    else:
        p = (m.corners[i, 0], m.corners[i, 1])
    a = _pin_at(b, w, step, nq, m, n_links)
    bb = _pin_at(b + 1, w, step, nq, m, n_links)
    c = a
    if kind == K_WHEEL_PIN or kind == K_CORNER_PIN:
        c = _pin_at(b - 1, w, step, nq, m, n_links)
    return _pair(kind, p, a, bb, c, m.par)


@njit(**INLINE)
def _gap_end(kind, i, b, pins, wheels, m):
    """_gap_at at an end of the step, from the points placed there."""
    if kind == K_PIN_GROUND:
        return _pin_ground(pins[i, 0], pins[i, 1], b, m, m.nbr_rows[K_PIN_GROUND] + i)
    if kind == K_WHEEL_LINK or kind == K_WHEEL_PIN:
        p = (wheels[i, 0], wheels[i, 1])
    else:
        p = (m.corners[i, 0], m.corners[i, 1])
    bp = b - 1 if (kind == K_WHEEL_PIN or kind == K_CORNER_PIN) else b
    return _pair(kind, p, (pins[b, 0], pins[b, 1]), (pins[b + 1, 0], pins[b + 1, 1]), (pins[bp, 0], pins[bp, 1]),
                 m.par)


@njit(**BORROW)
def _bisect(kind, i, b, g0, level, step, nq, m, n_links, kink=-1):
    """Upper end of the bracket where the gap (or the soil's kink function) crosses level
    (just after the kink)."""
    lo = 0.0
    hi = 1.0
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        _, gm = _gap_at(kind, i, b, mid, step, nq, m, n_links, kink)
        if (gm > level) == (g0 > level):
            lo = mid
        else:
            hi = mid
    return hi


@njit(**BORROW)
def first_contact_switch(y0, f0, y1, f1, h, m, ev):
    """Smallest t in (0, 1] at which some candidate contact starts or ends along the
    step's interpolant - or, with the viscous law, reaches the end of its dashpot's ramp,
    a kink of the same kind, or on soft soil a pin crosses a kink of the soil's pressure
    law (_soil_switch); 2.0 if none. Pairs whose validity (foot on link, wedge,
    acting segment) changes are left alone. ev: EventWork scratch."""
    nq = nq_of(y0.shape[0])
    n_links = ev.pins0.shape[0] - 1
    place(y0[:nq], m.par, m.arms, m.ends, ev.pins0, ev.wheels0, ev.arm)
    place(y1[:nq], m.par, m.arms, m.ends, ev.pins1, ev.wheels1, ev.arm)
    step = (y0, f0, y1, f1, h)
    ramp = m.par[P_DAMPING_RAMP] if m.par[P_CONTACT_DAMPING] == DAMPING_VISCOUS else -1.0
    soil = m.par[P_SOIL] != 0.0
    best = 2.0
    for kind in range(N_EVENT_KINDS):
        for row in range(m.nbr_rows[kind], m.nbr_rows[kind + 1]):
            i = row - m.nbr_rows[kind]
            for j in range(m.nbr[row, NB_COUNT]):
                b = m.nbr[row, 1 + j]
                valid = True
                g0 = 0.0
                g1 = 0.0
                for e in range(2):   # one inlined copy of _gap_end for both ends
                    v, g = _gap_end(kind, i, b, ev.pins0 if e == 0 else ev.pins1,
                                    ev.wheels0 if e == 0 else ev.wheels1, m)
                    valid = valid and v
                    if e == 0:
                        g0 = g
                    else:
                        g1 = g
                level = 0.0 if (g0 > 0.0) != (g1 > 0.0) else ramp
                if valid and level >= 0.0 and (g0 > level) != (g1 > level):
                    best = min(best, _bisect(kind, i, b, g0, level, step, nq, m, n_links))
                if soil and kind == K_PIN_GROUND and valid and (g0 > 0.0 or g1 > 0.0):
                    best = _soil_switch(i, b, (g0, g1), best, step, nq, m, ev)
    return best


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
            _, f_best = _gap_at(K_PIN_GROUND, i, b, best, step, nq, m, n_links, kink)
            if (f_best > -KINK_TOL) == (f0 > -KINK_TOL):
                continue
        best = min(best, _bisect(K_PIN_GROUND, i, b, f0, -KINK_TOL, step, nq, m, n_links, kink))
    return best
