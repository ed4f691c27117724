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
from .gaps import (ground_distance, link_frames, pin_cap_weight, pin_ground_selection, pin_segment_valid, point_on_link,
                   point_on_segment, segment_coords)
from .contact_force import friction, normal_force
from .soil_force import pin_on_soil, soil_shear
from .grip import pin_grip, uses_bristle
from .contact_laws import DAMPING_HUNT_CROSSLEY, DAMPING_NONE, GEOMETRY_CONTINUOUS, LAW_LINEAR
from .jit import BORROW, INLINE, KERNEL
from .index import diag_tension
from .layout import (
    LK_LENGTH, LK_TX, LK_TY,
    G_LIMIT, G_REACH, K_GUIDE_LINK, K_GUIDE_PIN, PN_LAST, P_PIN_AREA, P_SOIL,
    C_EVALUATIONS, D_DISSIPATION, P_CONTACT_GEOMETRY, P_FRICTION, P_FRICTION_VELOCITY, P_C_GROUND, P_C_WHEEL, P_CONTACT_DAMPING, P_CONTACT_EXPONENT, P_CONTACT_LAW, P_DAMPING_RAMP, P_LINK_DAMPING, P_MIN_APPROACH, P_RESTITUTION_FACTOR, C_REBUILDS, D_CORNER_FORCE, D_E_PAD_GROUND, D_E_PAD_WHEEL, D_E_TENSION, D_GROUND_FX, D_GROUND_FY, D_MAX_TENSION, D_MIN_TENSION, D_OBSTACLE_FORCE, D_POWER, D_STATUS, D_WHEEL, K_CORNER_LINK, K_CORNER_PIN, K_PIN_GROUND, K_WHEEL_LINK, K_WHEEL_PIN, NB_COUNT, P_K_GROUND, P_K_WHEEL, P_LINK_LENGTH, P_LINK_STIFFNESS, P_PAD_GROUND, P_PAD_WHEEL, P_SKIN, P_WHEEL_RADIUS, SEG_LENGTH, SEG_NX, SEG_NY, SEG_TX, SEG_TY, SEG_X0, SEG_Y0,
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


@njit(**BORROW)
def build_neighbours(apos, wc, gc, m):
    """Fill the candidate lists: every pair that could touch while no pin, wheel, idler or
    roller (gc) moves more than half the skin from where it is now."""
    par, seg, corners, nbr, rows = m.par, m.seg, m.corners, m.nbr, m.nbr_rows
    last = m.pins[PN_LAST]
    skin = par[P_SKIN]
    hg = par[P_PAD_GROUND]
    reach_w = par[P_WHEEL_RADIUS] + par[P_PAD_WHEEL] + skin
    reach_cl = max(hg, par[P_PAD_WHEEL]) + skin
    for i in range(wc.shape[0]):
        _near_links(wc[i, 0], wc[i, 1], apos, reach_w, nbr, rows[K_WHEEL_LINK] + i)
        _near_pins(wc[i, 0], wc[i, 1], apos, last, reach_w, nbr, rows[K_WHEEL_PIN] + i)
    for j in range(gc.shape[0]):
        reach_g = m.guides[j, G_REACH] + skin
        _near_links(gc[j, 0], gc[j, 1], apos, reach_g, nbr, rows[K_GUIDE_LINK] + j)
        _near_pins(gc[j, 0], gc[j, 1], apos, last, reach_g, nbr, rows[K_GUIDE_PIN] + j)
    for c in range(corners.shape[0]):
        _near_links(corners[c, 0], corners[c, 1], apos, reach_cl, nbr, rows[K_CORNER_LINK] + c)
        _near_pins(corners[c, 0], corners[c, 1], apos, last, hg + skin, nbr, rows[K_CORNER_PIN] + c)
    for b in range(1, last + 1):
        row = rows[K_PIN_GROUND] + b
        n = 0
        for j in range(seg.shape[0]):
            lam, s, _ = segment_coords(apos[b, 0], apos[b, 1], seg, j)
            if lam > -skin and lam < seg[j, SEG_LENGTH] + skin and s < hg + skin:
                n += 1
                nbr[row, n] = j
        nbr[row, NB_COUNT] = n


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


@njit(**INLINE)
def link_tensions(apos, avel, par, lk, fpin, diag, t_off):
    """Eq. (8): T = k_tau (|a_b - a_(b+1)| - L0), linear both ways, plus the link's axial
    dashpot c l' where track.link_damping is set; sets fpin to the pull on every pin,
    stores t and length in lk and T in diag[t_off + b]."""
    k = par[P_LINK_STIFFNESS]
    l0 = par[P_LINK_LENGTH]
    c = par[P_LINK_DAMPING]
    dissipation = 0.0
    fpin[0, 0] = 0.0
    fpin[0, 1] = 0.0
    energy = 0.0
    tmin = np.inf
    tmax = -np.inf
    link_frames(apos, lk)
    if lk.shape[0] == apos.shape[0]:   # closed loop: one more row, link 0 again, for pin n_links's cap
        for col in range(lk.shape[1]):
            lk[lk.shape[0] - 1, col] = lk[0, col]
    for b in range(apos.shape[0] - 1):
        tx = lk[b, LK_TX]
        ty = lk[b, LK_TY]
        stretch = lk[b, LK_LENGTH] - l0
        tension = k * stretch
        if c != 0.0:
            rate = (avel[b + 1, 0] - avel[b, 0]) * tx + (avel[b + 1, 1] - avel[b, 1]) * ty
            tension += c * rate
            dissipation += c * rate * rate
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
    diag[D_DISSIPATION] += dissipation
    diag[D_POWER] -= dissipation   # the dashpots' work on the pins


@njit(**BORROW)
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
def contact_law(par, kc):
    """The scenario's normal-force law for one contact kind (kc: P_C_WHEEL for wheel-track,
    P_C_GROUND for ground- and corner-track) as the tuple normal_force takes."""
    k = par[P_K_WHEEL] if kc == P_C_WHEEL else par[P_K_GROUND]
    return (int(par[P_CONTACT_LAW]), int(par[P_CONTACT_DAMPING]), k, par[P_CONTACT_EXPONENT], par[kc],
            par[P_RESTITUTION_FACTOR], par[P_DAMPING_RAMP])


@njit(**INLINE)
def _link_rate(vx, vy, avel, lk, b, d0):
    """ds/dt of a point moving at v against link b (s along the inner normal, d0 its foot):
    (v - a_b') . n_b + d0 omega_b, omega_b the link's rotation rate."""
    dvx = avel[b + 1, 0] - avel[b, 0]
    dvy = avel[b + 1, 1] - avel[b, 1]
    omega = (lk[b, LK_TX] * dvy - lk[b, LK_TY] * dvx) / lk[b, LK_LENGTH]
    return (vx - avel[b, 0]) * lk[b, LK_TY] - (vy - avel[b, 1]) * lk[b, LK_TX] + d0 * omega


@njit(**BORROW)
def law_force(law, delta, rate, mem, row, partner):
    """normal_force of one contact by a law beyond the paper's (compiled once, called:
    the paper's linear spring stays inline in the loops). For the laws by restitution
    the approach speed v0 is the one remembered at the pair's onset (remember_onsets),
    or, for an onset inside the step being tried, the current rate, which becomes the
    memory once the step is accepted. mem = (v0 table, seen stamps, rates, counters,
    min approach speed)."""
    v0 = 1.0
    if law[1] >= DAMPING_HUNT_CROSSLEY:
        v0tab, seen, rates, counters, v_min = mem
        seen[row, partner] = counters[C_EVALUATIONS]
        rates[row, partner] = rate
        v0 = v0tab[row, partner]
        if v0 <= 0.0:
            v0 = max(rate, v_min)
    return normal_force(law, delta, rate, v0)


@njit(**INLINE)
def _pad(plain, law, delta, rate, mem, row, partner):
    """(force, energy, damping power) of a pad compressed by delta > 0: the paper's spring
    inline (plain), any other law through law_force."""
    if plain:
        k = law[2]
        return k * delta, 0.5 * k * delta ** 2, 0.0
    return law_force(law, delta, rate, mem, row, partner)


@njit(**INLINE)
def _slip(mu, v_eps, p, v, t, fx, fy):
    """The force (fx, fy) on a track point plus its friction, the point sliding at v relative
    to what it presses on, along the contact's unit tangent t, under normal force p; and
    friction's dissipated power."""
    vt = v[0] * t[0] + v[1] * t[1]
    ft = friction(mu, v_eps, p, vt)
    return fx + ft * t[0], fy + ft * t[1], -ft * vt


@njit(**INLINE)
def _link_friction(avel, lk, b, d0, probe_force, p, mu, v_eps):
    """_slip of link b's point at d0 from pin b (its velocity the Eq. 7 blend of the pins')
    past a probe, along the link; probe_force = (probe vx, vy, force fx, fy on the link)."""
    vx, vy, fx, fy = probe_force
    w1 = d0 / lk[b, LK_LENGTH]
    ux = (1.0 - w1) * avel[b, 0] + w1 * avel[b + 1, 0] - vx
    uy = (1.0 - w1) * avel[b, 1] + w1 * avel[b + 1, 1] - vy
    return _slip(mu, v_eps, p, (ux, uy), (lk[b, LK_TX], lk[b, LK_TY]), fx, fy)


@njit(**INLINE)
def _push_pin(fpin, avel, b, force, other_v, tangent, fr, acc, counts):
    """A contact force on pin b into fpin and acc (layout of _probe_on_track's): force =
    (fx, fy, normal force p, pad energy, damping power), other_v the velocity of what the
    pin presses on, friction fr = (mu, v_eps) along the unit tangent, counts = what the
    force adds to acc's normal and obstacle sums."""
    fx, fy, p, e, pd = force
    vx, vy = other_v
    mu, v_eps = fr
    ftx, fty, normal, energy, power, obstacle, dissipation = acc
    if mu > 0.0:
        fx, fy, fd = _slip(mu, v_eps, p, (avel[b, 0] - vx, avel[b, 1] - vy), tangent, fx, fy)
        dissipation += fd
    fpin[b, 0] += fx
    fpin[b, 1] += fy
    power += fx * (avel[b, 0] - vx) + fy * (avel[b, 1] - vy)
    return ftx + fx, fty + fy, normal + counts[0], energy + e, power, obstacle + counts[1], dissipation + pd


# A probe is a point pressed against the track's pads: a road-wheel centre (reach r + h_w,
# from the inner side) or a ground corner (reach h_g, from the outer side). rule = (side,
# reach, wrong, status): side +1 for the inner side, -1 for the outer; a probe further than
# `wrong` on the other side of a link's centre line is no contact, a nearer one went through
# the track (status). probe = (x, y, vx, vy). acc = (fx, fy, normal force, energy, power,
# obstacle force, dissipation): (fx, fy) the sum of the contact forces on the track, so the
# probe takes minus it; carried through in the order of one loop.


@njit(**INLINE)
def _probe_on_track(probe, rule, rows, w, nbr, law, continuous, mem, diag, acc):
    """The probe against the candidate links of rows[0] where its foot lies on the link
    (Fig. 3, Eq. 4; Fig. 5 right: along the link's normal, split to its pins by Eq. 7), then
    against the round caps of the candidate free pins of rows[1], each as often as
    gaps.pin_cap_weight counts it (the paper: the convex wedge, Figs. 4 and 6)."""
    px, py, vx, vy = probe
    side, reach, wrong, status, mu, v_eps = rule
    row_link, row_pin = rows
    apos, avel, lk, fpin = w.apos, w.avel, w.lk, w.fpin
    ftx, fty, normal, energy, power, obstacle, dissipation = acc
    damped = law[1] != DAMPING_NONE
    plain = law[0] == LAW_LINEAR and not damped    # the paper's spring: no call
    for j in range(nbr[row_link, NB_COUNT]):
        b = nbr[row_link, 1 + j]
        d0, s_in = point_on_link(px, py, apos[b, 0], apos[b, 1], lk[b, LK_TX], lk[b, LK_TY])
        s = side * s_in
        if d0 < 0.0 or d0 > lk[b, LK_LENGTH] or s >= reach or s <= -wrong:
            continue
        if s < 0.0:
            diag[D_STATUS] = status
            continue
        rate = -side * _link_rate(vx, vy, avel, lk, b, d0) if damped else 0.0
        p, e, pd = _pad(plain, law, reach - s, rate, mem, row_link, b)     # Eqs. (4), (6)
        fx = p * lk[b, LK_TY]     # p n_inner: a corner lifts the link
        fy = -p * lk[b, LK_TX]
        if side > 0.0:            # a wheel presses it down
            fx = -fx
            fy = -fy
        if mu > 0.0:
            fx, fy, fd = _link_friction(avel, lk, b, d0, (vx, vy, fx, fy), p, mu, v_eps)
            dissipation += fd
        ftx += fx
        fty += fy
        normal += p
        energy += e
        dissipation += pd
        power -= fx * vx + fy * vy
        power += _link_load(fpin, avel, b, d0, lk[b, LK_LENGTH], fx, fy)
        obstacle += p
    for j in range(nbr[row_pin, NB_COUNT]):
        b = nbr[row_pin, 1 + j]
        weight = pin_cap_weight(px, py, apos[b, 0], apos[b, 1], lk[b - 1, LK_TX], lk[b - 1, LK_TY], lk[b, LK_TX],
                                lk[b, LK_TY], side > 0.0, continuous)
        if weight == 0:
            continue
        dx = px - apos[b, 0]
        dy = py - apos[b, 1]
        dist = math.sqrt(dx * dx + dy * dy)
        if dist >= reach:
            continue
        rate = -(dx * (vx - avel[b, 0]) + dy * (vy - avel[b, 1])) / dist if damped else 0.0
        p, e, pd = _pad(plain, law, reach - dist, rate, mem, row_pin, b)
        if weight != 1:
            p, e, pd = weight * p, weight * e, weight * pd
        acc = (ftx, fty, normal, energy, power, obstacle, dissipation)
        force = (-p * dx / dist, -p * dy / dist, p, e, pd)    # on the pin, away from the probe
        acc = _push_pin(fpin, avel, b, force, (vx, vy), (dy / dist, -dx / dist), (mu, v_eps), acc, (p, p))
        ftx, fty, normal, energy, power, obstacle, dissipation = acc
    return ftx, fty, normal, energy, power, obstacle, dissipation


@njit(**INLINE)
def round_on_track(probe, reach, rows, w, m, law, continuous, mem, diag, acc):
    """A round body (road wheel, idler, roller: centre and velocity in probe, wheel radius +
    pad h_w in reach) pressing the track from inside, frictionless: _probe_on_track with
    the body's own force (acc's first two) from 0 and the other sums carried on."""
    rule = (1.0, reach, reach, WHEEL_THROUGH_TRACK, 0.0, 1.0)
    _, _, normal, energy, power, obstacle, dissipation = acc
    acc = (0.0, 0.0, normal, energy, power, obstacle, dissipation)
    return _probe_on_track(probe, rule, rows, w, m.nbr, law, continuous, mem, diag, acc)


@njit(**INLINE)
def wheel_contacts(w, m, diag, mem):
    """Every road wheel against the track: links (Fig. 3, Eq. 4), then pin caps (Fig. 4).
    mem: see law_force."""
    par = m.par
    law = contact_law(par, P_C_WHEEL)
    continuous = par[P_CONTACT_GEOMETRY] == GEOMETRY_CONTINUOUS
    rho = par[P_WHEEL_RADIUS] + par[P_PAD_WHEEL]
    acc = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    for i in range(w.fwheel.shape[0]):
        probe = (w.wc[i, 0], w.wc[i, 1], w.wv[i, 0], w.wv[i, 1])
        rows = (m.nbr_rows[K_WHEEL_LINK] + i, m.nbr_rows[K_WHEEL_PIN] + i)
        acc = round_on_track(probe, rho, rows, w, m, law, continuous, mem, diag, acc)
        fwx = 0.0 - acc[0]
        fwy = 0.0 - acc[1]
        w.fwheel[i, 0] = fwx
        w.fwheel[i, 1] = fwy
        diag[D_WHEEL + 2 * i] = fwx
        diag[D_WHEEL + 2 * i + 1] = fwy
    diag[D_E_PAD_WHEEL] = acc[3]
    diag[D_POWER] += acc[4]
    diag[D_DISSIPATION] += acc[6]


@njit(**INLINE)
def _ground_traction(b, apos, avel, t, p, par, soil, law, gripped):
    """The tangential force along the ground's unit tangent t on pin b pressed with p:
    (force, its dissipated power, the mu left for the regularised Coulomb law of _push_pin,
    gripped). law = (on soft soil, bristle law), decided once per call of _pins_on_ground.
    On soft soil Janosi-Hanamoto's shear replaces friction; with the bristle law the pin's
    first ground contact holds its bristle (later ones, at a concave corner, keep the
    regularised law); otherwise the regularised law alone."""
    _, touchdown, _, grip = soil
    on_soil, bristle = law
    if on_soil:
        return soil_shear(apos[b, 0], apos[b, 1], touchdown[b, 0], touchdown[b, 1], t, p, par), 0.0, 0.0, gripped
    if bristle and not gripped:
        ft, fd = pin_grip(b, apos, avel, t, p, par, touchdown, grip)
        return ft, fd, 0.0, True
    return 0.0, 0.0, par[P_FRICTION], gripped


@njit(**INLINE)
def _pins_on_ground(apos, avel, fpin, last, par, seg, nbr, rows, mem, soil, acc):
    """Free pins on ground segments (Fig. 5 left, Eq. 6), the nearest segment only where
    a pin is beyond several (gaps.pin_ground_selection); in the continuous geometry one
    contact per pin with the ground's nearest point (gaps.ground_distance). acc = (fx,
    fy, corner force, energy, power, obstacle force, dissipation), carried through in
    the order of one loop. Every segment after the first (the ground the vehicle starts
    on) belongs to an obstacle. soil = (rut memory, sinkage out): on soft soil a pin sunk by
    z = h_g - s takes the soil's pressure times its area instead of the pad spring."""
    law = contact_law(par, P_C_GROUND)
    damped = law[1] != DAMPING_NONE
    plain = law[0] == LAW_LINEAR and not damped
    continuous = par[P_CONTACT_GEOMETRY] == GEOMETRY_CONTINUOUS
    v_eps = par[P_FRICTION_VELOCITY]
    hg = par[P_PAD_GROUND]
    first = rows[K_PIN_GROUND]
    on_soil = par[P_SOIL] != 0.0
    bristle = uses_bristle(par)
    rut, _, sink, grip = soil
    gx, gy, corner_force, energy, power, obstacle, dissipation = acc
    for b in range(1, last + 1):
        row = first + b
        if on_soil:
            sink[b] = 0.0
        if bristle:
            grip[b, G_LIMIT] = np.nan
        gripped = False                # the bristle on the pin's first ground contact only
        if nbr[row, NB_COUNT] == 0:    # no ground within reach (the closed track's top run): no call
            continue
        if continuous:
            inside, n_below, best = False, 0, 0.0
        else:
            inside, n_below, best = pin_ground_selection(apos[b, 0], apos[b, 1], seg, nbr, row, hg)
            if best == -np.inf:
                continue
        for j in range(1 if continuous else nbr[row, NB_COUNT]):
            if continuous:   # one contact: its memory (law_force) under partner 0
                s, nx, ny, sj = ground_distance(apos[b, 0], apos[b, 1], seg, nbr, row)
                partner = 0
            else:
                sj = nbr[row, 1 + j]
                partner = sj
                nx = seg[sj, SEG_NX]
                ny = seg[sj, SEG_NY]
                lam, s = point_on_segment(apos[b, 0], apos[b, 1], seg[sj, SEG_X0], seg[sj, SEG_Y0], seg[sj, SEG_TX],
                                          seg[sj, SEG_TY], nx, ny)
                if s < hg and not pin_segment_valid(lam, s, seg[sj, SEG_LENGTH], inside, n_below, best):
                    continue
            if s >= hg:
                continue
            if on_soil:     # Bekker pressure instead of the pad spring
                p = pin_on_soil(apos[b, 0], hg - s, par, rut) * par[P_PIN_AREA]
                e, pd = 0.0, 0.0
                sink[b] = max(sink[b], hg - s)
            else:
                rate = -(avel[b, 0] * nx + avel[b, 1] * ny) if damped else 0.0
                p, e, pd = _pad(plain, law, hg - s, rate, mem, row, partner)     # Eq. (6)
            ft, fd, mu_left, gripped = _ground_traction(b, apos, avel, (ny, -nx), p, par, soil, (on_soil, bristle),
                                                        gripped)
            fx, fy = p * nx + ft * ny, p * ny - ft * nx
            if on_soil:     # what the soil takes counts as dissipated (its elastic rebound gives some back)
                pd = -(fx * avel[b, 0] + fy * avel[b, 1])
            force = (fx, fy, p, e, pd)
            dissipation += fd
            fr = (mu_left, v_eps)
            acc = (gx, gy, corner_force, energy, power, obstacle, dissipation)
            acc = _push_pin(fpin, avel, b, force, (0.0, 0.0), (ny, -nx), fr, acc, (0.0, p if sj > 0 else 0.0))
            gx, gy, corner_force, energy, power, obstacle, dissipation = acc
    return gx, gy, corner_force, energy, power, obstacle, dissipation


@njit(**INLINE)
def _corners(w, m, diag, mem, acc):
    """Every convex ground corner against the links (Fig. 5 right, split by Eq. 7) and the
    pin caps (Fig. 6); acc as in _pins_on_ground."""
    par = m.par
    law = contact_law(par, P_C_GROUND)
    continuous = par[P_CONTACT_GEOMETRY] == GEOMETRY_CONTINUOUS
    rule = (-1.0, par[P_PAD_GROUND], par[P_PAD_WHEEL], CORNER_THROUGH_TRACK, par[P_FRICTION],
            par[P_FRICTION_VELOCITY])
    for c in range(m.corners.shape[0]):
        probe = (m.corners[c, 0], m.corners[c, 1], 0.0, 0.0)
        rows = (m.nbr_rows[K_CORNER_LINK] + c, m.nbr_rows[K_CORNER_PIN] + c)
        acc = _probe_on_track(probe, rule, rows, w, m.nbr, law, continuous, mem, diag, acc)
    return acc


@njit(**INLINE)
def ground_contacts(w, m, diag, mem):
    """The track against the ground: pins on segments, then the corners."""
    acc = _pins_on_ground(w.apos, w.avel, w.fpin, m.pins[PN_LAST], m.par, m.seg, m.nbr, m.nbr_rows, mem,
                          (m.rut, m.touchdown, w.sink, w.grip),
                          (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    gx, gy, corner_force, energy, power, obstacle, dissipation = _corners(w, m, diag, mem, acc)
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
    apos, wc, par = w.apos, w.wc, m.par
    mem = (m.v0, w.pair_seen, w.pair_rate, m.counters, par[P_MIN_APPROACH])
    diag[D_STATUS] = 0.0
    diag[D_POWER] = 0.0
    diag[D_DISSIPATION] = 0.0
    m.counters[C_EVALUATIONS] += 1
    refresh_neighbours(apos, wc, m.guides, m)   # m.guides: no rows, as no idler or rollers
    link_tensions(apos, w.avel, par, w.lk, w.fpin, diag, diag_tension(wc.shape[0]))
    wheel_contacts(w, m, diag, mem)
    ground_contacts(w, m, diag, mem)


@njit(**BORROW)
def remember_onsets(m, w):
    """After an accepted step (the last evaluation was at its end state): pairs in contact
    there keep the approach speed of their onset, a pair that came into contact in the
    step takes its compression rate now (the event location ends such a step just after
    the onset), a pair out of contact forgets it. Only the laws by restitution use it;
    memory is never touched inside a step, so a rejected step leaves no trace."""
    if m.par[P_CONTACT_DAMPING] < DAMPING_HUNT_CROSSLEY:
        return
    v0, seen, rates = m.v0, w.pair_seen, w.pair_rate
    now = m.counters[C_EVALUATIONS]
    v_min = m.par[P_MIN_APPROACH]
    for row in range(v0.shape[0]):
        for p in range(v0.shape[1]):
            if seen[row, p] != now:
                v0[row, p] = 0.0
            elif v0[row, p] <= 0.0:
                v0[row, p] = max(rates[row, p], v_min)


@njit(**BORROW)
def onset_in_step(m, w):
    """Did a pair come into contact in the step just tried (in contact at its end, the
    last evaluation, with no approach speed remembered yet)? Only for the laws by
    restitution: the solver then ends the step at the located onset, so that the
    approach speed taken there does not depend on where the step happened to end."""
    if m.par[P_CONTACT_DAMPING] < DAMPING_HUNT_CROSSLEY:
        return False
    v0, seen = m.v0, w.pair_seen
    now = m.counters[C_EVALUATIONS]
    for row in range(v0.shape[0]):
        for p in range(v0.shape[1]):
            if seen[row, p] == now and v0[row, p] <= 0.0:
                return True
    return False
