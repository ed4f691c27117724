"""Reduced-coordinate solver: an embedded explicit Runge-Kutta pair (tableau.py) with
adaptive step size, the whole time loop compiled. Returns output samples on a regular
grid (Hermite interpolation between accepted steps) and peaks over every step."""

import math

import numpy as np
from numba import njit

from ..model.layout import D_E_GRAVITY, D_STATUS, S_E0, S_H_MAX, S_H_MIN, S_N_OUT, S_REJECTED, S_RHS, \
    S_STATUS, S_STEPS, S_T_FINAL, Q_X
from ..model.reduced import reduced_rhs
from ..status import NAN, SUCCESSFUL
from .arrays import set_row
from .control import FAC_MAX, after_acceptance, after_rejection, before_step
from .events import first_contact_switch
from .monitor import energy_balance, energy_residual, hermite_second_order, init_peaks, update_peaks



@njit(cache=True, error_model="numpy")
def _combine(y, h, w, K, m, out):
    """out = y + h * sum_j<m w_j K_j (zero weights skipped). K is indexed in 2D, not by
    row views: a view per stage costs reference counting (~6 % of a run)."""
    n = out.shape[0]
    for k in range(n):
        out[k] = y[k]
    for j in range(m):
        c = h * w[j]
        if c != 0.0:
            for k in range(n):
                out[k] += c * K[j, k]


@njit(cache=True, error_model="numpy")
def _error_norm(y, y_new, K, e, e3, h, rtol, atol, n, er5, er3):
    """RMS norm of the embedded error estimate over the first n components
    (Hairer's DOP853 combination when e3 is given)."""
    use3 = e3[0] != 0.0
    for k in range(n):
        er5[k] = 0.0
        er3[k] = 0.0
    for j in range(K.shape[0]):
        if e[j] != 0.0:
            ej = e[j]
            for k in range(n):
                er5[k] += ej * K[j, k]
        if use3 and e3[j] != 0.0:
            ej = e3[j]
            for k in range(n):
                er3[k] += ej * K[j, k]
    s5 = 0.0
    s3 = 0.0
    for k in range(n):
        sc = atol + rtol * max(abs(y[k]), abs(y_new[k]))
        s5 += (er5[k] / sc) ** 2
        s3 += (er3[k] / sc) ** 2
    if use3:
        den = s5 + 0.01 * s3
        if den <= 0.0:
            return 0.0
        return abs(h) * s5 / math.sqrt(den * n)
    return abs(h) * math.sqrt(s5 / n)


@njit(cache=True, error_model="numpy")
def integrate(y0, t_end, dt_out, A, b, c, e, e3, expo, rtol, atol, h0, h_max, h_min, max_steps,
              par, arms, ends, seg, corners, nbr, ref, work, out_y, out_d, peaks, stats):
    ny = y0.shape[0]
    nq = (ny - 1) // 2
    s = b.shape[0]
    K = np.zeros((s + 1, ny))
    y = y0.copy()
    y_new = np.empty(ny)
    ys = np.empty(ny)
    fs = np.empty(ny)
    er5 = np.empty(ny)
    pins0 = np.empty((work[0].shape[0], 2))  # scratch of the event location
    pins1 = np.empty_like(pins0)
    wheels0 = np.empty((arms.shape[0], 2))
    wheels1 = np.empty_like(wheels0)
    er3 = np.empty(ny)
    diag = np.empty(out_d.shape[1])
    n_rhs = 0
    reduced_rhs(y, par, arms, ends, seg, corners, nbr, ref, work, K[0], diag)
    n_rhs += 1
    e_ref = energy_balance(diag)
    r_ref = energy_residual(diag, y[ny - 1])
    stats[S_E0] = e_ref - diag[D_E_GRAVITY]  # kinetic + elastic: gravity potential measured from t = 0
    init_peaks(peaks)
    update_peaks(peaks, 0.0, diag, y[nq + Q_X], y[ny - 1], e_ref, r_ref, False)
    set_row(out_y, 0, y)
    set_row(out_d, 0, diag)
    n_out = 1
    n_out_max = out_y.shape[0]
    status = SUCCESSFUL
    if diag[D_STATUS] != 0.0:
        status = int(diag[D_STATUS])
    t = 0.0
    h = min(h0, h_max)
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
        for i in range(1, s):
            _combine(y, h, A[i], K, i, ys)
            reduced_rhs(ys, par, arms, ends, seg, corners, nbr, ref, work, K[i], diag)
        _combine(y, h, b, K, s, y_new)
        reduced_rhs(y_new, par, arms, ends, seg, corners, nbr, ref, work, K[s], diag)
        n_rhs += s
        err = _error_norm(y, y_new, K, e, e3, h, rtol, atol, ny - 1, er5, er3)
        if not (err <= 1.0):  # also catches NaN
            rejected += 1
            th = 2.0
            if err == err and err > 0.0:
                # a contact starting or ending inside the step: end the retry just after it
                th = first_contact_switch(y, K[0], y_new, K[s], h, par, arms, ends, seg, corners, nbr,
                                          pins0, pins1, wheels0, wheels1)
            h, at_switch = after_rejection(h, err, expo, th, h_min)
            fac_max = 1.0
            continue
        # accepted
        t_new = t + h
        steps += 1
        h_lo = min(h_lo, h)
        h_hi = max(h_hi, h)
        for k in range(ny):
            if not math.isfinite(y_new[k]):
                status = NAN
        if diag[D_STATUS] != 0.0:
            status = int(diag[D_STATUS])
        update_peaks(peaks, t_new, diag, y_new[nq + Q_X], y_new[ny - 1], e_ref, r_ref, at_switch)
        at_switch = False
        # output samples in (t, t_new]
        while n_out < n_out_max and n_out * dt_out <= t_new * (1.0 + 1e-12):
            t_o = n_out * dt_out
            theta = min(1.0, (t_o - t) / h)
            hermite_second_order(y, K[0], y_new, K[s], h, theta, nq, ys)
            set_row(out_y, n_out, ys)
            reduced_rhs(ys, par, arms, ends, seg, corners, nbr, ref, work, fs, out_d[n_out])
            n_rhs += 1
            n_out += 1
        t = t_new
        for k in range(ny):
            y[k] = y_new[k]
            K[0, k] = K[s, k]
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
