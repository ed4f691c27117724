"""The track on the ground: pins pressed on rigid ground or sunk into soil (Eq. 6), their
friction or shear, and the ground's convex corners pressed against the track."""

import numpy as np
from numba import njit

from ...status import CORNER_THROUGH_TRACK
from ..contact.gaps import ground_distance, pin_ground_selection, pin_segment_valid, point_on_segment
from ..contact.laws import DAMPING_NONE, GEOMETRY_CONTINUOUS, LAW_LINEAR
from ..contact.track_contacts import _pad, _probe_on_track, _push_pin, contact_law
from ..core.indices import (
    C_CORNER_END,
    C_CORNER_FIRST,
    D_CORNER_FORCE,
    D_DISSIPATION,
    D_E_PAD_GROUND,
    D_GROUND_FX,
    D_GROUND_FY,
    D_OBSTACLE_FORCE,
    D_POWER,
    K_CORNER_LINK,
    K_CORNER_PIN,
    K_PIN_GROUND,
    NB_COUNT,
    P_C_GROUND,
    P_CONTACT_GEOMETRY,
    P_FRICTION,
    P_FRICTION_VELOCITY,
    P_PAD_GROUND,
    P_PAD_WHEEL,
    P_PIN_AREA,
    P_SOIL,
    PN_LAST,
    SEG_LENGTH,
    SEG_NX,
    SEG_NY,
    SEG_TX,
    SEG_TY,
    SEG_X0,
    SEG_Y0,
)
from ..core.jit import INLINE
from .grip import pin_grip, uses_bristle
from .soil_jit import pin_on_soil, soil_shear


@njit(**INLINE)
def _ground_traction(b, apos, avel, t, p, par, soil, law, gripped):
    """The tangential force along the ground's unit tangent t on pin b pressed with p:
    (force, the mu left for the regularised Coulomb law of _push_pin, gripped). law = (on
    soft soil, bristle law), decided once per call of _pins_on_ground. On soft soil
    Janosi-Hanamoto's shear replaces friction; with the bristle law the pin's first ground
    contact holds its bristle (later ones, at a concave corner, keep the regularised law);
    otherwise the regularised law alone."""
    _, touchdown, _, grip = soil
    on_soil, bristle = law
    if on_soil:
        return soil_shear(apos[b, 0], apos[b, 1], touchdown[b, 0], touchdown[b, 1], t, p, par), 0.0, gripped
    if bristle and not gripped:
        return pin_grip(b, avel, t, p, par, grip), 0.0, True
    return 0.0, par[P_FRICTION], gripped


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
    rut, _, sink, _ = soil
    gx, gy, corner_force, energy, power, obstacle, dissipation = acc
    for b in range(1, last + 1):
        row = first + b
        if on_soil:
            sink[b] = 0.0
        gripped = False  # the bristle on the pin's first ground contact only
        if nbr[row, NB_COUNT] == 0:  # no ground within reach (the closed track's top run): no call
            continue
        if continuous:
            inside, n_below, best = False, 0, 0.0
        else:
            inside, n_below, best = pin_ground_selection(apos[b, 0], apos[b, 1], seg, nbr, row, hg)
            if best == -np.inf:
                continue
        for j in range(1 if continuous else nbr[row, NB_COUNT]):
            if continuous:  # one contact: its memory (law_force) under partner 0
                s, nx, ny, sj = ground_distance(apos[b, 0], apos[b, 1], seg, nbr, row)
                partner = 0
            else:
                sj = nbr[row, 1 + j]
                partner = sj
                nx = seg[sj, SEG_NX]
                ny = seg[sj, SEG_NY]
                lam, s = point_on_segment(
                    apos[b, 0],
                    apos[b, 1],
                    seg[sj, SEG_X0],
                    seg[sj, SEG_Y0],
                    seg[sj, SEG_TX],
                    seg[sj, SEG_TY],
                    nx,
                    ny,
                )
                if s < hg and not pin_segment_valid(lam, s, seg[sj, SEG_LENGTH], inside, n_below, best):
                    continue
            if s >= hg:
                continue
            if on_soil:  # Bekker pressure instead of the pad spring
                p = pin_on_soil(apos[b, 0], hg - s, par, rut) * par[P_PIN_AREA]
                e, pd = 0.0, 0.0
                sink[b] = max(sink[b], hg - s)
            else:
                rate = -(avel[b, 0] * nx + avel[b, 1] * ny) if damped else 0.0
                p, e, pd = _pad(plain, law, hg - s, rate, mem, row, partner)  # Eq. (6)
            ft, mu_left, gripped = _ground_traction(
                b, apos, avel, (ny, -nx), p, par, soil, (on_soil, bristle), gripped
            )
            fx, fy = p * nx + ft * ny, p * ny - ft * nx
            if on_soil:  # what the soil takes counts as dissipated (its elastic rebound gives some back)
                pd = -(fx * avel[b, 0] + fy * avel[b, 1])
            force = (fx, fy, p, e, pd)
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
    rule = (
        -1.0,
        par[P_PAD_GROUND],
        par[P_PAD_WHEEL],
        CORNER_THROUGH_TRACK,
        par[P_FRICTION],
        par[P_FRICTION_VELOCITY],
    )
    for c in range(m.counters[C_CORNER_FIRST], m.counters[C_CORNER_END]):  # those within reach
        probe = (m.corners[c, 0], m.corners[c, 1], 0.0, 0.0)
        rows = (m.nbr_rows[K_CORNER_LINK] + c, m.nbr_rows[K_CORNER_PIN] + c)
        acc = _probe_on_track(probe, rule, rows, w, m.nbr, law, continuous, mem, diag, acc)
    return acc


@njit(**INLINE)
def ground_contacts(w, m, diag, mem):
    """The track against the ground: pins on segments, then the corners."""
    acc = _pins_on_ground(
        w.apos,
        w.avel,
        w.fpin,
        m.pins[PN_LAST],
        m.par,
        m.seg,
        m.nbr,
        m.nbr_rows,
        mem,
        (m.rut, m.touchdown, w.sink, w.grip),
        (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    )
    gx, gy, corner_force, energy, power, obstacle, dissipation = _corners(w, m, diag, mem, acc)
    diag[D_E_PAD_GROUND] = energy
    diag[D_GROUND_FX] = gx
    diag[D_GROUND_FY] = gy
    diag[D_CORNER_FORCE] = corner_force
    diag[D_OBSTACLE_FORCE] = obstacle
    diag[D_POWER] += power
    diag[D_DISSIPATION] += dissipation
