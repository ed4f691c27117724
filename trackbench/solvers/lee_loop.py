"""The "lee" solver's compiled time loop: per step the procedure of the paper's section
4.3 (Fig. 7), on the absolute coordinates of model/absolute.py.

1. Integrate Eq. (9) over the step with the RKN pair, lambda linear from lam0 (known)
   to lam1; iterate lam1 by Eq. (15) with the position error Eq. (12) at t + h until
   max |Phi| <= position_tol, re-integrating the step (contacts re-detected at every
   stage) at each iteration. Non-convergence rejects the step (h / 2).
2. Embedded error estimate; reject (and shrink h) or accept and pick the next h. A
   rejected step in which a contact starts or ends is retried to end just after it
   (solvers/events.py, on the step's ends in reduced coordinates), as in the reduced solver.
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
"""

import math

import numpy as np
from numba import njit

from ..model.absolute import (applied_forces, constraint_matrix, contact_power, finish_diag, from_reduced,
                              joint_vectors, phi, to_reduced)
from ..model.layout import (D_E_GRAVITY, D_STATUS, S_E0, S_H_MAX, S_H_MIN, S_N_OUT, S_REJECTED, S_RHS,
                            S_STATUS, S_STEPS, S_T_FINAL)
from ..status import CONSTRAINT_ITERATION, NAN, SUCCESSFUL
from .arrays import copy_2d, copy_into, set_row
from .control import FAC_MAX, after_acceptance, after_rejection, before_step
from .events import first_contact_switch
from .lee_iter import accel_matrix, acceleration_level, estimate_eps1, inf_norm, max_abs, update, velocity_level
from .lee_stages import error_norm, rkn_pass, work_increment
from .monitor import energy_balance, energy_residual, hermite_second_order, init_peaks, update_peaks

# diag's chassis acceleration and the joint forces (output samples, peaks of every accepted step) are those of the
# state with the multipliers iterated on from the level-4 value to this constraint-acceleration error
# (m/s^2): 1e-9 / h^2 leaves up to ~20 m/s^2 at h ~ 7e-6 s (up to 0.6 m/s^2 on the chassis
# before 0.25 s, 4.5 at worst).
# A copy of lambda is used, so lambda(t + h), qdd(t + h) and the trajectory stay the paper's.
DIAG_ACC_TOL = 1e-10
DIAG_MAX_IT = 1000

# out_x columns: per output sample, over the accepted steps since the previous sample
X_STEPS, X_REJECTED, X_IT_POS, X_IT_VEL, X_IT_ACC, X_ERR_POS, X_ERR_VEL, X_ERR_ACC, \
    X_RATIO_POS, X_RATIO_VEL, X_RATIO_ACC, X_H = range(12)
N_X = 12
# lstats: run totals
L_IT_POS, L_IT_VEL, L_IT_ACC, L_PASSES, L_REJ_ERROR, L_REJ_CONSTRAINT, L_EPS1, \
    L_RATIO_POS, L_RATIO_VEL, L_RATIO_ACC, L_IT_OUT, L_BUILDS, L_IT_DIAG, L_DIAG_UNCONVERGED = range(14)
N_L = 14


@njit(cache=True, error_model="numpy")
def _count_diag(it, lstats):
    """Bookkeeping of the DIAG_ACC_TOL iterations (it < 0: not converged in DIAG_MAX_IT)."""
    if it < 0:
        lstats[L_DIAG_UNCONVERGED] += 1
    else:
        lstats[L_IT_DIAG] += it


