"""The soil's memory along an accepted step, from its interpolant (the quintic Hermite of
hermite.py, positions only): the deepest sinkage a pin reached inside the step and where a pin
touched the soil. The memory (soil_jit.remember_sinkage) is otherwise moved from the step's
end state alone, which makes it depend on where the steps happened to end: a pin that went
deeper inside a step and rose again before its end left a shallower rut, and a pin that
touched down inside a step had its shear counted from where it was at the step's end."""

import numpy as np
from numba import njit

from ...model.contact.gaps import ground_distance, pin_ground_selection, pin_segment_valid, segment_coords
from ...model.contact.laws import GEOMETRY_CONTINUOUS
from ...model.core.indices import (
    K_PIN_GROUND,
    NB_COUNT,
    P_CONTACT_GEOMETRY,
    P_LINK_LENGTH,
    P_PAD_GROUND,
    P_RUT_DX,
    P_RUT_X0,
    P_SOIL,
    PN_LAST,
    PN_NQ,
    SEG_LENGTH,
)
from ...model.core.jit import BORROW
from ...model.ground.soil_jit import raise_memory
from .events import BISECTIONS, _pin_at
from .hermite import quintic_basis

# fraction of the step: a pin whose sinkage falls over this last bit of a step and rose over its
# first bit (or since it touched down) turned inside it
TURN_PROBE = 1e-3
GOLDEN_STEPS = 40  # golden-section steps for the turning point (the bracket shrinks to 4e-9)
GOLDEN = 0.6180339887498949


@njit(**BORROW)
def _sinkage_at(i, t, step, nq, m, n_links, ev):
    """Pin i's sinkage at fraction t of the step: the deepest of its valid ground contacts, as
    the force kernel's (ground_contact._pins_on_ground, the same selection); -1 m where it has
    none."""
    row = m.nbr_rows[K_PIN_GROUND] + i
    if m.nbr[row, NB_COUNT] == 0:
        return -1.0
    px, py = _pin_at(i, quintic_basis(t), step, nq, m, n_links, ev)
    hg = m.par[P_PAD_GROUND]
    if m.par[P_CONTACT_GEOMETRY] == GEOMETRY_CONTINUOUS:
        return hg - ground_distance(px, py, m.seg, m.nbr, row)[0]
    inside, n_below, best = pin_ground_selection(px, py, m.seg, m.nbr, row, hg)
    z = -1.0
    if best == -np.inf:
        return z
    for j in range(m.nbr[row, NB_COUNT]):
        sj = m.nbr[row, 1 + j]
        lam, s, _ = segment_coords(px, py, m.seg, sj)
        if hg - s > z and pin_segment_valid(lam, s, m.seg[sj, SEG_LENGTH], inside, n_below, best):
            z = hg - s
    return z


@njit(**BORROW)
def _touchdown(i, step, nq, m, n_links, ev):
    """Fraction of the step just after pin i, out of the soil at its start and in it at its
    end, entered the soil (bisection of its sinkage's last sign change)."""
    lo = 0.0
    hi = 1.0
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        if _sinkage_at(i, mid, step, nq, m, n_links, ev) > 0.0:
            hi = mid
        else:
            lo = mid
    return hi


@njit(**BORROW)
def _deepest(i, lo, z_end, step, nq, m, n_links, ev):
    """(t, z): pin i's deepest sinkage in [lo, 1] of the step where it turned inside it (its
    sinkage rose after lo and falls before the end; golden-section search), else (1, z_end)."""
    probe = TURN_PROBE * (1.0 - lo)
    if _sinkage_at(i, 1.0 - probe, step, nq, m, n_links, ev) <= z_end:
        return 1.0, z_end
    if _sinkage_at(i, lo + probe, step, nq, m, n_links, ev) <= _sinkage_at(i, lo, step, nq, m, n_links, ev):
        return 1.0, z_end
    a, b = lo, 1.0
    c = b - GOLDEN * (b - a)
    d = a + GOLDEN * (b - a)
    zc = _sinkage_at(i, c, step, nq, m, n_links, ev)
    zd = _sinkage_at(i, d, step, nq, m, n_links, ev)
    for _ in range(GOLDEN_STEPS):
        if zc >= zd:
            b, d, zd = d, c, zc
            c = b - GOLDEN * (b - a)
            zc = _sinkage_at(i, c, step, nq, m, n_links, ev)
        else:
            a, c, zc = c, d, zd
            d = a + GOLDEN * (b - a)
            zd = _sinkage_at(i, d, step, nq, m, n_links, ev)
    return (c, zc) if zc >= zd else (d, zd)


@njit(**BORROW)
def remember_inside_step(y0, f0, y1, f1, h, m, ev, end):
    """After an accepted step on soft soil (end: EndOfStep, its end state), before the memory
    is moved from that end state: a pin that touched the soil inside the step keeps where it
    touched (located on the interpolant), and the memory is raised to a pin's deepest
    sinkage inside the step where it turned there (soil_jit.raise_memory at that point)."""
    if m.par[P_SOIL] == 0.0:
        return
    nq = m.pins[PN_NQ]
    step = (y0, f0, y1, f1, h)
    n_links = ev.pins0.shape[0] - 1
    for i in range(1, m.pins[PN_LAST] + 1):
        if end.sink[i] <= 0.0:
            continue
        lo = 0.0
        if m.touchdown[i, 0] != m.touchdown[i, 0]:  # out of the soil at the step's start
            lo = _touchdown(i, step, nq, m, n_links, ev)
            x, y = _pin_at(i, quintic_basis(lo), step, nq, m, n_links, ev)
            m.touchdown[i, 0] = x
            m.touchdown[i, 1] = y
        t, z = _deepest(i, lo, end.sink[i], step, nq, m, n_links, ev)
        if t < 1.0:
            x, _ = _pin_at(i, quintic_basis(t), step, nq, m, n_links, ev)
            raise_memory(x, z, m.par[P_RUT_X0], m.par[P_RUT_DX], m.par[P_LINK_LENGTH], m.rut)
