"""Compiled track kernels shared by every solver: link tension (Eq. 8), wheel-track
and ground-track penalty contacts (Eqs. 2-7, Figs. 3-6 and the contact cases of docs/model.md),
and the candidate lists that keep the contact search away from far-apart pairs.

Every kernel takes the bundles of model/core/bundles.py: ``m`` (ModelArrays: parameters,
ground, candidate lists), ``w`` (Work: pin and wheel kinematics in, forces out) and
``diag`` (indices.D_*). The geometry of each contact (which side, which wedge, which
segment) is model/contact/gaps.py.
"""

import math

from numba import njit

from ...status import WHEEL_THROUGH_TRACK
from ..core.indices import (
    ARMS_REACH,
    C_EVALUATIONS,
    D_DISSIPATION,
    D_E_PAD_WHEEL,
    D_POWER,
    D_STATUS,
    D_WHEEL,
    K_WHEEL_LINK,
    K_WHEEL_PIN,
    LK_LENGTH,
    LK_TX,
    LK_TY,
    NB_COUNT,
    P_C_WHEEL,
    P_CONTACT_DAMPING,
    P_CONTACT_EXPONENT,
    P_CONTACT_GEOMETRY,
    P_CONTACT_LAW,
    P_DAMPING_RAMP,
    P_K_GROUND,
    P_K_WHEEL,
    P_RESTITUTION_FACTOR,
)
from ..core.jit import BORROW, INLINE
from .gaps import pin_cap_weight, point_on_link
from .laws import DAMPING_NONE, GEOMETRY_CONTINUOUS, LAW_LINEAR
from .laws_jit import friction, needs_approach_speed, normal_force


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
    the paper's linear spring stays inline in the loops). For the laws that need it the
    approach speed v0 is the one remembered at the pair's onset (remember_onsets),
    or, for an onset inside the step being tried, the current rate, which becomes the
    memory once the step is accepted. mem = (v0 table, seen stamps, rates, counters,
    min approach speed)."""
    v0 = 1.0
    if needs_approach_speed(law[1]):
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
        weight = pin_cap_weight(
            px,
            py,
            apos[b, 0],
            apos[b, 1],
            lk[b - 1, LK_TX],
            lk[b - 1, LK_TY],
            lk[b, LK_TX],
            lk[b, LK_TY],
            side > 0.0,
            continuous,
        )
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
    acc = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    for i in range(w.fwheel.shape[0]):
        rho = m.arms[i, ARMS_REACH]   # wheel radius + pad h_w, the station's own
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


