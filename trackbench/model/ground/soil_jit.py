"""Soft soil under the track's pins, compiled (the soil values and closed forms: soil.py).

Bekker's pressure-sinkage law p = (k_c / b + k_phi) z^n while the soil is loaded beyond the
deepest sinkage z_m it has seen at that place; below z_m it unloads and reloads elastically,
p = p(z_m) - K_e (z_m - z) (not above the first-loading curve), down to zero at the plastic
sinkage z_m - p(z_m) / K_e (the rut).
z_m is the soil's memory along x: one node per cell centre (ModelArrays.rut), smoothly
interpolated between the two nodes around x (rut_nodes), so that a pin sliding along the
ground meets a memory with no jumps and no kinks (a jump in z_m is a jump in the elastic
branch's pressure, which every step across a cell boundary met and was rejected at). It is
raised only after an accepted step (remember_sinkage from the step's end state, and before it
solvers/common/sinkage.py from the step's interpolant: the deepest sinkage of a pin that turned
inside the step), so a rejected step leaves no trace, and the pressure is continuous where it is
raised at the step's end (at z = z_m both branches agree).

Shear by Janosi-Hanamoto, tau = (c + p tan phi)(1 - exp(-j / K)), on the pin's area A: the
shear displacement j is the pin's displacement along the surface since it touched the soil
(ModelArrays.touchdown, set after the accepted step in which it touched down, where its sinkage
crossed zero along the step's interpolant (solvers/common/sinkage.py), cleared when it leaves),
so a pin that slips by j shears the soil by j; it replaces Coulomb friction on soil."""

import math

import numpy as np
from numba import njit

from ..core import fixed_math as fm
from ..core.indices import (
    P_LINK_LENGTH,
    P_RUT_DX,
    P_RUT_X0,
    P_SOIL,
    P_SOIL_COHESION,
    P_SOIL_K,
    P_SOIL_KE,
    P_SOIL_N,
    P_SOIL_SHEAR_K,
    P_SOIL_TAN_PHI,
)
from ..core.jit import BORROW, INLINE, KERNEL, SCALAR

SURFACE_DEPTH = 1e-3     # m: for n < 1, Bekker's curve runs straight to the surface from here


@njit(**SCALAR)
def first_loading(z, n, k):
    """Bekker's p = k z^n; for n < 1 its slope is infinite at the surface, which no
    equilibrium search or step-size control can follow: straight to zero from SURFACE_DEPTH."""
    if n < 1.0 and z < SURFACE_DEPTH:
        return k * fm.pow(SURFACE_DEPTH, n) * (z / SURFACE_DEPTH)
    return k * fm.pow(z, n)


@njit(**SCALAR)
def soil_pressure(z, z_max, n, k, ke):
    """Pressure (Pa) at sinkage z where the soil has been pressed down to z_max before."""
    if z <= 0.0:
        return 0.0
    loading = first_loading(z, n, k)
    if z >= z_max:
        return loading
    # the elastic line, but never above the first-loading curve (for n < 1 that curve is
    # steeper than any K_e near the surface; Chrono's SCM takes the smaller alike)
    return max(min(first_loading(z_max, n, k) - ke * (z_max - z), loading), 0.0)


@njit(**INLINE)
def rut_nodes(x, x0, dx, n):
    """(c, w): the memory's node left of x (nodes at the centres of the cells of width dx from
    x0, n of them) and the weight of the node right of it, w = 10 u^3 - 15 u^4 + 6 u^5 at the
    fraction u of the way: the memory is then continuous with its slope and curvature along x
    (both zero at the nodes), so a pin sliding at speed v meets no jump in the rate of its
    pressure (K_e z_m'' v^2 would be one). c = -1 beyond the nodes (fresh soil)."""
    u = (x - x0) / dx - 0.5
    c = int(math.floor(u))
    if c < 0 or c + 1 >= n:
        return -1, 0.0
    u -= c
    return c, u * u * u * (10.0 + u * (6.0 * u - 15.0))


@njit(**INLINE)
def deepest_sinkage(x, par, rut):
    """z_m at x: the nodes around it, weighted (0 on fresh soil)."""
    c, wr = rut_nodes(x, par[P_RUT_X0], par[P_RUT_DX], rut.shape[0])
    if c < 0:
        return 0.0
    return (1.0 - wr) * rut[c] + wr * rut[c + 1]


@njit(**INLINE)
def pin_on_soil(x, z, par, rut):
    """Pressure under a pin at x sunk by z into the soil."""
    return soil_pressure(z, deepest_sinkage(x, par, rut), par[P_SOIL_N], par[P_SOIL_K], par[P_SOIL_KE])


KINK_MEMORY = 0       # soil_kink: at the deepest sinkage z_m, loading meets the elastic line
KINK_PLASTIC = 1      # at the plastic sinkage, the elastic line reaches zero pressure
N_KINKS = 2
KINK_TOL = 1e-12      # m: a pin within this of a kink is on it (z_m is raised to the sinkage
                      # reached after an accepted step, up to rounding)


