"""Contact onsets and releases inside a rejected step.

A penalty force k max(reach - s, 0) is continuous where a contact starts or ends, but its
rate jumps (by ~k v / m): a step across such a kink is rejected again and again while the
controller shrinks it. Here the gap (reach - s) of every candidate pair is followed along
the quintic Hermite interpolant of the rejected step (positions only: cheap, and accurate
because the kink barely disturbs positions), and the first sign change is found by
bisection, so that the retried step ends right after the kink.
"""

import math

from numba import njit

from ..model.layout import P_ARM_LENGTH, P_PAD_GROUND, P_PAD_WHEEL, P_WHEEL_RADIUS, Q_ARM, Q_PITCH, Q_X, Q_Y

BISECTIONS = 24


@njit(cache=True, error_model="numpy")
def _coord(y0, f0, y1, f1, h, t, k, nq):
    """Quintic Hermite of coordinate k at t in [0, 1] (same basis as monitor.py)."""
    t2 = t * t
    t3 = t2 * t
    t4 = t3 * t
    t5 = t4 * t
    return ((1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5) * y0[k]
            + h * (t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5) * y0[nq + k]
            + h * h * (0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5) * f0[nq + k]
            + (10.0 * t3 - 15.0 * t4 + 6.0 * t5) * y1[k]
            + h * (-4.0 * t3 + 7.0 * t4 - 3.0 * t5) * y1[nq + k]
            + h * h * (0.5 * t3 - t4 + 0.5 * t5) * f1[nq + k])


@njit(cache=True, error_model="numpy")
def _pin(b, n_links, y0, f0, y1, f1, h, t, nq, ends):
    """Position of pin b at t (pins 0 and n_links ride on the chassis)."""
    if b == 0 or b == n_links:
        e = 0 if b == 0 else 1
        x = _coord(y0, f0, y1, f1, h, t, Q_X, nq)
        y = _coord(y0, f0, y1, f1, h, t, Q_Y, nq)
        th = _coord(y0, f0, y1, f1, h, t, Q_PITCH, nq)
        c = math.cos(th)
        s = math.sin(th)
        return x + c * ends[e, 0] - s * ends[e, 1], y + s * ends[e, 0] + c * ends[e, 1]
    k = nq - 2 * (n_links - 1) + 2 * (b - 1)
    return _coord(y0, f0, y1, f1, h, t, k, nq), _coord(y0, f0, y1, f1, h, t, k + 1, nq)


@njit(cache=True, error_model="numpy")
def _wheel(i, y0, f0, y1, f1, h, t, nq, par, arms):
    x = _coord(y0, f0, y1, f1, h, t, Q_X, nq)
    y = _coord(y0, f0, y1, f1, h, t, Q_Y, nq)
    th = _coord(y0, f0, y1, f1, h, t, Q_PITCH, nq)
    beta = th + _coord(y0, f0, y1, f1, h, t, Q_ARM + i, nq)
    c = math.cos(th)
    s = math.sin(th)
    la = par[P_ARM_LENGTH]
    return (x + c * arms[i, 0] - s * arms[i, 1] + la * math.cos(beta),
            y + s * arms[i, 0] + c * arms[i, 1] + la * math.sin(beta))


@njit(cache=True, error_model="numpy")
def _pair_gap(kind, px, py, ax, ay, bx, by, cx, cy, reach):
    """(valid, reach - s) for point P against link A->B (kinds 0, 3) or against pin A in the
    wedge after the link C->A (kinds 1, 4); see _gap."""
    ex = bx - ax
    ey = by - ay
    length = math.sqrt(ex * ex + ey * ey)
    tx = ex / length
    ty = ey / length
    dx = px - ax
    dy = py - ay
    if kind == 0 or kind == 3:
        d0 = dx * tx + dy * ty
        s = dx * ty - dy * tx
        if kind == 3:
            s = -s
        return 0.0 <= d0 <= length and s > 0.0, reach - s
    ux = ax - cx
    uy = ay - cy
    cross = ux * ty - uy * tx
    wedge = dx * tx + dy * ty < 0.0 and dx * ux + dy * uy > 0.0
    convex = cross > 0.0 if kind == 1 else cross < 0.0
    return wedge and convex, reach - math.sqrt(dx * dx + dy * dy)


@njit(cache=True, error_model="numpy")
def _seg_gap(px, py, seg, j, hg):
    dx = px - seg[j, 0]
    dy = py - seg[j, 1]
    lam = dx * seg[j, 2] + dy * seg[j, 3]
    s = dx * seg[j, 5] + dy * seg[j, 6]
    return 0.0 <= lam <= seg[j, 4] and s > 0.0, hg - s


