"""The lee solver's work inside one step: the position level (Eq. 12), the velocity and
acceleration levels (Eqs. 13-14) and the end state, with the rebuilds of Lee's matrices."""

import math

import numpy as np
from numba import njit

from ...model.core.indices import Z_PITCH, ZA_BETA
from ...model.core.indices_jit import z_arm, z_pin
from ...model.core.jit import BORROW
from ...model.dynamics.absolute import constraint_matrix, contact_power, finish_diag, phi
from ..common.arrays import copy_into
from .lee_iter import accel_matrix, acceleration_level, max_abs, update, velocity_level
from .lee_stages import rkn_pass, work_increment
from .lee_work import (
    L_BUILDS,
    L_DIAG_UNCONVERGED,
    L_EPS1,
    L_IT_ACC,
    L_IT_DIAG,
    L_IT_POS,
    L_IT_VEL,
    L_PASSES,
    SC_ALPHA,
    SC_GN,
    SC_P_START,
    SC_W,
)

# diag's chassis acceleration and the joint forces (output samples, peaks of every accepted step) are
# those of the
# state with the multipliers iterated on from the level-4 value to this constraint-acceleration error
# (m/s^2): 1e-9 / h^2 leaves up to ~20 m/s^2 at h ~ 7e-6 s (up to 0.6 m/s^2 on the chassis
# before 0.25 s, 4.5 at worst).
# A copy of lambda is used, so lambda(t + h), qdd(t + h) and the trajectory stay the paper's.
DIAG_ACC_TOL = 1e-10
DIAG_MAX_IT = 1000


@njit(**BORROW)
def _itm(lw):
    return lw.An, lw.sc[SC_ALPHA], lw.sc[SC_GN]


@njit(**BORROW)
def _reported(F, geo, zd, minv, lam, lw, lstats):
    """The acceleration level iterated on a copy (lw.lam_d) to DIAG_ACC_TOL: what diag
    and the joint forces report. Counts the iterations (or one that did not converge)."""
    copy_into(lw.lam_d, 0, lam)
    it, _ = acceleration_level(
        F, geo, zd, minv, lw.lam_d, _itm(lw), DIAG_ACC_TOL, DIAG_MAX_IT, (lw.zdd_d, lw.gam, lw.v)
    )
    if it < 0:
        lstats[L_DIAG_UNCONVERGED] += 1
    else:
        lstats[L_IT_DIAG] += it


@njit(**BORROW)
def _build_matrices(z, geo, ls, minv, lw, lstats):
    """A_n and alpha (A1-A6) from C at configuration z (joint vectors geo); remembers
    the angles they were built at."""
    constraint_matrix(geo, minv, lw.G)
    alpha, gn = accel_matrix(lw.G, ls.accel_order, lstats[L_EPS1], lw.An, lw.Cn, lw.T, lw.tmp)
    lw.sc[SC_ALPHA] = alpha
    lw.sc[SC_GN] = gn
    lstats[L_BUILDS] += 1
    lw.ang_ref[0] = z[Z_PITCH]
    for i in range(geo.shape[0]):
        lw.ang_ref[1 + i] = z[z_arm(i) + ZA_BETA]


@njit(**BORROW)
def _position_level(h, h_prev, tab, ls, minv, m, w, lw, lstats):
    """Step 1: re-integrate the step while iterating lam1 with Eq. (12).
    Returns (converged, final max |Phi|, iterations, stage evaluations)."""
    lam0, lam1, lam_prev, v = lw.lam0, lw.lam1, lw.lam_prev, lw.v
    ns = tab.c.shape[0]
    for r in range(lam1.shape[0]):
        lam1[r] = lam0[r]
        if h_prev > 0.0:
            lam1[r] += h / h_prev * (lam0[r] - lam_prev[r])
    scale = lw.sc[SC_ALPHA] / (h * h / 6.0 * lw.sc[SC_GN])
    err_p = np.inf
    err_first = np.inf
    n_eval = 0
    updates = 0
    ok = False
    for it in range(ls.max_iterations + 1):
        rkn_pass(h, tab, minv, m, w, lw)
        n_eval += ns - 1
        lstats[L_PASSES] += 1
        phi(lw.Y, lw.geos[ns - 1], v)
        for r in range(v.shape[0]):
            v[r] = -v[r]  # Eq. (12)
        err_p = max_abs(v)
        if err_p <= ls.position_tol:
            ok = True
            break
        if it == 0:
            err_first = err_p
        if not math.isfinite(err_p) or err_p > 1e3 * err_first:
            break
        update(lam1, lw.An, v, scale)
        updates += 1
    lstats[L_IT_POS] += updates
    return ok, err_p, updates, n_eval


