"""The "lee" solver's compiled time loop: per step the procedure of the paper's section
4.3 (Fig. 7), on the absolute coordinates of model/dynamics/absolute.py.

1. Integrate Eq. (9) over the step with the RKN pair, lambda linear from lam0 (known)
   to lam1; iterate lam1 by Eq. (15) with the position error Eq. (12) at t + h until
   max |Phi| <= position_tol, re-integrating the step (contacts re-detected at every
   stage) at each iteration. Non-convergence rejects the step (h / 2).
2. Embedded error estimate; reject (and shrink h) or accept and pick the next h. A
   rejected step in which a contact starts or ends is retried to end just after it
   (solvers/common/events.py, on the step's ends in reduced coordinates), as in the reduced solver.
3. Velocity level: with the stage forces of 1 held, iterate lambda with Eq. (13) to
   max |Phi_q qd| <= position_tol / h; this sets qd(t + h) of the chassis and arms.
4. Acceleration level: with the forces at t + h, iterate lambda with Eq. (14) to
   <= position_tol / h^2; gives lambda(t + h) and qdd(t + h), and lambda starts the
   next step (it is that step's lam0; the first guess of its lam1 extrapolates it
   linearly from the last two steps).
A_n and alpha (lee_iter.py) are built from C at the configuration reached by an accepted
step and serve the three levels there and the position level of the next step; they are
rebuilt when the chassis pitch or an arm angle has moved by more than rebuild_angle
(scenario lee.matrix_update_angle; 0 = after every step) since the last build. C_1
depends on the configuration only through these angles; the update keeps the paper's
form and the convergence tests are unchanged, only C is up to that much out of date.
Output samples: quintic Hermite interpolation of (z, zd) (cubic for the contact work),
then forces and the acceleration level at the sample, so diag means what reduced_rhs
puts there. The chassis acceleration in diag (samples and peaks) and the joint forces come
from a copy of the multipliers iterated on to DIAG_ACC_TOL (below).

Every array the loop uses is allocated by the Python side (lee_run.py) and arrives bundled:
``lw`` (LeeWork, lee_work.py), ``lout`` (LeeOutputs), ``ls`` (LeeSettings), the rest as in
the reduced solver (solvers/rk/rk_loop.py). Scalars that live from step to step sit in
``lw.sc`` under the SC_* names.
"""

import math

from numba import njit

from ...model.core.indices import D_E_GRAVITY, D_STATUS, S_E0, Z_X
from ...model.core.indices_jit import z_pin
from ...model.core.jit import BORROW
from ...model.dynamics.absolute import (
    applied_forces,
    constraint_matrix,
    contact_power,
    finish_diag,
    from_reduced,
    joint_vectors,
    to_reduced,
)
from ...status import CONSTRAINT_ITERATION, NAN, SUCCESSFUL
from ..common.arrays import copy_2d, copy_into, set_row
from ..common.control import (
    FAC_MAX,
    after_acceptance,
    after_rejection,
    before_step,
    counted,
    finish_stats,
    loop_start,
)
from ..common.events import first_contact_switch
from ..common.hermite import hermite_second_order
from ..common.monitor import energy_balance, energy_residual, init_peaks, update_peaks
from .lee_iter import (
    acceleration_level,
    estimate_eps1,
    inf_norm,
)
from .lee_levels import (
    _build_matrices,
    _end_state,
    _itm,
    _maybe_rebuild,
    _position_level,
    _reported,
    _velocity_and_acceleration,
)
from .lee_stages import error_norm
from .lee_work import (
    L_EPS1,
    L_IT_OUT,
    L_RATIO_ACC,
    L_RATIO_POS,
    L_RATIO_VEL,
    L_REJ_CONSTRAINT,
    L_REJ_ERROR,
    SC_P_START,
    SC_W,
    X_ERR_ACC,
    X_ERR_POS,
    X_ERR_VEL,
    X_H,
    X_IT_ACC,
    X_IT_POS,
    X_IT_VEL,
    X_RATIO_ACC,
    X_RATIO_POS,
    X_RATIO_VEL,
    X_REJECTED,
    X_STEPS,
)