@njit(cache=True, error_model="numpy")
def _gap(kind, i, b, t, y0, f0, y1, f1, h, nq, n_links, par, arms, ends, seg, corners):
    """(valid, reach - s) of one candidate pair at t along the interpolant: kind 0
    wheel-link, 1 wheel-pin, 2 pin-segment (i = segment), 3 corner-link, 4 corner-pin
    (i = corner); valid = foot on the link / segment, or in the convex wedge."""
    if kind == 2:
        px, py = _pin(b, n_links, y0, f0, y1, f1, h, t, nq, ends)
        return _seg_gap(px, py, seg, i, par[P_PAD_GROUND])
    if kind == 0 or kind == 1:
        px, py = _wheel(i, y0, f0, y1, f1, h, t, nq, par, arms)
        reach = par[P_WHEEL_RADIUS] + par[P_PAD_WHEEL]
    else:
        px = corners[i, 0]
        py = corners[i, 1]
        reach = par[P_PAD_GROUND]
    ax, ay = _pin(b, n_links, y0, f0, y1, f1, h, t, nq, ends)
    bx, by = _pin(b + 1, n_links, y0, f0, y1, f1, h, t, nq, ends)
    cx, cy = ax, ay
    if kind == 1 or kind == 4:
        cx, cy = _pin(b - 1, n_links, y0, f0, y1, f1, h, t, nq, ends)
    return _pair_gap(kind, px, py, ax, ay, bx, by, cx, cy, reach)


@njit(cache=True, error_model="numpy")
def _points(y, nq, par, arms, ends, pins, wheels):
    """Pin and wheel-centre positions of state y (the ends of the step)."""
    n_links = pins.shape[0] - 1
    c = math.cos(y[Q_PITCH])
    s = math.sin(y[Q_PITCH])
    la = par[P_ARM_LENGTH]
    for e in range(2):
        b = 0 if e == 0 else n_links
        pins[b, 0] = y[Q_X] + c * ends[e, 0] - s * ends[e, 1]
        pins[b, 1] = y[Q_Y] + s * ends[e, 0] + c * ends[e, 1]
    off = nq - 2 * (n_links - 1)
    for b in range(1, n_links):
        pins[b, 0] = y[off + 2 * (b - 1)]
        pins[b, 1] = y[off + 2 * (b - 1) + 1]
    for i in range(arms.shape[0]):
        beta = y[Q_PITCH] + y[Q_ARM + i]
        wheels[i, 0] = y[Q_X] + c * arms[i, 0] - s * arms[i, 1] + la * math.cos(beta)
        wheels[i, 1] = y[Q_Y] + s * arms[i, 0] + c * arms[i, 1] + la * math.sin(beta)


@njit(cache=True, error_model="numpy")
def _end_gap(kind, sg, b, pins, wheels, par, seg, corners):
    """_gap at an end of the step, from precomputed points."""
    if kind == 2:
        return _seg_gap(pins[b, 0], pins[b, 1], seg, sg, par[P_PAD_GROUND])
    if kind == 0 or kind == 1:
        px = wheels[sg, 0]
        py = wheels[sg, 1]
        reach = par[P_WHEEL_RADIUS] + par[P_PAD_WHEEL]
    else:
        px = corners[sg, 0]
        py = corners[sg, 1]
        reach = par[P_PAD_GROUND]
    bp = b - 1 if (kind == 1 or kind == 4) else b
    return _pair_gap(kind, px, py, pins[b, 0], pins[b, 1], pins[b + 1, 0], pins[b + 1, 1],
                     pins[bp, 0], pins[bp, 1], reach)


@njit(cache=True, error_model="numpy")
def first_contact_switch(y0, f0, y1, f1, h, par, arms, ends, seg, corners, nbr, pins0, pins1, wheels0, wheels1):
    """Smallest t in (0, 1] at which some candidate contact starts or ends along the
    step's interpolant (the upper end of the bisection bracket: just after the kink);
    2.0 if none. Pairs whose validity (foot on link, wedge) changes are left alone.
    pins0/1, wheels0/1: scratch for the positions at both ends of the step."""
    nq = (y0.shape[0] - 1) // 2
    _points(y0, nq, par, arms, ends, pins0, wheels0)
    _points(y1, nq, par, arms, ends, pins1, wheels1)
    nw = arms.shape[0]
    nc = corners.shape[0]
    n_links = nbr.shape[0] - 1 - 2 * nw - 2 * nc - 1
    best = 2.0
    for row in range(nbr.shape[0] - 1):
        if row < nw:
            kind, i = 0, row
        elif row < 2 * nw:
            kind, i = 1, row - nw
        elif row < 2 * nw + nc:
            kind, i = 3, row - 2 * nw
        elif row < 2 * nw + 2 * nc:
            kind, i = 4, row - 2 * nw - nc
        else:
            kind, i = 2, row - 2 * nw - 2 * nc  # i = pin here
        for j in range(nbr[row, 0]):
            other = nbr[row, 1 + j]
            if kind == 2:
                b, sg = i, other
            else:
                b, sg = other, i
            v0, g0 = _end_gap(kind, sg, b, pins0, wheels0, par, seg, corners)
            v1, g1 = _end_gap(kind, sg, b, pins1, wheels1, par, seg, corners)
            if not (v0 and v1) or (g0 > 0.0) == (g1 > 0.0):
                continue
            lo = 0.0
            hi = 1.0
            for _ in range(BISECTIONS):
                mid = 0.5 * (lo + hi)
                _, gm = _gap(kind, sg, b, mid, y0, f0, y1, f1, h, nq, n_links, par, arms, ends, seg, corners)
                if (gm > 0.0) == (g0 > 0.0):
                    lo = mid
                else:
                    hi = mid
            best = min(best, hi)
    return best
