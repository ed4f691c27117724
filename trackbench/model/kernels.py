"""Compiled track kernels shared by every solver: link tension (Eq. 8), wheel-track
and ground-track penalty contacts (Eqs. 2-7, Figs. 3-6 and the spec's contact cases),
and the neighbour lists that keep the contact search away from far-apart pairs.

All kernels work on plain arrays (see ``layout``):

    apos, avel (n_links+1, 2)  pin positions / velocities, pins 0 and n_links included
    wc, wv     (n_wheels, 2)   road-wheel centres / velocities
    lk         (n_links, 3)    per link: unit direction t (pin b -> b+1) and length
    fpin       (n_links+1, 2)  out: tension + contact force on each pin
    fwheel     (n_wheels, 2)   out: contact force of the track on each wheel
    seg        (n_seg, 7)      ground segments: x0, y0, tx, ty, length, nx, ny (n outward)
    corners    (n_corners, 2)  convex ground corners
    nbr        int (rows, 1 + width)  neighbour lists, column 0 holds the count
    ref        (n_links+1+n_wheels, 2) pin and wheel positions when the lists were built

The inner normal of link b is n = (t_y, -t_x) (towards the road wheels).
"""

import math

import numpy as np
from numba import njit

from ..status import CORNER_THROUGH_TRACK, WHEEL_THROUGH_TRACK
from .jit import INLINE, KERNEL
from .layout import (
    D_CORNER_FORCE, D_E_PAD_GROUND, D_E_PAD_WHEEL, D_E_TENSION, D_GROUND_FX, D_GROUND_FY,
    D_MAX_TENSION, D_MIN_TENSION, D_POWER, D_STATUS, D_WHEEL, P_K_GROUND, P_K_WHEEL,
    P_LINK_LENGTH, P_LINK_STIFFNESS, P_PAD_GROUND, P_PAD_WHEEL, P_SKIN, P_WHEEL_RADIUS,
)


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


@njit(**KERNEL)
def build_neighbours(apos, wc, par, seg, corners, nbr):
    """Fill the candidate lists: every pair that could touch while no pin or wheel
    moves more than half the skin from where it is now."""
    n_links = apos.shape[0] - 1
    nw = wc.shape[0]
    nc = corners.shape[0]
    skin = par[P_SKIN]
    hg = par[P_PAD_GROUND]
    reach_w = par[P_WHEEL_RADIUS] + par[P_PAD_WHEEL] + skin
    reach_cl = max(hg, par[P_PAD_WHEEL]) + skin
    reach_cp = hg + skin
    r_wp = nw
    r_cl = 2 * nw
    r_cp = r_cl + nc
    r_ps = r_cp + nc
    for i in range(nw):
        px = wc[i, 0]
        py = wc[i, 1]
        n = 0
        for b in range(n_links):
            if _seg_dist2(px, py, apos[b, 0], apos[b, 1], apos[b + 1, 0], apos[b + 1, 1]) < reach_w * reach_w:
                n += 1
                nbr[i, n] = b
        nbr[i, 0] = n
        n = 0
        for b in range(1, n_links):
            dx = px - apos[b, 0]
            dy = py - apos[b, 1]
            if dx * dx + dy * dy < reach_w * reach_w:
                n += 1
                nbr[r_wp + i, n] = b
        nbr[r_wp + i, 0] = n
    for c in range(nc):
        px = corners[c, 0]
        py = corners[c, 1]
        n = 0
        for b in range(n_links):
            if _seg_dist2(px, py, apos[b, 0], apos[b, 1], apos[b + 1, 0], apos[b + 1, 1]) < reach_cl * reach_cl:
                n += 1
                nbr[r_cl + c, n] = b
        nbr[r_cl + c, 0] = n
        n = 0
        for b in range(1, n_links):
            dx = apos[b, 0] - px
            dy = apos[b, 1] - py
            if dx * dx + dy * dy < reach_cp * reach_cp:
                n += 1
                nbr[r_cp + c, n] = b
        nbr[r_cp + c, 0] = n
    for b in range(1, n_links):
        n = 0
        for j in range(seg.shape[0]):
            dx = apos[b, 0] - seg[j, 0]
            dy = apos[b, 1] - seg[j, 1]
            lam = dx * seg[j, 2] + dy * seg[j, 3]
            s = dx * seg[j, 5] + dy * seg[j, 6]
            if lam > -skin and lam < seg[j, 4] + skin and s < hg + skin:
                n += 1
                nbr[r_ps + b, n] = j
        nbr[r_ps + b, 0] = n


