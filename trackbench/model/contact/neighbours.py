"""Candidate lists that keep the contact search away from far-apart pairs: for each wheel
centre and ground corner, the links and pins within reach, rebuilt when something has
moved more than the skin."""

from numba import njit

from ..core.indices import (
    ARMS_REACH,
    C_CORNER_END,
    C_CORNER_FIRST,
    C_OVERFLOW,
    C_REBUILDS,
    G_REACH,
    GROUND_WINDOW,
    K_CORNER_LINK,
    K_CORNER_PIN,
    K_GUIDE_LINK,
    K_GUIDE_PIN,
    K_PIN_GROUND,
    K_WHEEL_LINK,
    K_WHEEL_PIN,
    NB_COUNT,
    P_PAD_GROUND,
    P_PAD_WHEEL,
    P_SKIN,
    PN_LAST,
    SEG_LENGTH,
    SEG_X0,
    SEGMENT_CANDIDATES,
)
from ..core.jit import BORROW, INLINE
from .gaps import segment_coords


@njit(**INLINE)
def _seg_dist2(px, py, ax, ay, bx, by):
    """Squared distance from point P to segment AB."""
    ex = bx - ax
    ey = by - ay
    l2 = ex * ex + ey * ey
    u = 0.0
    if l2 > 0.0:
        u = ((px - ax) * ex + (py - ay) * ey) / l2
        u = min(1.0, max(0.0, u))
    dx = px - ax - u * ex
    dy = py - ay - u * ey
    return dx * dx + dy * dy


@njit(**INLINE)
def _near_links(px, py, apos, reach, nbr, row):
    """Candidate row: every link whose centre line passes within reach of P."""
    n = 0
    for b in range(apos.shape[0] - 1):
        if _seg_dist2(px, py, apos[b, 0], apos[b, 1], apos[b + 1, 0], apos[b + 1, 1]) < reach * reach:
            n += 1
            nbr[row, n] = b
    nbr[row, NB_COUNT] = n


@njit(**INLINE)
def _near_pins(px, py, apos, last, reach, nbr, row):
    """Candidate row: every free pin (rows 1..last) within reach of P."""
    n = 0
    for b in range(1, last + 1):
        dx = apos[b, 0] - px
        dy = apos[b, 1] - py
        if dx * dx + dy * dy < reach * reach:
            n += 1
            nbr[row, n] = b
    nbr[row, NB_COUNT] = n


@njit(**INLINE)
def _first_beyond(table, col, x, inclusive):
    """The first row of table whose column col is at x or beyond (inclusive) or beyond x
    alone, by bisection: the ground's corners and its segments' starts ascend in x as the
    ground's vertices do."""
    lo, hi = 0, table.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if table[mid, col] < x or (not inclusive and table[mid, col] == x):
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(**INLINE)
def _track_x_range(apos):
    """The smallest and largest x of the pins (the links lie between them)."""
    lo, hi = apos[0, 0], apos[0, 0]
    for b in range(apos.shape[0]):
        lo = min(lo, apos[b, 0])
        hi = max(hi, apos[b, 0])
    return lo, hi


@njit(**INLINE)
def _corner_window(span, m, reach):
    """Clear the corner rows of the last window, then the new window: the corners within
    reach in x of the track's span, the only ones with candidates."""
    nbr, rows, counters = m.nbr, m.nbr_rows, m.counters
    for c in range(counters[C_CORNER_FIRST], counters[C_CORNER_END]):
        nbr[rows[K_CORNER_LINK] + c, NB_COUNT] = 0
        nbr[rows[K_CORNER_PIN] + c, NB_COUNT] = 0
    counters[C_CORNER_FIRST] = _first_beyond(m.corners, 0, span[0] - reach, True)
    counters[C_CORNER_END] = _first_beyond(m.corners, 0, span[1] + reach, False)
    return counters[C_CORNER_FIRST], counters[C_CORNER_END]


@njit(**INLINE)
def _segment_window(span, seg, reach):
    """(first, end) of the ground segments a pin may have as candidates: every one on a ground
    of at most SEGMENT_CANDIDATES segments (the paper's and every obstacle's: a full search),
    else those within GROUND_WINDOW + reach of the track's span in x (the segment before the
    first starting in it, which may reach into it, included): a rough ground's gentle slopes
    keep the others out of a pin's reach."""
    n = seg.shape[0]
    if n <= SEGMENT_CANDIDATES:
        return 0, n
    margin = GROUND_WINDOW + reach
    first = max(_first_beyond(seg, SEG_X0, span[0] - margin, True) - 1, 0)
    return first, _first_beyond(seg, SEG_X0, span[1] + margin, False)


