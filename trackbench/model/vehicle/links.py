"""Link tension (Eq. 8) and the links' axial dashpots: each link's spring between its two
pins."""

import numpy as np
from numba import njit

from ..contact.gaps import link_frames
from ..core.indices import (
    D_DISSIPATION,
    D_E_TENSION,
    D_MAX_TENSION,
    D_MIN_TENSION,
    D_POWER,
    LK_LENGTH,
    LK_TX,
    LK_TY,
    P_LINK_DAMPING,
    P_LINK_LENGTH,
    P_LINK_STIFFNESS,
)
from ..core.jit import INLINE


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
    if lk.shape[0] == apos.shape[0]:  # closed loop: one more row, link 0 again, for pin n_links's cap
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
    diag[D_POWER] -= dissipation  # the dashpots' work on the pins