@njit(**INLINE)
def refresh_neighbours(apos, wc, par, seg, corners, nbr, ref):
    """Rebuild the lists if any pin or wheel moved more than skin/2 since the last build
    (so the lists always hold every pair that can touch: results equal a full search)."""
    half = 0.5 * par[P_SKIN]
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
    if stale:
        build_neighbours(apos, wc, par, seg, corners, nbr)
        for b in range(n_pins):
            ref[b, 0] = apos[b, 0]
            ref[b, 1] = apos[b, 1]
        for i in range(wc.shape[0]):
            ref[n_pins + i, 0] = wc[i, 0]
            ref[n_pins + i, 1] = wc[i, 1]
        nbr[nbr.shape[0] - 1, 0] += 1


@njit(**INLINE)
def link_tensions(apos, par, lk, fpin, diag, t_off):
    """Eq. (8): T = k_tau (|a_b - a_(b+1)| - L0), linear both ways; sets fpin to the pull
    on every pin, stores t and length in lk and T in diag[t_off + b]."""
    k = par[P_LINK_STIFFNESS]
    l0 = par[P_LINK_LENGTH]
    fpin[0, 0] = 0.0
    fpin[0, 1] = 0.0
    energy = 0.0
    tmin = np.inf
    tmax = -np.inf
    n_links = apos.shape[0] - 1
    for b in range(n_links):  # lengths first: a loop of square roots that vectorises
        dx = apos[b + 1, 0] - apos[b, 0]
        dy = apos[b + 1, 1] - apos[b, 1]
        lk[b, 0] = dx
        lk[b, 1] = dy
        lk[b, 2] = math.sqrt(dx * dx + dy * dy)
    for b in range(n_links):
        length = lk[b, 2]
        inv = 1.0 / length
        tx = lk[b, 0] * inv
        ty = lk[b, 1] * inv
        lk[b, 0] = tx
        lk[b, 1] = ty
        stretch = length - l0
        tension = k * stretch
        diag[t_off + b] = tension
        energy += 0.5 * k * stretch * stretch
        tmin = min(tmin, tension)
        tmax = max(tmax, tension)
        fpin[b, 0] += tension * tx
        fpin[b, 1] += tension * ty
        fpin[b + 1, 0] = -tension * tx  # first force on pin b+1: no need to zero fpin
        fpin[b + 1, 1] = -tension * ty
    diag[D_E_TENSION] = energy
    diag[D_MIN_TENSION] = tmin
    diag[D_MAX_TENSION] = tmax


@njit(**KERNEL)
def _link_load(fpin, avel, b, d0, length, fx, fy):
    """Eq. (7): split a force on link b at distance d0 from pin b to pins b and b+1;
    returns the power of the split force."""
    w1 = d0 / length
    w0 = 1.0 - w1
    fpin[b, 0] += w0 * fx
    fpin[b, 1] += w0 * fy
    fpin[b + 1, 0] += w1 * fx
    fpin[b + 1, 1] += w1 * fy
    return (w0 * avel[b, 0] + w1 * avel[b + 1, 0]) * fx + (w0 * avel[b, 1] + w1 * avel[b + 1, 1]) * fy


