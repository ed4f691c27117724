"""One Runge-Kutta-Nystrom pass over a step of the "lee" solver, its error norm and the
contact-work quadrature (compiled helpers of lee_loop.py).

The multipliers vary linearly over the step, lambda(t + tau) = lam0 + (tau / h)
(lam1 - lam0): lam0 is the acceleration-level value at t (step 4 of the previous
step), lam1 the unknown end value that step 1 iterates. This is the reading under
which the paper's C matrices are the exact sensitivities of the constraint errors to
lam1: d q(t+h) / d lam1 = -h^2 sum_j b_j c_j M^-1 Phi_q^T = -h^2/6 M^-1 Phi_q^T
(Eq. 17) and d qd(t+h) / d lam1 = -h sum_j bp_j c_j M^-1 Phi_q^T = -h/2 M^-1 Phi_q^T
(Eq. 18); with lambda constant over the step they would be h^2/2 and h and the
iteration with alpha from Eq. (16) would diverge.
"""

import math

from numba import njit

from ...model.core.jit import BORROW
from ...model.dynamics.absolute import add_phi_qt, applied_forces, contact_power, joint_vectors
from ..common.arrays import copy_2d
from ..common.hermite import hermite_second_order


@njit(**BORROW)
def rkn_pass(h, tab, minv, m, w, lw):
    """Stages 2..s of the RKN pair from (lw.z, lw.zd) with lambda linear from lw.lam0 to
    lw.lam1 (stage 1, K[0], is the acceleration at t). Contacts are re-detected at every
    stage. On return lw.Y = z(t + h) (last stage, first same as last), lw.zd_new =
    zd(t + h); per stage j the applied forces Fst[j], contact forces fcs[j] (pins) and
    fws[j] (wheels), joint geometry geos[j] and the track_loads diagnostics diags[j]."""
    A, bp, c = tab.A, tab.bp, tab.c
    z, zd, K, Y, zd_new, lam0, lam1, lam_s = lw.z, lw.zd, lw.K, lw.Y, lw.zd_new, lw.lam0, lw.lam1, lw.lam_s
    Fst, fcs, fws, geos, diags = lw.Fst, lw.fcs, lw.fws, lw.geos, lw.diags
    par, arms = m.par, m.arms
    ns = c.shape[0]
    nz = z.shape[0]
    for i in range(1, ns):
        for k in range(nz):
            acc = 0.0
            for j in range(i):
                acc += A[i, j] * K[j, k]
            Y[k] = z[k] + c[i] * h * zd[k] + h * h * acc
        applied_forces(Y, zd, m, w, Fst[i], fcs[i], diags[i])
        copy_2d(fws[i], w.fwheel)
        joint_vectors(Y, par, arms, geos[i])
        for r in range(lam_s.shape[0]):
            lam_s[r] = lam0[r] + c[i] * (lam1[r] - lam0[r])
        Ki = K[i]
        for k in range(nz):
            Ki[k] = Fst[i, k]
        add_phi_qt(geos[i], lam_s, -1.0, Ki)
        for k in range(nz):
            Ki[k] *= minv[k]
    for k in range(nz):
        acc = 0.0
        for j in range(ns):
            acc += bp[j] * K[j, k]
        zd_new[k] = zd[k] + h * acc


@njit(**BORROW)
def error_norm(z, zd, Y, zd_new, K, eb, ebp, h, rtol, atol):
    """RMS over positions and velocities of the embedded estimate (h^2 sum eb k, h sum ebp k)
    scaled by atol + rtol max(|old|, |new|)."""
    nz = z.shape[0]
    ns = eb.shape[0]
    s = 0.0
    for k in range(nz):
        ep = 0.0
        ev = 0.0
        for j in range(ns):
            ep += eb[j] * K[j, k]
            ev += ebp[j] * K[j, k]
        sc = atol + rtol * max(abs(z[k]), abs(Y[k]))
        s += (h * h * ep / sc) ** 2
        sc = atol + rtol * max(abs(zd[k]), abs(zd_new[k]))
        s += (h * ev / sc) ** 2
    return math.sqrt(s / (2 * nz))


@njit(**BORROW)
def work_increment(h, tab, ends, nw, p_start, p_end, lw):
    """Contact work over the step: W' = P(t) = contact force . velocity, integrated by the
    pair's velocity weights, h sum_j bp_j P_j (exact for polynomials of degree 5 in time):
    P_j pairs the contact forces found at stage j (the forces the step used) with the
    velocity at t + c_j h from the quintic Hermite interpolant of the accepted step
    (lw.ya, lw.fa: (z, zd, -), (zd, zdd, -) at t; lw.yb, lw.fb at t + h). P_1, P_s are exact."""
    ya, fa, yb, fb, yo, fcs, fws = lw.ya, lw.fa, lw.yb, lw.fb, lw.yo, lw.fcs, lw.fws
    bp, c = tab.bp, tab.c
    nz = (ya.shape[0] - 1) // 2
    ns = c.shape[0]
    acc = bp[0] * p_start + bp[ns - 1] * p_end
    for j in range(1, ns - 1):
        if bp[j] != 0.0:
            hermite_second_order(ya, fa, yb, fb, h, c[j], nz, yo)
            acc += bp[j] * contact_power(yo[:nz], yo[nz:2 * nz], ends, fcs[j], fws[j], nw)
    return h * acc
