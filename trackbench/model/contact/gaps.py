"""Contact geometry, written once: where a point lies relative to a link, a pin's wedge or
a ground segment, and which ground segment a pin presses on. The force kernels
(track_contacts.py, ground/ground_contact.py) and the event location
(solvers/common/events.py) both decide "in contact or not" through these functions, so a
located onset is an onset of the force law.

Conventions (docs/model.md): link b runs from pin b to pin b+1 with unit direction t and
length l (Work.lk); its inner normal (towards the road wheels) is (t_y, -t_x).
"""

import math

import numpy as np
from numba import njit

from ..core.indices import (
    LK_LENGTH,
    LK_TX,
    LK_TY,
    NB_COUNT,
    SEG_LENGTH,
    SEG_NX,
    SEG_NY,
    SEG_TX,
    SEG_TY,
    SEG_X0,
    SEG_Y0,
)
from ..core.jit import BORROW, INLINE, SCALAR


@njit(**INLINE)
def link_frames(apos, lk):
    """Unit direction and length of every link into lk (lengths first: a loop of square
    roots that vectorises)."""
    n_links = apos.shape[0] - 1
    for b in range(n_links):
        dx = apos[b + 1, 0] - apos[b, 0]
        dy = apos[b + 1, 1] - apos[b, 1]
        lk[b, LK_TX] = dx
        lk[b, LK_TY] = dy
        lk[b, LK_LENGTH] = math.sqrt(dx * dx + dy * dy)
    for b in range(n_links):
        inv = 1.0 / lk[b, LK_LENGTH]
        lk[b, LK_TX] = lk[b, LK_TX] * inv
        lk[b, LK_TY] = lk[b, LK_TY] * inv


@njit(**SCALAR)
def link_frame(ax, ay, bx, by):
    """(tx, ty, length) of the link from pin A to pin B, rounded as link_frames does."""
    dx = bx - ax
    dy = by - ay
    length = math.sqrt(dx * dx + dy * dy)
    inv = 1.0 / length
    return dx * inv, dy * inv, length


@njit(**SCALAR)
def point_on_link(px, py, ax, ay, tx, ty):
    """(d0, s) of point P against the link from pin A along t: d0 along the link (the foot
    lies on the link when 0 <= d0 <= length), s the distance along the inner normal, Eq. (2)."""
    dx = px - ax
    dy = py - ay
    return dx * tx + dy * ty, dx * ty - dy * tx


@njit(**SCALAR)
def wedge(px, py, ax, ay, t0x, t0y, t1x, t1y, towards_inner):
    """P lies in the wedge beyond the free pin A between a link along t0 (ending at A) and
    one along t1 (starting at A) - both fail the foot test - on the convex side of the
    bend: convex towards the inner side (a road wheel) when towards_inner, towards the
    ground otherwise (Figs. 4 and 6)."""
    dx = px - ax
    dy = py - ay
    if dx * t1x + dy * t1y >= 0.0:
        return False
    if dx * t0x + dy * t0y <= 0.0:
        return False
    turn = t0x * t1y - t0y * t1x  # > 0: counter-clockwise bend
    return turn > 0.0 if towards_inner else turn < 0.0


@njit(**SCALAR)
def pin_cap_weight(px, py, ax, ay, t0x, t0y, t1x, t1y, towards_inner, continuous):
    """How many times the round cap of the free pin A (between a link along t0 ending at A
    and one along t1 starting at A) acts on P.
    Paper geometry: once in the convex wedge (wedge), else never.
    Continuous geometry: the pad surface is the union of the two links' pads, each a
    link with round caps at its pins; by inclusion-exclusion the cap counts once for
    each link whose foot test P fails towards A (P on that link's contact side), less
    once where P is on the contact side of both links (the caps overlap). The result is
    1 in the convex wedge (the paper's pin contact), 0 where P's foot lies on one link
    and not the other (the paper's link contact), -1 where it lies on both (a concave
    bend: the two links' terms overlap there). Every term is continuous in P and the
    pins, so the contact energy is too: no jump from link to pin."""
    if not continuous:
        return 1 if wedge(px, py, ax, ay, t0x, t0y, t1x, t1y, towards_inner) else 0
    dx = px - ax
    dy = py - ay
    side0 = dx * t0y - dy * t0x    # along the inner normal of each link
    side1 = dx * t1y - dy * t1x
    if not towards_inner:
        side0 = -side0
        side1 = -side1
    weight = 0
    if side0 > 0.0 and dx * t0x + dy * t0y > 0.0:
        weight += 1
    if side1 > 0.0 and dx * t1x + dy * t1y < 0.0:
        weight += 1
    if side0 > 0.0 and side1 > 0.0:
        weight -= 1
    return weight