@njit(**BORROW)
def _start(y0, h, ls, minv, m, w, lw, out, lout):
    """t = 0: forces, eps-bar-1 by Eq. (20), A_n, then the acceleration level for
    lambda(0); the first sample and the energy references. Returns (status, e_ref, r_ref)."""
    z, zd, zdd = lw.z, lw.zd, lw.zdd
    nw = m.arms.shape[0]
    nbody = z_pin(nw)
    lstats = lout.lstats
    lstats[:] = 0.0
    lw.sc[SC_W] = from_reduced(y0, m.par, m.arms, z, zd)
    applied_forces(z, zd, m, w, lw.Fst[0], lw.fcs[0], lw.diags[0])
    copy_2d(lw.fws[0], w.fwheel)
    joint_vectors(z, m.par, m.arms, lw.geos[0])
    constraint_matrix(lw.geos[0], minv, lw.G)
    lstats[L_EPS1] = estimate_eps1(
        lw.Fst[0], lw.geos[0], zd, minv, lw.lam0, inf_norm(lw.G), ls.eps_iterations, nbody, zdd, lw.gam, lw.v
    )
    _build_matrices(z, lw.geos[0], ls, minv, lw, lstats)
    status = SUCCESSFUL
    it_a, err_a = acceleration_level(
        lw.Fst[0],
        lw.geos[0],
        zd,
        minv,
        lw.lam0,
        _itm(lw),
        ls.position_tol / (h * h),
        ls.max_iterations,
        (zdd, lw.gam, lw.v),
    )
    if it_a < 0:
        status = CONSTRAINT_ITERATION
    for k in range(nbody, z.shape[0]):
        zdd[k] = lw.Fst[0, k] * minv[k]
    set_row(lw.K, 0, zdd)
    lw.sc[SC_P_START] = contact_power(z, zd, m.ends, lw.fcs[0], lw.fws[0], nw)
    _reported(lw.Fst[0], lw.geos[0], zd, minv, lw.lam0, lw, lstats)
    diag = lw.diags[0]
    finish_diag(z, zd, lw.zdd_d, m.par, m.arms, lw.sc[SC_P_START], diag)
    e_ref = energy_balance(diag)
    r_ref = energy_residual(diag, lw.sc[SC_W])
    out.stats[S_E0] = e_ref - diag[D_E_GRAVITY]
    init_peaks(out.peaks)
    update_peaks(out.peaks, 0.0, diag, zd[Z_X], lw.sc[SC_W], e_ref, r_ref, False)
    to_reduced(z, zd, lw.sc[SC_W], nw, lw.yred)
    set_row(out.y, 0, lw.yred)
    set_row(out.diag, 0, diag)
    set_row(lout.lam, 0, lw.lam_d)  # the converged multipliers, as for diag
    lout.x[0, :] = 0.0
    lout.x[0, X_ERR_ACC] = err_a
    if diag[D_STATUS] != 0.0:
        status = int(diag[D_STATUS])
    return status, e_ref, r_ref


@njit(**BORROW)
def _locate_switch(h, tab, m, ev, lw, nw):
    """Step 2 on a rejection: the contact switch inside the step, on its ends in reduced
    coordinates (the last stage, c = 1, is the acceleration at t + h)."""
    ns = tab.c.shape[0]
    to_reduced(lw.z, lw.zd, 0.0, nw, lw.ev_y0)
    to_reduced(lw.zd, lw.zdd, 0.0, nw, lw.ev_f0)
    to_reduced(lw.Y, lw.zd_new, 0.0, nw, lw.ev_y1)
    to_reduced(lw.zd_new, lw.K[ns - 1], 0.0, nw, lw.ev_f1)
    return first_contact_switch(lw.ev_y0, lw.ev_f0, lw.ev_y1, lw.ev_f1, h, m, ev)