@njit(**BORROW)
def _maybe_rebuild(ls, minv, lw, lstats):
    """A_n again where the pitch or an arm angle moved more than rebuild_angle."""
    ns = lw.geos.shape[0]
    moved = abs(lw.Y[Z_PITCH] - lw.ang_ref[0])
    for i in range(lw.geos.shape[1]):
        moved = max(moved, abs(lw.Y[z_arm(i) + ZA_BETA] - lw.ang_ref[1 + i]))
    if moved > ls.matrix_update_angle:
        _build_matrices(lw.Y, lw.geos[ns - 1], ls, minv, lw, lstats)


@njit(**BORROW)
def _velocity_and_acceleration(h, tab, ls, minv, lw, lstats):
    """Steps 3 and 4: qd(t + h) of the bodies, then lambda(t + h) and qdd(t + h).
    Returns (velocity iterations, error, acceleration iterations, error)."""
    ns = tab.c.shape[0]
    lam_s, geo = lw.lam_s, lw.geos[ns - 1]
    for r in range(lam_s.shape[0]):
        lam_s[r] = lw.lam1[r]
    it_v, err_v = velocity_level(
        lw.zd_new,
        geo,
        lw.geos,
        tab.bp,
        tab.c,
        h,
        minv,
        lam_s,
        _itm(lw),
        ls.position_tol / h,
        ls.max_iterations,
        (lw.dl, lw.u, lw.v),
    )
    for r in range(lam_s.shape[0]):
        lw.lam_prev[r] = lw.lam0[r]
        lam_s[r] = lw.lam1[r]
    it_a, err_a = acceleration_level(
        lw.Fst[ns - 1],
        geo,
        lw.zd_new,
        minv,
        lam_s,
        _itm(lw),
        ls.position_tol / (h * h),
        ls.max_iterations,
        (lw.zdd_new, lw.gam, lw.v),
    )
    lstats[L_IT_VEL] += max(it_v, 0)
    lstats[L_IT_ACC] += max(it_a, 0)
    for k in range(z_pin(geo.shape[0]), lw.z.shape[0]):
        lw.zdd_new[k] = lw.Fst[ns - 1, k] * minv[k]
    return it_v, err_v, it_a, err_a


@njit(**BORROW)
def _end_state(h, tab, minv, m, lw, lstats):
    """The contact work over the step and diag at t + h (the reported multipliers).
    Returns (W(t + h), p_end)."""
    ns = tab.c.shape[0]
    nz = lw.z.shape[0]
    nw = m.arms.shape[0]
    p_end = contact_power(lw.Y, lw.zd_new, m.ends, lw.fcs[ns - 1], lw.fws[ns - 1], nw)
    ya, fa, yb, fb = lw.ya, lw.fa, lw.yb, lw.fb
    copy_into(ya, 0, lw.z)
    copy_into(ya, nz, lw.zd)
    ya[2 * nz] = lw.sc[SC_W]
    copy_into(fa, 0, lw.zd)
    copy_into(fa, nz, lw.zdd)
    fa[2 * nz] = lw.sc[SC_P_START]
    copy_into(yb, 0, lw.Y)
    copy_into(yb, nz, lw.zd_new)
    copy_into(fb, 0, lw.zd_new)
    copy_into(fb, nz, lw.zdd_new)
    fb[2 * nz] = p_end
    w_new = lw.sc[SC_W] + work_increment(h, tab, m.ends, nw, lw.sc[SC_P_START], p_end, lw)
    yb[2 * nz] = w_new
    _reported(lw.Fst[ns - 1], lw.geos[ns - 1], lw.zd_new, minv, lw.lam_s, lw, lstats)
    finish_diag(lw.Y, lw.zd_new, lw.zdd_d, m.par, m.arms, p_end, lw.diags[ns - 1])
    return w_new, p_end