@njit(**SCALAR)
def point_on_segment(px, py, x0, y0, tx, ty, nx, ny):
    """(lam, s) of point P against a ground segment from (x0, y0) along t with outward
    normal n: lam along it (the foot lies on it when 0 <= lam <= length), s along n."""
    dx = px - x0
    dy = py - y0
    return dx * tx + dy * ty, dx * nx + dy * ny


@njit(**INLINE)
def segment_coords(px, py, seg, j):
    """point_on_segment for ground segment j, and dx (P's x from the segment start) for
    the inside-the-ground test."""
    lam, s = point_on_segment(px, py, seg[j, SEG_X0], seg[j, SEG_Y0], seg[j, SEG_TX], seg[j, SEG_TY],
                              seg[j, SEG_NX], seg[j, SEG_NY])
    return lam, s, px - seg[j, SEG_X0]


@njit(**INLINE)
def _under(s, dx, seg, j):
    """Is a point at (s, dx) of segment_coords under the non-vertical segment j, within its
    x-range (so inside the ground)?"""
    return s < 0.0 and seg[j, SEG_TX] > 0.0 and 0.0 <= dx <= seg[j, SEG_LENGTH] * seg[j, SEG_TX]


@njit(**INLINE)
def pin_ground_selection(px, py, seg, nbr, row, hg):
    """Which of a pin's candidate segments may push it (docs/model.md): (inside, n_below, best).
    inside: the pin is below a non-vertical segment within its x-range, i.e. inside the
    ground; only then may a segment it lies behind (s < 0) push it, otherwise the back of
    an obstacle's far face would push pins on the ground before it from metres away.
    n_below: segments it is behind; best: the largest s among the acting candidates (a pin
    beyond several segments presses on the nearest one only); -inf when none acts."""
    inside = False
    n_below = 0
    best = -np.inf
    best_outside = -np.inf
    for j in range(nbr[row, NB_COUNT]):
        sj = nbr[row, 1 + j]
        lam, s, dx = segment_coords(px, py, seg, sj)
        inside |= _under(s, dx, seg, sj)
        if lam < 0.0 or lam > seg[sj, SEG_LENGTH] or s >= hg:
            continue
        if s < 0.0:
            n_below += 1
        else:
            best_outside = max(best_outside, s)
        best = max(best, s)
    if not inside:
        return False, 0, best_outside
    return True, n_below, best


@njit(**SCALAR)
def pin_segment_valid(lam, s, length, inside, n_below, best):
    """May a segment of this length push the pin at (lam, s) (foot on it, on the right
    side, the nearest of several it is behind; pin_ground_selection gives inside,
    n_below, best)? It does when also s < h_g; h_g - s is then the pad compression."""
    if lam < 0.0 or lam > length:
        return False
    if s < 0.0 and not inside:
        return False
    return not (n_below >= 2 and s < best)


@njit(**BORROW)
def ground_distance(px, py, seg, nbr, row):
    """Continuous geometry: (s, nx, ny, j) of P against the ground - s the signed distance
    to the nearest point of the ground's surface among the candidate segments in row
    (negative inside the ground), (nx, ny) the unit direction in which s grows, j the
    segment of that nearest point. Beyond a segment's end the nearest point is the end
    itself (a round cap at a convex corner), so s is continuous in P everywhere: the
    one distance replaces the paper's per-segment cases and its nearest-segment rule."""
    best = np.inf
    ux = 0.0
    uy = 1.0
    near = -1
    inside = False
    for j in range(nbr[row, NB_COUNT]):
        sj = nbr[row, 1 + j]
        lam, s, dx = segment_coords(px, py, seg, sj)
        length = seg[sj, SEG_LENGTH]
        inside |= _under(s, dx, seg, sj)
        lam = min(max(lam, 0.0), length)
        qx = px - seg[sj, SEG_X0] - lam * seg[sj, SEG_TX]    # P minus its nearest point on sj
        qy = py - seg[sj, SEG_Y0] - lam * seg[sj, SEG_TY]
        d = math.sqrt(qx * qx + qy * qy)
        if d < best and d > 0.0:
            best = d
            ux = qx / d
            uy = qy / d
            near = sj
    if inside:
        return -best, -ux, -uy, near
    return best, ux, uy, near