@njit(**BORROW)
def _count_step(h, errors, iterations, ptol, lw, lstats):
    """Figures of an accepted step: into the run totals and the per-sample accumulator."""
    err_p, err_v, err_a = errors
    it_p, it_v, it_a = iterations
    acc_x = lw.acc_x
    rp = err_p / ptol
    rv = err_v * h / ptol
    ra = err_a * h * h / ptol
    lstats[L_RATIO_POS] = max(lstats[L_RATIO_POS], rp)
    lstats[L_RATIO_VEL] = max(lstats[L_RATIO_VEL], rv)
    lstats[L_RATIO_ACC] = max(lstats[L_RATIO_ACC], ra)
    acc_x[X_STEPS] += 1
    acc_x[X_IT_POS] += it_p
    acc_x[X_IT_VEL] += it_v
    acc_x[X_IT_ACC] += it_a
    acc_x[X_ERR_POS] = max(acc_x[X_ERR_POS], err_p)
    acc_x[X_ERR_VEL] = max(acc_x[X_ERR_VEL], err_v)
    acc_x[X_ERR_ACC] = max(acc_x[X_ERR_ACC], err_a)
    acc_x[X_RATIO_POS] = max(acc_x[X_RATIO_POS], rp)
    acc_x[X_RATIO_VEL] = max(acc_x[X_RATIO_VEL], rv)
    acc_x[X_RATIO_ACC] = max(acc_x[X_RATIO_ACC], ra)
    acc_x[X_H] = h


@njit(**BORROW)
def _samples(t, h, n_out, ctl, ls, minv, m, w, lw, out, lout):
    """Output samples in (t, t + h]: Hermite state, forces, the acceleration level with
    lambda interpolated over the step. Returns (new sample count, evaluations)."""
    nz = lw.z.shape[0]
    nw = m.arms.shape[0]
    yo, Fo, fco, geo_o, lam_o = lw.yo, lw.Fo, lw.fco, lw.geo_o, lw.lam_o
    lstats = lout.lstats
    n_eval = 0
    while n_out < out.y.shape[0] and n_out * ctl.dt_out <= (t + h) * (1.0 + 1e-12):
        theta = min(1.0, (n_out * ctl.dt_out - t) / h)
        hermite_second_order(lw.ya, lw.fa, lw.yb, lw.fb, h, theta, nz, yo)
        zo = yo[:nz]
        zdo = yo[nz:2 * nz]
        applied_forces(zo, zdo, m, w, Fo, fco, out.diag[n_out])
        n_eval += 1
        joint_vectors(zo, m.par, m.arms, geo_o)
        for r in range(lam_o.shape[0]):
            lam_o[r] = lw.lam0[r] + theta * (lw.lam_s[r] - lw.lam0[r])
        it_o, _ = acceleration_level(Fo, geo_o, zdo, minv, lam_o, _itm(lw), ls.position_tol / (h * h),
                                     ls.max_iterations, (lw.zdd_o, lw.gam, lw.v))
        lstats[L_IT_OUT] += max(it_o, 0)
        _reported(Fo, geo_o, zdo, minv, lam_o, lw, lstats)
        finish_diag(zo, zdo, lw.zdd_d, m.par, m.arms, contact_power(zo, zdo, m.ends, fco, w.fwheel, nw),
                    out.diag[n_out])
        to_reduced(zo, zdo, yo[2 * nz], nw, lw.yred)
        set_row(out.y, n_out, lw.yred)
        set_row(lout.lam, n_out, lw.lam_d)
        set_row(lout.x, n_out, lw.acc_x)
        lw.acc_x[:] = 0.0
        lw.acc_x[X_H] = h
        n_out += 1
    return n_out, n_eval


@njit(**BORROW)
def _shift(w_new, p_end, lw):
    """The end of this step is the start of the next."""
    ns = lw.K.shape[0]
    copy_into(lw.z, 0, lw.Y)
    copy_into(lw.zd, 0, lw.zd_new)
    copy_into(lw.zdd, 0, lw.zdd_new)
    lw.sc[SC_W] = w_new
    lw.sc[SC_P_START] = p_end
    set_row(lw.K, 0, lw.zdd_new)
    set_row(lw.Fst, 0, lw.Fst[ns - 1])
    copy_2d(lw.fcs[0], lw.fcs[ns - 1])
    copy_2d(lw.fws[0], lw.fws[ns - 1])
    copy_2d(lw.geos[0], lw.geos[ns - 1])
    copy_into(lw.lam0, 0, lw.lam_s)