@njit(**INLINE)
def wheel_contacts(apos, avel, wc, wv, lk, par, nbr, fpin, fwheel, diag):
    """Road wheel against link (Fig. 3, Eq. 4) and against pin in the wedge (Fig. 4)."""
    nw = wc.shape[0]
    k = par[P_K_WHEEL]
    rho = par[P_WHEEL_RADIUS] + par[P_PAD_WHEEL]
    energy = 0.0
    power = 0.0
    for i in range(nw):
        fwx = 0.0
        fwy = 0.0
        for j in range(nbr[i, 0]):
            b = nbr[i, 1 + j]
            tx = lk[b, 0]
            ty = lk[b, 1]
            length = lk[b, 2]
            dx = wc[i, 0] - apos[b, 0]
            dy = wc[i, 1] - apos[b, 1]
            d0 = dx * tx + dy * ty
            if d0 < 0.0 or d0 > length:
                continue
            s = dx * ty - dy * tx  # Eq. (2): distance along the inner normal
            if s >= rho or s <= -rho:
                continue
            if s < 0.0:
                diag[D_STATUS] = WHEEL_THROUGH_TRACK
                continue
            p = k * (rho - s)  # Eq. (4)
            fx = p * ty
            fy = -p * tx
            fwx += fx
            fwy += fy
            energy += 0.5 * k * (rho - s) ** 2
            power += fx * wv[i, 0] + fy * wv[i, 1]
            power += _link_load(fpin, avel, b, d0, length, -fx, -fy)
        row = nw + i
        for j in range(nbr[row, 0]):
            b = nbr[row, 1 + j]
            dx = wc[i, 0] - apos[b, 0]
            dy = wc[i, 1] - apos[b, 1]
            if dx * lk[b, 0] + dy * lk[b, 1] >= 0.0:
                continue
            if dx * lk[b - 1, 0] + dy * lk[b - 1, 1] <= 0.0:
                continue
            # the bend must be convex towards the wheel (counter-clockwise turn)
            if lk[b - 1, 0] * lk[b, 1] - lk[b - 1, 1] * lk[b, 0] <= 0.0:
                continue
            dist = math.sqrt(dx * dx + dy * dy)
            if dist >= rho:
                continue
            p = k * (rho - dist)
            fx = p * dx / dist
            fy = p * dy / dist
            fwx += fx
            fwy += fy
            fpin[b, 0] -= fx
            fpin[b, 1] -= fy
            energy += 0.5 * k * (rho - dist) ** 2
            power += fx * (wv[i, 0] - avel[b, 0]) + fy * (wv[i, 1] - avel[b, 1])
        fwheel[i, 0] = fwx
        fwheel[i, 1] = fwy
        diag[D_WHEEL + 2 * i] = fwx
        diag[D_WHEEL + 2 * i + 1] = fwy
    diag[D_E_PAD_WHEEL] = energy
    diag[D_POWER] += power