@njit(**INLINE)
def soil_kink(x, z, kink, par, rut):
    """z minus the depth of a kink of the pressure law at x, for the event location: the
    law's slope jumps there (from Bekker's to K_e, from K_e to none) and a step across it
    is rejected unless it ends there."""
    zm = deepest_sinkage(x, par, rut)
    if kink == KINK_PLASTIC:
        zm -= first_loading(zm, par[P_SOIL_N], par[P_SOIL_K]) / par[P_SOIL_KE]
    return z - zm


@njit(**INLINE)
def raise_memory(x, z, x0, dx, shoe, rut):
    """A pin at x sunk by z stands for a shoe of its link's length: the soil under the whole
    shoe is pressed to z. The nodes around x are raised, never lowered, just enough that z_m
    at x becomes z (when z is deeper): both to z if z is deeper than both, else only the
    shallower one; every other node within half the shoe's length `shoe` (the link length)
    of x to z where it is shallower (beyond the nodes' ends, x has no two nodes around it:
    every node within that half). No node ends deeper than the deeper of its old value and a sinkage
    reached within half a shoe (or a cell) of it: a sliding pin leaves the sinkage it
    reached, not more. Raising one shoe moves the memory under no other sunk pin while
    sunk pins stay more than half a link and a cell apart along x (links less steep than
    ~55 deg; on paper_step on LETE sand the closest were 0.14 m apart against 0.105 m)."""
    n = rut.shape[0]
    c, wr = rut_nodes(x, x0, dx, n)
    half = 0.5 * shoe
    lo_i = max(int(math.ceil((x - half - x0) / dx - 0.5)), 0)
    hi_i = min(int(math.floor((x + half - x0) / dx - 0.5)), n - 1)
    for i in range(lo_i, hi_i + 1):
        if (c < 0 or (i != c and i != c + 1)) and rut[i] < z:
            rut[i] = z
    if c < 0 or z <= (1.0 - wr) * rut[c] + wr * rut[c + 1]:
        return
    lo, hi = (c, c + 1) if rut[c] <= rut[c + 1] else (c + 1, c)
    if z >= rut[hi]:
        rut[c] = z
        rut[c + 1] = z
        return
    w_lo = 1.0 - wr if lo == c else wr      # > 0 here: with w_lo = 0, z_m at x = rut[hi] > z
    rut[lo] = min(max((z - (1.0 - w_lo) * rut[hi]) / w_lo, rut[lo]), rut[hi])


@njit(**KERNEL)
def replay_memory(px, sink, x0, dx, shoe, idx, out):
    """The memory rebuilt from output samples (pin x and sinkage per sample), raised by the
    rule above (shoes `shoe` long) at each sample instead of after each step:
    out[j] = the nodes after sample idx[j] (idx sorted). Returns the nodes after the last
    sample."""
    rut = np.zeros(out.shape[1])
    j = 0
    for i in range(px.shape[0]):
        for b in range(px.shape[1]):
            if sink[i, b] > 0.0:
                raise_memory(px[i, b], sink[i, b], x0, dx, shoe, rut)
        while j < idx.shape[0] and idx[j] == i:
            out[j, :] = rut
            j += 1
    return rut


@njit(**INLINE)
def soil_shear(x, y, x0, y0, t, normal, par):
    """Shear force along the surface's unit tangent t on a pin at (x, y) that touched the
    soil at (x0, y0) (NaN: in this step; no shear yet), pressed with normal force `normal`."""
    if x0 != x0:
        return 0.0
    j = (x - x0) * t[0] + (y - y0) * t[1]
    limit = par[P_SOIL_COHESION] + normal * par[P_SOIL_TAN_PHI]
    f = limit * (1.0 - fm.exp(-abs(j) / par[P_SOIL_SHEAR_K]))
    return -f if j > 0.0 else f


@njit(**BORROW)
def remember_sinkage(m, w):
    """After an accepted step (the last evaluation was at its end), after the memory has been
    raised along the step (solvers/common/sinkage.py): the memory keeps the sinkage a pin has
    at the step's end (raise_memory); a pin that touched the soil in the step keeps where (its
    end position where the interpolant did not locate it), one that left it forgets."""
    if m.par[P_SOIL] == 0.0:
        return
    for b in range(w.sink.shape[0]):
        if w.sink[b] > 0.0:
            raise_memory(
                w.apos[b, 0], w.sink[b], m.par[P_RUT_X0], m.par[P_RUT_DX], m.par[P_LINK_LENGTH], m.rut
            )
            if m.touchdown[b, 0] != m.touchdown[b, 0]:
                m.touchdown[b, 0] = w.apos[b, 0]
                m.touchdown[b, 1] = w.apos[b, 1]
        else:
            m.touchdown[b, 0] = math.nan
            m.touchdown[b, 1] = math.nan