@njit(**BORROW)
def _accepted_status(lw):
    status = SUCCESSFUL
    for k in range(lw.z.shape[0]):
        if not (math.isfinite(lw.Y[k]) and math.isfinite(lw.zd_new[k])):
            status = NAN
    diag = lw.diags[lw.diags.shape[0] - 1]
    if diag[D_STATUS] != 0.0:
        status = int(diag[D_STATUS])
    return status


@njit(**BORROW)
def integrate_lee(y0, ctl, tab, ls, minv, m, w, ev, lw, out, lout):
    """The paper's procedure (module docstring) from the reduced state y0 to ctl.t_end."""
    nw = m.arms.shape[0]
    lstats = lout.lstats
    h = min(ctl.h0, ctl.h_max)
    status, e_ref, r_ref = _start(y0, h, ls, minv, m, w, lw, out, lout)
    h_prev = 0.0
    n_rhs = n_out = 1
    t, steps, rejected, h_lo, h_hi, fac_max, at_switch = loop_start()
    while status == SUCCESSFUL and t < ctl.t_end * (1.0 - 1e-14):
        status, h = before_step(t, h, ctl.t_end, steps, rejected, ctl.max_steps, ctl.h_min)
        if status != SUCCESSFUL:
            break
        ok, err_p, it_p, n_eval = _position_level(h, h_prev, tab, ls, minv, m, w, lw, lstats)   # 1
        n_rhs += n_eval
        if not ok:
            rejected += 1
            lstats[L_REJ_CONSTRAINT] += 1
            lw.acc_x[X_REJECTED] += 1
            at_switch = False
            h *= 0.5
            fac_max = 1.0
            continue
        err = error_norm(lw.z, lw.zd, lw.Y, lw.zd_new, lw.K, tab.eb, tab.ebp, h, ctl.rtol, ctl.atol)   # 2
        if not (err <= 1.0):
            rejected += 1
            lstats[L_REJ_ERROR] += 1
            lw.acc_x[X_REJECTED] += 1
            th = _locate_switch(h, tab, m, ev, lw, nw) if (err == err and err > 0.0) else 2.0
            h, at_switch = after_rejection(h, err, tab.expo, th, ctl.h_min)
            fac_max = 1.0
            continue
        t_new = t + h
        steps, h_lo, h_hi = counted(h, steps, h_lo, h_hi)
        _maybe_rebuild(ls, minv, lw, lstats)
        it_v, err_v, it_a, err_a = _velocity_and_acceleration(h, tab, ls, minv, lw, lstats)   # 3, 4
        if it_v < 0 or it_a < 0:
            status = CONSTRAINT_ITERATION
        w_new, p_end = _end_state(h, tab, minv, m, lw, lstats)
        accepted = _accepted_status(lw)
        if accepted != SUCCESSFUL:
            status = accepted
        update_peaks(out.peaks, t_new, lw.diags[lw.diags.shape[0] - 1], lw.zd_new[Z_X], w_new, e_ref, r_ref,
                     at_switch)
        at_switch = False
        _count_step(h, (err_p, err_v, err_a), (it_p, it_v, it_a), ls.position_tol, lw, lstats)
        n_new, n_eval = _samples(t, h, n_out, ctl, ls, minv, m, w, lw, out, lout)
        n_rhs += n_eval
        n_out = n_new
        t = t_new
        _shift(w_new, p_end, lw)
        h_prev = h
        h = after_acceptance(h, err, tab.expo, fac_max, ctl.h_max)
        fac_max = FAC_MAX
    finish_stats(out.stats, status, t, steps, rejected, n_rhs, n_out, h_lo, h_hi)
