"""Compiled track kernels shared by every solver: link tension (Eq. 8), wheel-track
and ground-track penalty contacts (Eqs. 2-7, Figs. 3-6 and the spec's contact cases),
and the candidate lists that keep the contact search away from far-apart pairs.

Every kernel takes the bundles of model/bundles.py: ``m`` (ModelArrays: parameters,
ground, candidate lists), ``w`` (Work: pin and wheel kinematics in, forces out) and
``diag`` (layout.D_*). The geometry of each contact (which side, which wedge, which
segment) is model/gaps.py.
"""

import math

import numpy as np
from numba import njit

from ..status import CORNER_THROUGH_TRACK, WHEEL_THROUGH_TRACK
from .gaps import in_pin_wedge, link_coords, link_frames, pin_ground_selection, pin_segment_acts, segment_coords
from .contact_force import normal_force
from .contact_laws import DAMPING_HUNT_CROSSLEY, DAMPING_NONE
from .jit import INLINE, KERNEL
from .layout import (
    C_EVALUATIONS, C_REBUILDS, D_CORNER_FORCE, D_DISSIPATION, P_C_GROUND, P_C_WHEEL, P_CONTACT_DAMPING, P_CONTACT_EXPONENT,
    P_CONTACT_LAW, P_DAMPING_RAMP, P_LINK_DAMPING, P_MIN_APPROACH, P_RESTITUTION_FACTOR, D_E_PAD_GROUND, D_E_PAD_WHEEL, D_E_TENSION, D_GROUND_FX, D_GROUND_FY,
    D_MAX_TENSION, D_MIN_TENSION, D_OBSTACLE_FORCE, D_POWER, D_STATUS, D_WHEEL, K_CORNER_LINK, K_CORNER_PIN, K_PIN_GROUND,
    K_WHEEL_LINK, K_WHEEL_PIN, NB_COUNT, P_K_GROUND, P_K_WHEEL, P_LINK_LENGTH, P_LINK_STIFFNESS, P_PAD_GROUND,
    P_PAD_WHEEL, P_SKIN, P_WHEEL_RADIUS, SEG_LENGTH, SEG_NX, SEG_NY, diag_tension,
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
def _near_pins(px, py, apos, reach, nbr, row):
    """Candidate row: every free pin within reach of P."""
    n = 0
    for b in range(1, apos.shape[0] - 1):
        dx = apos[b, 0] - px
        dy = apos[b, 1] - py
        if dx * dx + dy * dy < reach * reach:
            n += 1
            nbr[row, n] = b
    nbr[row, NB_COUNT] = n


@njit(**KERNEL)
def build_neighbours(apos, wc, m):
    """Fill the candidate lists: every pair that could touch while no pin or wheel
    moves more than half the skin from where it is now."""
    par, seg, corners, nbr, rows = m.par, m.seg, m.corners, m.nbr, m.nbr_rows
    skin = par[P_SKIN]
    hg = par[P_PAD_GROUND]
    reach_w = par[P_WHEEL_RADIUS] + par[P_PAD_WHEEL] + skin
    reach_cl = max(hg, par[P_PAD_WHEEL]) + skin
    for i in range(wc.shape[0]):
        _near_links(wc[i, 0], wc[i, 1], apos, reach_w, nbr, rows[K_WHEEL_LINK] + i)
        _near_pins(wc[i, 0], wc[i, 1], apos, reach_w, nbr, rows[K_WHEEL_PIN] + i)
    for c in range(corners.shape[0]):
        _near_links(corners[c, 0], corners[c, 1], apos, reach_cl, nbr, rows[K_CORNER_LINK] + c)
        _near_pins(corners[c, 0], corners[c, 1], apos, hg + skin, nbr, rows[K_CORNER_PIN] + c)
    for b in range(1, apos.shape[0] - 1):
        row = rows[K_PIN_GROUND] + b
        n = 0
        for j in range(seg.shape[0]):
            lam, s, _ = segment_coords(apos[b, 0], apos[b, 1], seg, j)
            if lam > -skin and lam < seg[j, SEG_LENGTH] + skin and s < hg + skin:
                n += 1
                nbr[row, n] = j
        nbr[row, NB_COUNT] = n


@njit(**INLINE)
def _moved(points, ref, first, lim):
    """Has any point moved more than sqrt(lim) from ref[first + k]?"""
    stale = False
    for k in range(points.shape[0]):
        dx = points[k, 0] - ref[first + k, 0]
        dy = points[k, 1] - ref[first + k, 1]
        stale |= not (dx * dx + dy * dy <= lim)  # no early exit: the loop vectorises
    return stale


@njit(**INLINE)
def _remember(points, ref, first):
    for k in range(points.shape[0]):
        ref[first + k, 0] = points[k, 0]
        ref[first + k, 1] = points[k, 1]


@njit(**INLINE)
def refresh_neighbours(w, m):
    """Rebuild the lists if any pin or wheel moved more than skin/2 since the last build
    (so the lists always hold every pair that can touch: results equal a full search)."""
    half = 0.5 * m.par[P_SKIN]
    lim = half * half
    n_pins = w.apos.shape[0]
    stale = _moved(w.apos, m.ref, 0, lim)
    stale |= _moved(w.wc, m.ref, n_pins, lim)
    if stale:
        build_neighbours(w.apos, w.wc, m)
        _remember(w.apos, m.ref, 0)
        _remember(w.wc, m.ref, n_pins)
        m.counters[C_REBUILDS] += 1


@njit(**INLINE)
def link_tensions(w, par, diag):
    """Eq. (8): T = k_tau (|a_b - a_(b+1)| - L0), linear both ways, plus the link's axial
    dashpot c l' where track.link_damping is set; sets fpin to the pull on every pin,
    stores t and length in lk and T in diag."""
    apos, lk, fpin = w.apos, w.lk, w.fpin
    k = par[P_LINK_STIFFNESS]
    l0 = par[P_LINK_LENGTH]
    c = par[P_LINK_DAMPING]
    t_off = diag_tension(w.wc.shape[0])
    fpin[0, 0] = 0.0
    fpin[0, 1] = 0.0
    energy = 0.0
    power = 0.0
    tmin = np.inf
    tmax = -np.inf
    link_frames(apos, lk)
    for b in range(apos.shape[0] - 1):
        tx = lk[b, 0]
        ty = lk[b, 1]
        stretch = lk[b, 2] - l0
        tension = k * stretch
        if c != 0.0:
            rate = (w.avel[b + 1, 0] - w.avel[b, 0]) * tx + (w.avel[b + 1, 1] - w.avel[b, 1]) * ty
            tension += c * rate
            power += c * rate * rate
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
    diag[D_DISSIPATION] += power
    diag[D_POWER] -= power


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
def _link_rate(vx, vy, w, b, d0):
    """ds/dt of a point moving at v against link b (s along the inner normal, d0 its foot):
    (v - a_b') . n_b + d0 omega_b, omega_b the link's rotation rate."""
    lk, avel = w.lk, w.avel
    dvx = avel[b + 1, 0] - avel[b, 0]
    dvy = avel[b + 1, 1] - avel[b, 1]
    omega = (lk[b, 0] * dvy - lk[b, 1] * dvx) / lk[b, 2]
    return (vx - avel[b, 0]) * lk[b, 1] - (vy - avel[b, 1]) * lk[b, 0] + d0 * omega


@njit(**INLINE)
def _force(m, w, kc, row, j, delta, delta_dot):
    """(force, pad energy, dissipated power) of candidate j of row at compression delta
    by the scenario's contact law; kc: P_C_WHEEL or P_C_GROUND. The approach speed v0 is
    the one remembered at the pair's onset (remember_onsets), or, for an onset inside the
    current step, the current rate (it becomes the memory once the step is accepted)."""
    par = m.par
    partner = m.nbr[row, 1 + j]
    v0 = m.v0[row, partner]
    if par[P_CONTACT_DAMPING] >= DAMPING_HUNT_CROSSLEY:
        w.pair_seen[row, partner] = m.counters[C_EVALUATIONS]
        w.pair_rate[row, partner] = delta_dot
        if v0 <= 0.0:
            v0 = max(delta_dot, par[P_MIN_APPROACH])
    k = par[P_K_WHEEL] if kc == P_C_WHEEL else par[P_K_GROUND]
    return normal_force(int(par[P_CONTACT_LAW]), int(par[P_CONTACT_DAMPING]), k, par[P_CONTACT_EXPONENT], par[kc],
                        par[P_RESTITUTION_FACTOR], par[P_DAMPING_RAMP], delta, delta_dot, v0)


@njit(**INLINE)
def _wheel_on_links(i, w, m, rho, diag, acc):
    """Road wheel i against the links (Fig. 3, Eq. 4). acc = (fx, fy, energy, power,
    dissipation) is carried through, not summed apart and added: every sum keeps the order
    of one loop."""
    apos, lk, wc = w.apos, w.lk, w.wc
    damped = m.par[P_CONTACT_DAMPING] != DAMPING_NONE
    fwx, fwy, energy, power, dissipation = acc
    row = m.nbr_rows[K_WHEEL_LINK] + i
    for j in range(m.nbr[row, NB_COUNT]):
        b = m.nbr[row, 1 + j]
        d0, s = link_coords(wc[i, 0], wc[i, 1], apos, lk, b)
        if d0 < 0.0 or d0 > lk[b, 2]:
            continue
        if s >= rho or s <= -rho:
            continue
        if s < 0.0:
            diag[D_STATUS] = WHEEL_THROUGH_TRACK
            continue
        rate = -_link_rate(w.wv[i, 0], w.wv[i, 1], w, b, d0) if damped else 0.0
        p, e, pd = _force(m, w, P_C_WHEEL, row, j, rho - s, rate)  # Eq. (4)
        fx = p * lk[b, 1]
        fy = -p * lk[b, 0]
        fwx += fx
        fwy += fy
        energy += e
        dissipation += pd
        power += fx * w.wv[i, 0] + fy * w.wv[i, 1]
        power += _link_load(w.fpin, w.avel, b, d0, lk[b, 2], -fx, -fy)
    return fwx, fwy, energy, power, dissipation


@njit(**INLINE)
def _wheel_on_pins(i, w, m, rho, acc):
    """Road wheel i against free pins in the wedge (Fig. 4); acc as in _wheel_on_links."""
    apos, avel, wc = w.apos, w.avel, w.wc
    damped = m.par[P_CONTACT_DAMPING] != DAMPING_NONE
    fwx, fwy, energy, power, dissipation = acc
    row = m.nbr_rows[K_WHEEL_PIN] + i
    for j in range(m.nbr[row, NB_COUNT]):
        b = m.nbr[row, 1 + j]
        if not in_pin_wedge(wc[i, 0], wc[i, 1], apos, w.lk, b, True):
            continue
        dx = wc[i, 0] - apos[b, 0]
        dy = wc[i, 1] - apos[b, 1]
        dist = math.sqrt(dx * dx + dy * dy)
        if dist >= rho:
            continue
        rate = -(dx * (w.wv[i, 0] - avel[b, 0]) + dy * (w.wv[i, 1] - avel[b, 1])) / dist if damped else 0.0
        p, e, pd = _force(m, w, P_C_WHEEL, row, j, rho - dist, rate)
        fx = p * dx / dist
        fy = p * dy / dist
        fwx += fx
        fwy += fy
        w.fpin[b, 0] -= fx
        w.fpin[b, 1] -= fy
        energy += e
        dissipation += pd
        power += fx * (w.wv[i, 0] - avel[b, 0]) + fy * (w.wv[i, 1] - avel[b, 1])
    return fwx, fwy, energy, power, dissipation


@njit(**INLINE)
def wheel_contacts(w, m, diag):
    """Every road wheel against the track: links, then pins in the wedge."""
    rho = m.par[P_WHEEL_RADIUS] + m.par[P_PAD_WHEEL]
    energy = 0.0
    power = 0.0
    dissipation = 0.0
    for i in range(w.wc.shape[0]):
        acc = _wheel_on_links(i, w, m, rho, diag, (0.0, 0.0, energy, power, dissipation))
        fwx, fwy, energy, power, dissipation = _wheel_on_pins(i, w, m, rho, acc)
        w.fwheel[i, 0] = fwx
        w.fwheel[i, 1] = fwy
        diag[D_WHEEL + 2 * i] = fwx
        diag[D_WHEEL + 2 * i + 1] = fwy
    diag[D_E_PAD_WHEEL] = energy
    diag[D_POWER] += power
    diag[D_DISSIPATION] += dissipation


@njit(**INLINE)
def _pins_on_ground(w, m, hg, acc):
    """Free pins on ground segments (Fig. 5 left, Eq. 6), the nearest segment only where
    a pin is beyond several (gaps.pin_ground_selection). acc = (fx, fy, corner force,
    energy, power, obstacle force, dissipation), carried through in the order of one loop.
    Every segment after the first (the ground the vehicle starts on) is an obstacle's."""
    apos, seg = w.apos, m.seg
    damped = m.par[P_CONTACT_DAMPING] != DAMPING_NONE
    gx, gy, corner_force, energy, power, obstacle, dissipation = acc
    for b in range(1, apos.shape[0] - 1):
        row = m.nbr_rows[K_PIN_GROUND] + b
        inside, n_below, best = pin_ground_selection(apos[b, 0], apos[b, 1], seg, m.nbr, row, hg)
        if best == -np.inf:
            continue
        for j in range(m.nbr[row, NB_COUNT]):
            sj = m.nbr[row, 1 + j]
            lam, s, _ = segment_coords(apos[b, 0], apos[b, 1], seg, sj)
            if not pin_segment_acts(lam, s, seg, sj, hg, inside, n_below, best):
                continue
            rate = -(w.avel[b, 0] * seg[sj, SEG_NX] + w.avel[b, 1] * seg[sj, SEG_NY]) if damped else 0.0
            p, e, pd = _force(m, w, P_C_GROUND, row, j, hg - s, rate)  # Eq. (6)
            fx = p * seg[sj, SEG_NX]
            fy = p * seg[sj, SEG_NY]
            w.fpin[b, 0] += fx
            w.fpin[b, 1] += fy
            gx += fx
            gy += fy
            energy += e
            dissipation += pd
            power += fx * w.avel[b, 0] + fy * w.avel[b, 1]
            if sj > 0:
                obstacle += p
    return gx, gy, corner_force, energy, power, obstacle, dissipation


@njit(**INLINE)
def _corner_on_links(c, w, m, hg, diag, acc):
    """Ground corner c against the links (Fig. 5 right), split by Eq. (7); acc as above."""
    apos, lk = w.apos, w.lk
    cx = m.corners[c, 0]
    cy = m.corners[c, 1]
    hw = m.par[P_PAD_WHEEL]
    damped = m.par[P_CONTACT_DAMPING] != DAMPING_NONE
    gx, gy, corner_force, energy, power, obstacle, dissipation = acc
    row = m.nbr_rows[K_CORNER_LINK] + c
    for j in range(m.nbr[row, NB_COUNT]):
        b = m.nbr[row, 1 + j]
        d0, s_in = link_coords(cx, cy, apos, lk, b)
        if d0 < 0.0 or d0 > lk[b, 2]:
            continue
        s = -s_in  # along the outer normal -n_inner
        if s >= hg or s <= -hw:
            continue
        if s < 0.0:
            diag[D_STATUS] = CORNER_THROUGH_TRACK
            continue
        rate = _link_rate(0.0, 0.0, w, b, d0) if damped else 0.0   # d(s_in)/dt = -ds/dt
        p, e, pd = _force(m, w, P_C_GROUND, row, j, hg - s, rate)
        fx = p * lk[b, 1]
        fy = -p * lk[b, 0]
        gx += fx
        gy += fy
        corner_force += p
        energy += e
        dissipation += pd
        power += _link_load(w.fpin, w.avel, b, d0, lk[b, 2], fx, fy)
        obstacle += p
    return gx, gy, corner_force, energy, power, obstacle, dissipation


@njit(**INLINE)
def _corner_on_pins(c, w, m, hg, acc):
    """Ground corner c against free pins in the wedge (Fig. 6); acc as above."""
    apos = w.apos
    cx = m.corners[c, 0]
    cy = m.corners[c, 1]
    damped = m.par[P_CONTACT_DAMPING] != DAMPING_NONE
    gx, gy, corner_force, energy, power, obstacle, dissipation = acc
    row = m.nbr_rows[K_CORNER_PIN] + c
    for j in range(m.nbr[row, NB_COUNT]):
        b = m.nbr[row, 1 + j]
        if not in_pin_wedge(cx, cy, apos, w.lk, b, False):
            continue
        dx = cx - apos[b, 0]
        dy = cy - apos[b, 1]
        dist = math.sqrt(dx * dx + dy * dy)
        if dist >= hg:
            continue
        rate = (dx * w.avel[b, 0] + dy * w.avel[b, 1]) / dist if damped else 0.0
        p, e, pd = _force(m, w, P_C_GROUND, row, j, hg - dist, rate)
        fx = -p * dx / dist
        fy = -p * dy / dist
        w.fpin[b, 0] += fx
        w.fpin[b, 1] += fy
        gx += fx
        gy += fy
        corner_force += p
        energy += e
        dissipation += pd
        power += fx * w.avel[b, 0] + fy * w.avel[b, 1]
        obstacle += p
    return gx, gy, corner_force, energy, power, obstacle, dissipation


@njit(**INLINE)
def ground_contacts(w, m, diag):
    """The track against the ground: pins on segments, then each corner on links and pins."""
    hg = m.par[P_PAD_GROUND]
    acc = _pins_on_ground(w, m, hg, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    for c in range(m.corners.shape[0]):
        acc = _corner_on_links(c, w, m, hg, diag, acc)
        acc = _corner_on_pins(c, w, m, hg, acc)
    gx, gy, corner_force, energy, power, obstacle, dissipation = acc
    diag[D_E_PAD_GROUND] = energy
    diag[D_GROUND_FX] = gx
    diag[D_GROUND_FY] = gy
    diag[D_CORNER_FORCE] = corner_force
    diag[D_OBSTACLE_FORCE] = obstacle
    diag[D_POWER] += power
    diag[D_DISSIPATION] += dissipation


@njit(**INLINE)
def track_loads(w, m, diag):
    """All forces of the track model for the pin and wheel kinematics in w (fpin is
    overwritten, tension first): tension and contact forces on the pins (w.fpin, pins 0
    and n_links included), contact forces on the wheels (w.fwheel), energies, power and
    status in diag. Gravity is left to the caller."""
    diag[D_STATUS] = 0.0
    diag[D_POWER] = 0.0
    diag[D_DISSIPATION] = 0.0
    m.counters[C_EVALUATIONS] += 1
    refresh_neighbours(w, m)
    link_tensions(w, m.par, diag)
    wheel_contacts(w, m, diag)
    ground_contacts(w, m, diag)


@njit(**KERNEL)
def remember_onsets(m, w):
    """After an accepted step (the last evaluation was at its end state): pairs in contact
    there keep the approach speed of their onset, a pair that came into contact in the
    step takes its compression rate now (the event location ends such a step just after
    the onset), a pair out of contact forgets it. Only the laws by restitution use it;
    memory is never touched inside a step, so a rejected step leaves no trace."""
    if m.par[P_CONTACT_DAMPING] < DAMPING_HUNT_CROSSLEY:
        return
    now = m.counters[C_EVALUATIONS]
    v_min = m.par[P_MIN_APPROACH]
    for row in range(m.v0.shape[0]):
        for p in range(m.v0.shape[1]):
            if w.pair_seen[row, p] != now:
                m.v0[row, p] = 0.0
            elif m.v0[row, p] <= 0.0:
                m.v0[row, p] = max(w.pair_rate[row, p], v_min)
