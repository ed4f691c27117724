"""Soft soil under the track's pins, compiled (the soil values and closed forms: soil.py).

Bekker's pressure-sinkage law p = (k_c / b + k_phi) z^n while the soil is loaded beyond the
deepest sinkage z_m it has seen at that place; below z_m it unloads and reloads elastically,
p = p(z_m) - K_e (z_m - z) (not above the first-loading curve), down to zero at the plastic
sinkage z_m - p(z_m) / K_e (the rut).
z_m is the soil's memory, one value per cell along x (ModelArrays.rut): raised only after an
accepted step (remember_sinkage), so a rejected step leaves no trace, and the pressure is
continuous where it is raised (at z = z_m both branches agree).

Shear by Janosi-Hanamoto, tau = (c + p tan phi)(1 - exp(-j / K)), on the pin's area A: the
shear displacement j is the pin's displacement along the surface since it touched the soil
(ModelArrays.touchdown, set after the accepted step in which it touched down, cleared when it
leaves), so a pin that slips by j shears the soil by j; it replaces Coulomb friction on soil."""

import math

from numba import njit

from .jit import BORROW, INLINE, SCALAR
from .layout import (P_RUT_DX, P_RUT_X0, P_SOIL, P_SOIL_COHESION, P_SOIL_K, P_SOIL_KE, P_SOIL_N, P_SOIL_SHEAR_K,
                     P_SOIL_TAN_PHI)


SURFACE_DEPTH = 1e-3     # m: for n < 1, Bekker's curve runs straight to the surface from here


@njit(**SCALAR)
def first_loading(z, n, k):
    """Bekker's p = k z^n; for n < 1 its slope is infinite at the surface, which no
    equilibrium search or step-size control can follow: straight to zero from SURFACE_DEPTH."""
    if n < 1.0 and z < SURFACE_DEPTH:
        return k * SURFACE_DEPTH ** n * (z / SURFACE_DEPTH)
    return k * z ** n


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
def rut_cell(x, par, rut):
    """The memory cell under x, or -1 beyond the cells."""
    c = int(math.floor((x - par[P_RUT_X0]) / par[P_RUT_DX]))
    return c if 0 <= c < rut.shape[0] else -1


@njit(**INLINE)
def pin_on_soil(x, z, par, rut):
    """Pressure under a pin at x sunk by z into the soil."""
    c = rut_cell(x, par, rut)
    z_max = rut[c] if c >= 0 else 0.0
    return soil_pressure(z, z_max, par[P_SOIL_N], par[P_SOIL_K], par[P_SOIL_KE])


@njit(**INLINE)
def soil_shear(x, y, x0, y0, t, normal, par):
    """Shear force along the surface's unit tangent t on a pin at (x, y) that touched the
    soil at (x0, y0) (NaN: in this step; no shear yet), pressed with normal force `normal`."""
    if x0 != x0:
        return 0.0
    j = (x - x0) * t[0] + (y - y0) * t[1]
    limit = par[P_SOIL_COHESION] + normal * par[P_SOIL_TAN_PHI]
    f = limit * (1.0 - math.exp(-abs(j) / par[P_SOIL_SHEAR_K]))
    return -f if j > 0.0 else f


@njit(**BORROW)
def remember_sinkage(m, w):
    """After an accepted step (the last evaluation was at its end): each cell keeps the
    deepest sinkage a pin reached in it; a pin that touched the soil in the step keeps
    where, one that left it forgets."""
    if m.par[P_SOIL] == 0.0:
        return
    for b in range(w.sink.shape[0]):
        if w.sink[b] > 0.0:
            c = rut_cell(w.apos[b, 0], m.par, m.rut)
            if c >= 0 and w.sink[b] > m.rut[c]:
                m.rut[c] = w.sink[b]
            if m.touchdown[b, 0] != m.touchdown[b, 0]:
                m.touchdown[b, 0] = w.apos[b, 0]
                m.touchdown[b, 1] = w.apos[b, 1]
        else:
            m.touchdown[b, 0] = math.nan
            m.touchdown[b, 1] = math.nan