@njit(**INLINE)
def _pin_ground_row(apos, b, seg, window, skin, hg, m):
    """Candidate row of free pin b: the segments of the window it could touch; flags an
    overflow of the row (counters[C_OVERFLOW]) instead of writing beyond it."""
    nbr = m.nbr
    row = m.nbr_rows[K_PIN_GROUND] + b
    room = nbr.shape[1] - 1
    n = 0
    for j in range(window[0], window[1]):
        lam, s, _ = segment_coords(apos[b, 0], apos[b, 1], seg, j)
        if lam > -skin and lam < seg[j, SEG_LENGTH] + skin and s < hg + skin:
            if n == room:
                m.counters[C_OVERFLOW] = 1
                break
            n += 1
            nbr[row, n] = j
    nbr[row, NB_COUNT] = n


@njit(**BORROW)
def build_neighbours(apos, wc, gc, m):
    """Fill the candidate lists: every pair that could touch while no pin, wheel, idler or
    roller (gc) moves more than half the skin from where it is now."""
    par, seg, corners, nbr, rows = m.par, m.seg, m.corners, m.nbr, m.nbr_rows
    last = m.pins[PN_LAST]
    skin = par[P_SKIN]
    hg = par[P_PAD_GROUND]
    reach_cl = max(hg, par[P_PAD_WHEEL]) + skin
    for i in range(wc.shape[0]):
        reach_w = m.arms[i, ARMS_REACH] + skin   # wheel radius + pad h_w, the station's own
        _near_links(wc[i, 0], wc[i, 1], apos, reach_w, nbr, rows[K_WHEEL_LINK] + i)
        _near_pins(wc[i, 0], wc[i, 1], apos, last, reach_w, nbr, rows[K_WHEEL_PIN] + i)
    for j in range(gc.shape[0]):
        reach_g = m.guides[j, G_REACH] + skin
        _near_links(gc[j, 0], gc[j, 1], apos, reach_g, nbr, rows[K_GUIDE_LINK] + j)
        _near_pins(gc[j, 0], gc[j, 1], apos, last, reach_g, nbr, rows[K_GUIDE_PIN] + j)
    span = _track_x_range(apos)
    for c in range(*_corner_window(span, m, max(reach_cl, hg + skin))):
        _near_links(corners[c, 0], corners[c, 1], apos, reach_cl, nbr, rows[K_CORNER_LINK] + c)
        _near_pins(corners[c, 0], corners[c, 1], apos, last, hg + skin, nbr, rows[K_CORNER_PIN] + c)
    window = _segment_window(span, seg, hg + skin)
    for b in range(1, last + 1):
        _pin_ground_row(apos, b, seg, window, skin, hg, m)


@njit(**INLINE)
def refresh_neighbours(apos, wc, gc, m):
    """Rebuild the lists if any pin, wheel, idler or roller moved more than skin/2 since the
    last build (so the lists always hold every pair that can touch: results equal a full
    search). gc: the idler and roller centres (no rows in the paper's layout)."""
    ref = m.ref
    half = 0.5 * m.par[P_SKIN]
    lim = half * half
    n_pins = apos.shape[0]
    stale = False
    for b in range(n_pins):
        dx = apos[b, 0] - ref[b, 0]
        dy = apos[b, 1] - ref[b, 1]
        stale |= not (dx * dx + dy * dy <= lim)  # no early exit: the loop vectorises
    for i in range(wc.shape[0]):
        dx = wc[i, 0] - ref[n_pins + i, 0]
        dy = wc[i, 1] - ref[n_pins + i, 1]
        stale |= not (dx * dx + dy * dy <= lim)
    n_wc = n_pins + wc.shape[0]
    for j in range(gc.shape[0]):
        dx = gc[j, 0] - ref[n_wc + j, 0]
        dy = gc[j, 1] - ref[n_wc + j, 1]
        stale |= not (dx * dx + dy * dy <= lim)
    if stale:
        build_neighbours(apos, wc, gc, m)
        for b in range(n_pins):
            ref[b, 0] = apos[b, 0]
            ref[b, 1] = apos[b, 1]
        for i in range(wc.shape[0]):
            ref[n_pins + i, 0] = wc[i, 0]
            ref[n_pins + i, 1] = wc[i, 1]
        for j in range(gc.shape[0]):
            ref[n_wc + j, 0] = gc[j, 0]
            ref[n_wc + j, 1] = gc[j, 1]
        m.counters[C_REBUILDS] += 1