@njit(cache=True, error_model="numpy")
def integrate_lee(y0, t_end, dt_out, A, b, bp, c, eb, ebp, expo, rtol, atol, h0, h_max, h_min, max_steps,
                  n_acc, n_eps, ptol, max_it, rebuild_angle, minv, par, arms, ends, seg, corners, nbr, ref, work,
                  out_y, out_d, out_x, out_lam, peaks, stats, lstats):
    nw = arms.shape[0]
    nbody = 3 * (1 + nw)
    nz = minv.shape[0]
    ns = c.shape[0]
    nl = 2 * nw
    nd = out_d.shape[1]
    n_pins = work[0].shape[0]
    z = np.empty(nz)
    zd = np.empty(nz)
    zdd = np.empty(nz)
    Y = np.empty(nz)
    zd_new = np.empty(nz)
    zdd_new = np.empty(nz)
    u = np.empty(nz)
    K = np.zeros((ns, nz))
    Fst = np.zeros((ns, nz))
    fcs = np.zeros((ns, n_pins, 2))
    fws = np.zeros((ns, nw, 2))
    geos = np.zeros((ns, nw, 4))
    diags = np.zeros((ns, nd))
    lam0 = np.zeros(nl)
    lam1 = np.zeros(nl)
    lam_prev = np.zeros(nl)
    lam_s = np.zeros(nl)
    lam_o = np.zeros(nl)
    dl = np.zeros(nl)
    v = np.zeros(nl)
    gam = np.zeros(nl)
    G = np.zeros((nl, nl))
    An = np.zeros((nl, nl))
    Cn = np.zeros((nl, nl))
    T = np.zeros((nl, nl))
    tmp = np.zeros((nl, nl))
    ya = np.zeros(2 * nz + 1)
    fa = np.zeros(2 * nz + 1)
    yb = np.zeros(2 * nz + 1)
    fb = np.zeros(2 * nz + 1)
    yo = np.zeros(2 * nz + 1)
    yred = np.zeros(y0.shape[0])
    # scratch of the event location (reduced-coordinate views of a rejected step's ends)
    ev_y0 = np.zeros(y0.shape[0])
    ev_f0 = np.zeros(y0.shape[0])
    ev_y1 = np.zeros(y0.shape[0])
    ev_f1 = np.zeros(y0.shape[0])
    ev_pins0 = np.empty((n_pins, 2))
    ev_pins1 = np.empty((n_pins, 2))
    ev_wheels0 = np.empty((nw, 2))
    ev_wheels1 = np.empty((nw, 2))
    Fo = np.zeros(nz)
    fco = np.zeros((n_pins, 2))
    geo_o = np.zeros((nw, 4))
    zdd_o = np.zeros(nz)
    acc_x = np.zeros(N_X)
    lam_d = np.zeros(nl)
    zdd_d = np.zeros(nz)
    ang_ref = np.zeros(1 + nw)    # chassis pitch and arm angles where A_n was last built
    lstats[:] = 0.0
    status = SUCCESSFUL
    n_rhs = 0

    # t = 0: forces, eps-bar-1 by Eq. (20), then the acceleration level for lambda(0)
    W = from_reduced(y0, par, arms, z, zd)
    applied_forces(z, zd, par, arms, ends, seg, corners, nbr, ref, work, Fst[0], fcs[0], diags[0])
    n_rhs += 1
    copy_2d(fws[0], work[3])
    joint_vectors(z, par, arms, geos[0])
    constraint_matrix(geos[0], minv, G)
    eps1 = estimate_eps1(Fst[0], geos[0], zd, minv, lam0, inf_norm(G), n_eps, nbody, zdd, gam, v)
    lstats[L_EPS1] = eps1
    alpha, gn = accel_matrix(G, n_acc, eps1, An, Cn, T, tmp)
    lstats[L_BUILDS] += 1
    ang_ref[0] = z[2]
    for i in range(nw):
        ang_ref[1 + i] = z[5 + 3 * i]
    h = min(h0, h_max)
    it_a, err_a = acceleration_level(Fst[0], geos[0], zd, minv, lam0, An, alpha, gn, ptol / (h * h), max_it,
                                     nbody, zdd, gam, v)
    if it_a < 0:
        status = CONSTRAINT_ITERATION
    for k in range(nbody, nz):
        zdd[k] = Fst[0, k] * minv[k]
    set_row(K, 0, zdd)
    p_start = contact_power(z, zd, ends, fcs[0], fws[0], nw)
    copy_into(lam_d, 0, lam0)
    it_d, _ = acceleration_level(Fst[0], geos[0], zd, minv, lam_d, An, alpha, gn, DIAG_ACC_TOL, DIAG_MAX_IT, nbody,
                                 zdd_d, gam, v)
    _count_diag(it_d, lstats)
    finish_diag(z, zd, zdd_d, par, arms, p_start, diags[0])
    e_ref = energy_balance(diags[0])
    r_ref = energy_residual(diags[0], W)
    stats[S_E0] = e_ref - diags[0, D_E_GRAVITY]
    init_peaks(peaks)
    update_peaks(peaks, 0.0, diags[0], zd[0], W, e_ref, r_ref, False)
    to_reduced(z, zd, W, nw, yred)
    set_row(out_y, 0, yred)
    set_row(out_d, 0, diags[0])
    set_row(out_lam, 0, lam_d)  # the converged multipliers, as for diag
    out_x[0, :] = 0.0
    out_x[0, X_ERR_ACC] = err_a
    n_out = 1
    n_out_max = out_y.shape[0]
    if diags[0, D_STATUS] != 0.0:
        status = int(diags[0, D_STATUS])

    t = 0.0
    h_prev = 0.0
    steps = 0
    rejected = 0
    h_lo = np.inf
    h_hi = 0.0
    fac_max = FAC_MAX
    at_switch = False  # the step being tried ends just after a located contact switch
    while status == SUCCESSFUL and t < t_end * (1.0 - 1e-14):
        status, h = before_step(t, h, t_end, steps, rejected, max_steps, h_min)
        if status != SUCCESSFUL:
            break
        # ---- 1: position level, re-integrating the step at each iteration
        for m in range(nl):
            lam1[m] = lam0[m]
            if h_prev > 0.0:
                lam1[m] += h / h_prev * (lam0[m] - lam_prev[m])
        scale = alpha / (h * h / 6.0 * gn)
        ok = False
        err_p = np.inf
        err_first = np.inf
        it_p = 0
        for it in range(max_it + 1):
            rkn_pass(z, zd, K, h, lam0, lam1, A, bp, c, minv, par, arms, ends, seg, corners, nbr, ref, work,
                     Fst, fcs, fws, geos, diags, lam_s, Y, zd_new)
            n_rhs += ns - 1
            lstats[L_PASSES] += 1
            phi(Y, geos[ns - 1], v)
            for m in range(nl):
                v[m] = -v[m]       # Eq. (12)
            err_p = max_abs(v)
            if err_p <= ptol:
                ok = True
                break
            if it == 0:
                err_first = err_p
            if not math.isfinite(err_p) or err_p > 1e3 * err_first:
                break
            update(lam1, An, v, scale)
            it_p += 1
        lstats[L_IT_POS] += it_p
        if not ok:
            rejected += 1
            lstats[L_REJ_CONSTRAINT] += 1
            acc_x[X_REJECTED] += 1
            at_switch = False
            h *= 0.5
            fac_max = 1.0
            continue
        # ---- 2: error estimate, accept or reject
        err = error_norm(z, zd, Y, zd_new, K, eb, ebp, h, rtol, atol)
        if not (err <= 1.0):
            rejected += 1
            lstats[L_REJ_ERROR] += 1
            acc_x[X_REJECTED] += 1
            th = 2.0
            if err == err and err > 0.0:
                # a contact starting or ending inside the step: end the retry just after it
                # (solvers/events.py, on the step's ends in reduced coordinates; the last
                # stage, c = 1, is the acceleration at t + h)
                to_reduced(z, zd, 0.0, nw, ev_y0)
                to_reduced(zd, zdd, 0.0, nw, ev_f0)
                to_reduced(Y, zd_new, 0.0, nw, ev_y1)
                to_reduced(zd_new, K[ns - 1], 0.0, nw, ev_f1)
                th = first_contact_switch(ev_y0, ev_f0, ev_y1, ev_f1, h, par, arms, ends, seg, corners, nbr,
                                          ev_pins0, ev_pins1, ev_wheels0, ev_wheels1)
            h, at_switch = after_rejection(h, err, expo, th, h_min)
            fac_max = 1.0
            continue
        t_new = t + h
        steps += 1
        h_lo = min(h_lo, h)
        h_hi = max(h_hi, h)
        moved = abs(Y[2] - ang_ref[0])
        for i in range(nw):
            moved = max(moved, abs(Y[5 + 3 * i] - ang_ref[1 + i]))
        if moved > rebuild_angle:
            constraint_matrix(geos[ns - 1], minv, G)
            alpha, gn = accel_matrix(G, n_acc, eps1, An, Cn, T, tmp)
            lstats[L_BUILDS] += 1
            ang_ref[0] = Y[2]
            for i in range(nw):
                ang_ref[1 + i] = Y[5 + 3 * i]
        # ---- 3: velocity level (lambda starts from the position-level end value)
        for m in range(nl):
            lam_s[m] = lam1[m]
        it_v, err_v = velocity_level(zd_new, geos[ns - 1], geos, bp, c, h, minv, lam_s, An, alpha, gn,
                                     ptol / h, max_it, nbody, dl, u, v)
        # ---- 4: acceleration level: lambda(t + h), qdd(t + h)
        for m in range(nl):
            lam_prev[m] = lam0[m]
            lam_s[m] = lam1[m]
        it_a, err_a = acceleration_level(Fst[ns - 1], geos[ns - 1], zd_new, minv, lam_s, An, alpha, gn,
                                         ptol / (h * h), max_it, nbody, zdd_new, gam, v)
        if it_v < 0 or it_a < 0:
            status = CONSTRAINT_ITERATION
        lstats[L_IT_VEL] += max(it_v, 0)
        lstats[L_IT_ACC] += max(it_a, 0)
        for k in range(nbody, nz):
            zdd_new[k] = Fst[ns - 1, k] * minv[k]
        # contact work and the diagnostics at t + h
        p_end = contact_power(Y, zd_new, ends, fcs[ns - 1], fws[ns - 1], nw)
        copy_into(ya, 0, z)
        copy_into(ya, nz, zd)
        ya[2 * nz] = W
        copy_into(fa, 0, zd)
        copy_into(fa, nz, zdd)
        fa[2 * nz] = p_start
        copy_into(yb, 0, Y)
        copy_into(yb, nz, zd_new)
        copy_into(fb, 0, zd_new)
        copy_into(fb, nz, zdd_new)
        fb[2 * nz] = p_end
        W_new = W + work_increment(ya, fa, yb, fb, h, bp, c, fcs, fws, ends, nw, p_start, p_end, yo)
        yb[2 * nz] = W_new
        diag = diags[ns - 1]
        copy_into(lam_d, 0, lam_s)
        it_d, _ = acceleration_level(Fst[ns - 1], geos[ns - 1], zd_new, minv, lam_d, An, alpha, gn, DIAG_ACC_TOL,
                                     DIAG_MAX_IT, nbody, zdd_d, gam, v)
        _count_diag(it_d, lstats)
        finish_diag(Y, zd_new, zdd_d, par, arms, p_end, diag)
        for k in range(nz):
            if not (math.isfinite(Y[k]) and math.isfinite(zd_new[k])):
                status = NAN
        if diag[D_STATUS] != 0.0:
            status = int(diag[D_STATUS])
        update_peaks(peaks, t_new, diag, zd_new[0], W_new, e_ref, r_ref, at_switch)
        at_switch = False
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
        # ---- output samples in (t, t + h]
        while n_out < n_out_max and n_out * dt_out <= t_new * (1.0 + 1e-12):
            theta = min(1.0, (n_out * dt_out - t) / h)
            hermite_second_order(ya, fa, yb, fb, h, theta, nz, yo)
            zo = yo[:nz]
            zdo = yo[nz:2 * nz]
            applied_forces(zo, zdo, par, arms, ends, seg, corners, nbr, ref, work, Fo, fco, out_d[n_out])
            n_rhs += 1
            joint_vectors(zo, par, arms, geo_o)
            for m in range(nl):
                lam_o[m] = lam0[m] + theta * (lam_s[m] - lam0[m])
            it_o, _ = acceleration_level(Fo, geo_o, zdo, minv, lam_o, An, alpha, gn, ptol / (h * h), max_it,
                                         nbody, zdd_o, gam, v)
            lstats[L_IT_OUT] += max(it_o, 0)
            copy_into(lam_d, 0, lam_o)
            it_d, _ = acceleration_level(Fo, geo_o, zdo, minv, lam_d, An, alpha, gn, DIAG_ACC_TOL, DIAG_MAX_IT,
                                         nbody, zdd_d, gam, v)
            _count_diag(it_d, lstats)
            finish_diag(zo, zdo, zdd_d, par, arms, contact_power(zo, zdo, ends, fco, work[3], nw), out_d[n_out])
            to_reduced(zo, zdo, yo[2 * nz], nw, yred)
            set_row(out_y, n_out, yred)
            set_row(out_lam, n_out, lam_d)
            set_row(out_x, n_out, acc_x)
            acc_x[:] = 0.0
            acc_x[X_H] = h
            n_out += 1
        # ---- shift: the end of this step is the start of the next
        t = t_new
        copy_into(z, 0, Y)
        copy_into(zd, 0, zd_new)
        copy_into(zdd, 0, zdd_new)
        W = W_new
        p_start = p_end
        set_row(K, 0, zdd_new)
        set_row(Fst, 0, Fst[ns - 1])
        copy_2d(fcs[0], fcs[ns - 1])
        copy_2d(fws[0], fws[ns - 1])
        copy_2d(geos[0], geos[ns - 1])
        copy_into(lam0, 0, lam_s)
        h_prev = h
        h = after_acceptance(h, err, expo, fac_max, h_max)
        fac_max = FAC_MAX
    stats[S_STATUS] = status
    stats[S_T_FINAL] = t
    stats[S_STEPS] = steps
    stats[S_REJECTED] = rejected
    stats[S_RHS] = n_rhs
    stats[S_N_OUT] = n_out
    stats[S_H_MIN] = h_lo
    stats[S_H_MAX] = h_hi