@njit(**INLINE)
def ground_contacts(apos, avel, lk, par, seg, corners, nbr, fpin, diag):
    """Pin on ground segment (Fig. 5 left, Eq. 6), ground corner on link (Fig. 5 right)
    and corner on pin in the wedge (Fig. 6)."""
    n_links = apos.shape[0] - 1
    nc = corners.shape[0]
    k = par[P_K_GROUND]
    hg = par[P_PAD_GROUND]
    hw = par[P_PAD_WHEEL]
    rows = nbr.shape[0] - 1  # last row holds counters
    r_ps = rows - (n_links + 1)
    r_cp = r_ps - nc
    r_cl = r_cp - nc
    energy = 0.0
    power = 0.0
    gx = 0.0
    gy = 0.0
    corner_force = 0.0
    for b in range(1, n_links):
        row = r_ps + b
        # Is the pin inside the ground (below the surface at its x)? Only then may a
        # segment it lies behind (s < 0) push it: otherwise the back of an obstacle's
        # far face (a block's) would push pins on the ground before it from metres away.
        inside = False
        n_below = 0
        best = -np.inf          # largest s over all candidates
        best_outside = -np.inf  # largest s >= 0
        for j in range(nbr[row, 0]):
            sj = nbr[row, 1 + j]
            dx = apos[b, 0] - seg[sj, 0]
            dy = apos[b, 1] - seg[sj, 1]
            s = dx * seg[sj, 5] + dy * seg[sj, 6]
            if s < 0.0 and seg[sj, 2] > 0.0 and 0.0 <= dx <= seg[sj, 4] * seg[sj, 2]:
                inside = True  # below a non-vertical segment, within its x-range
            lam = dx * seg[sj, 2] + dy * seg[sj, 3]
            if lam < 0.0 or lam > seg[sj, 4] or s >= hg:
                continue
            if s < 0.0:
                n_below += 1
            else:
                best_outside = max(best_outside, s)
            best = max(best, s)
        if not inside:
            n_below = 0
            best = best_outside
        if best == -np.inf:
            continue
        for j in range(nbr[row, 0]):
            sj = nbr[row, 1 + j]
            dx = apos[b, 0] - seg[sj, 0]
            dy = apos[b, 1] - seg[sj, 1]
            lam = dx * seg[sj, 2] + dy * seg[sj, 3]
            if lam < 0.0 or lam > seg[sj, 4]:
                continue
            s = dx * seg[sj, 5] + dy * seg[sj, 6]
            if s >= hg or (s < 0.0 and not inside):
                continue
            # a pin beyond several segments presses on the nearest one only
            if n_below >= 2 and s < best:
                continue
            p = k * (hg - s)  # Eq. (6)
            fx = p * seg[sj, 5]
            fy = p * seg[sj, 6]
            fpin[b, 0] += fx
            fpin[b, 1] += fy
            gx += fx
            gy += fy
            energy += 0.5 * k * (hg - s) ** 2
            power += fx * avel[b, 0] + fy * avel[b, 1]
    for c in range(nc):
        cx = corners[c, 0]
        cy = corners[c, 1]
        row = r_cl + c
        for j in range(nbr[row, 0]):
            b = nbr[row, 1 + j]
            tx = lk[b, 0]
            ty = lk[b, 1]
            length = lk[b, 2]
            dx = cx - apos[b, 0]
            dy = cy - apos[b, 1]
            d0 = dx * tx + dy * ty
            if d0 < 0.0 or d0 > length:
                continue
            s = -(dx * ty - dy * tx)  # along the outer normal -n_inner
            if s >= hg or s <= -hw:
                continue
            if s < 0.0:
                diag[D_STATUS] = CORNER_THROUGH_TRACK
                continue
            p = k * (hg - s)
            fx = p * ty
            fy = -p * tx
            gx += fx
            gy += fy
            corner_force += p
            energy += 0.5 * k * (hg - s) ** 2
            power += _link_load(fpin, avel, b, d0, length, fx, fy)
        row = r_cp + c
        for j in range(nbr[row, 0]):
            b = nbr[row, 1 + j]
            dx = cx - apos[b, 0]
            dy = cy - apos[b, 1]
            if dx * lk[b, 0] + dy * lk[b, 1] >= 0.0:
                continue
            if dx * lk[b - 1, 0] + dy * lk[b - 1, 1] <= 0.0:
                continue
            # the bend must be convex towards the ground (clockwise turn)
            if lk[b - 1, 0] * lk[b, 1] - lk[b - 1, 1] * lk[b, 0] >= 0.0:
                continue
            dist = math.sqrt(dx * dx + dy * dy)
            if dist >= hg:
                continue
            p = k * (hg - dist)
            fx = -p * dx / dist
            fy = -p * dy / dist
            fpin[b, 0] += fx
            fpin[b, 1] += fy
            gx += fx
            gy += fy
            corner_force += p
            energy += 0.5 * k * (hg - dist) ** 2
            power += fx * avel[b, 0] + fy * avel[b, 1]
    diag[D_E_PAD_GROUND] = energy
    diag[D_GROUND_FX] = gx
    diag[D_GROUND_FY] = gy
    diag[D_CORNER_FORCE] = corner_force
    diag[D_POWER] += power


@njit(**INLINE)
def track_loads(apos, avel, wc, wv, par, seg, corners, nbr, ref, lk, fpin, fwheel, diag, t_off):
    """All forces of the track model for given pin and wheel positions/velocities
    (fpin is overwritten, tension first):
    tension and contact forces on the pins (fpin, pins 0 and n_links included),
    contact forces on the wheels (fwheel), energies, power and status in diag.
    Gravity is left to the caller."""
    diag[D_STATUS] = 0.0
    diag[D_POWER] = 0.0
    refresh_neighbours(apos, wc, par, seg, corners, nbr, ref)
    link_tensions(apos, par, lk, fpin, diag, t_off)
    wheel_contacts(apos, avel, wc, wv, lk, par, nbr, fpin, fwheel, diag)
    ground_contacts(apos, avel, lk, par, seg, corners, nbr, fpin, diag)


def allocate_neighbours(n_wheels, n_corners, n_links, n_seg):
    """Empty neighbour lists (marked stale) for a model of this size."""
    rows = 2 * n_wheels + 2 * n_corners + (n_links + 1) + 1
    width = 1 + max(n_links + 1, n_seg)
    nbr = np.zeros((rows, width), dtype=np.int64)
    ref = np.full((n_links + 1 + n_wheels, 2), np.nan)
    return nbr, ref
