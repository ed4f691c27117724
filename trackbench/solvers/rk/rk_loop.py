"""Reduced-coordinate solver: an embedded explicit Runge-Kutta pair (tableau.py) with
adaptive step size, the whole time loop compiled. Returns output samples on a regular
grid (Hermite interpolation between accepted steps) and peaks over every step.

The loop's scratch is allocated by the Python side (rk_run.py) and arrives bundled:
``ctl`` (base.Control), ``tab`` (tableau.TableauArrays), ``m``/``w``/``ev``
(model/core/bundles.py), ``lw`` (RkWork below: the time loop's scratch), ``out`` (base.Outputs)."""

import math
from collections import namedtuple

import numpy as np
from numba import njit

from ...model.contact.onsets import onset_in_step
from ...model.core.indices import N_Y_EXTRA, PN_NQ, RS_ERR_OLD, RS_N_OUT
from ...model.core.jit import BORROW, INLINE
from ...model.dynamics.rhs import rhs
from ...status import SUCCESSFUL
from ..common.control import (
    ERR_OLD_MIN,
    FAC_MAX,
    after_acceptance_pi,
    after_rejection,
    before_step,
    counted,
    finish_stats,
)
from ..common.events import first_contact_switch
from ..common.stepping import accept_step, chunk_full, end_of_step, keep_state, loop_resume

RkWork = namedtuple("RkWork", [
    "K",      # (stages + 1, ny) stage derivatives; row 0 = f at the step start (FSAL)
    "y",      # (ny,) state at the step start
    "y_new",  # (ny,) state at the step end
    "ys",     # (ny,) stage state, then the state at an output sample
    "fs",     # (ny,) derivative at an output sample (unused but required by the right-hand side)
    "er5",    # (ny,) error estimate, 5th order
    "er3",    # (ny,) error estimate, 3rd order (DOP853)
    "diag",   # (n_diag,) diagnostics of the last evaluation
    "end",    # EndOfStep: the ground's state at the end of the accepted step
])


def loop_arrays(stages, ny, n_diag, n_pins):
    # diag zeroed: a layout's rhs leaves the other layout's columns alone, and the first sample
    # copies the whole row (np.empty left it what memory held: runs that differed there)
    return RkWork(np.zeros((stages + 1, ny)), np.empty(ny), np.empty(ny), np.empty(ny), np.empty(ny),
                  np.empty(ny), np.empty(ny), np.zeros(n_diag), end_of_step(n_pins))


@njit(**INLINE)
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


@njit(**INLINE)
def _error_sums(y, y_new, K, e, e3, rtol, atol, lo, hi, er5, er3):
    """Sums of the squared scaled error estimates (5th order, 3rd order when e3 is given)
    over the components lo..hi-1."""
    use3 = e3[0] != 0.0
    for k in range(lo, hi):
        er5[k] = 0.0
        er3[k] = 0.0
    for j in range(K.shape[0]):
        if e[j] != 0.0:
            ej = e[j]
            for k in range(lo, hi):
                er5[k] += ej * K[j, k]
        if use3 and e3[j] != 0.0:
            ej = e3[j]
            for k in range(lo, hi):
                er3[k] += ej * K[j, k]
    s5 = 0.0
    s3 = 0.0
    for k in range(lo, hi):
        sc = atol + rtol * max(abs(y[k]), abs(y_new[k]))
        s5 += (er5[k] / sc) ** 2
        s3 += (er3[k] / sc) ** 2
    return s5, s3


@njit(**INLINE)
def _error_norm(y, y_new, K, e, e3, h, rtol, atol, n, er5, er3):
    """RMS norm of the embedded error estimate over the second-order states (q, qd), the
    first n components, and the bristle deflections after the extras (Hairer's DOP853
    combination when e3 is given); the extras (W, D, the drive's) are left out."""
    ny = y.shape[0]
    s5, s3 = _error_sums(y, y_new, K, e, e3, rtol, atol, 0, n, er5, er3)
    if ny > n + N_Y_EXTRA:   # the bristle law's states (a separate call: the loops above stay as fast)
        z5, z3 = _error_sums(y, y_new, K, e, e3, rtol, atol, n + N_Y_EXTRA, ny, er5, er3)
        s5 += z5
        s3 += z3
    n_err = ny - N_Y_EXTRA
    if e3[0] != 0.0:
        den = s5 + 0.01 * s3
        if den <= 0.0:
            return 0.0
        return abs(h) * s5 / math.sqrt(den * n_err)
    return abs(h) * math.sqrt(s5 / n_err)


@njit(**INLINE)
def _stages(h, A, b, m, w, y, K, ys, y_new, diag):
    """One step of the pair from y: stages into K, the new state into y_new and its
    derivative into the last row of K (first same as last)."""
    s = b.shape[0]
    for i in range(1, s):
        _combine(y, h, A[i], K, i, ys)
        rhs(ys, m, w, K[i], diag)
    _combine(y, h, b, K, s, y_new)
    rhs(y_new, m, w, K[s], diag)


@njit(**BORROW)
def integrate(y0, ctl, tab, m, w, ev, lw, out):
    A, b, e, e3, expo = tab.A, tab.b, tab.e, tab.e3, tab.expo
    K, y, y_new, ys, er5, er3, diag = lw.K, lw.y, lw.y_new, lw.ys, lw.er5, lw.er3, lw.diag
    rtol, atol, h_min, h_max, t_end = ctl.rtol, ctl.atol, ctl.h_min, ctl.h_max, ctl.t_end
    nq = m.pins[PN_NQ]
    s = b.shape[0]
    status, at, counts, refs = loop_resume(y0, min(ctl.h0, h_max), m, w, lw, out)
    t, h, n_out, n_rhs = at
    steps, rejected, h_lo, h_hi, fac_max, at_switch = counts
    e_ref, r_ref = refs
    err_old = max(out.resume[RS_ERR_OLD], ERR_OLD_MIN)   # the PI controller's (ctl.pi_beta)
    while status == SUCCESSFUL and t < t_end * (1.0 - 1e-14):
        status, h = before_step(t, h, t_end, steps, rejected, ctl.max_steps, h_min)
        if status != SUCCESSFUL:
            break
        if chunk_full(t, h, n_out, ctl, out):   # a run streamed in chunks: hand this one over
            counts = (steps, rejected, h_lo, h_hi, fac_max, at_switch)
            keep_state(out.resume, (t, h, n_out, n_rhs), counts, refs)
            out.resume[RS_ERR_OLD] = err_old
            return
        _stages(h, A, b, m, w, y, K, ys, y_new, diag)
        n_rhs += s
        err = _error_norm(y, y_new, K, e, e3, h, rtol, atol, 2 * nq, er5, er3)  # (q, qd), bristles
        if not (err <= 1.0):  # also catches NaN
            rejected += 1
            th = 2.0
            if err == err and err > 0.0:
                # a contact starting or ending inside the step: end the retry just after it
                th = first_contact_switch(y, K[0], y_new, K[s], h, m, ev)
            h, at_switch = after_rejection(h, err, expo, th, h_min)
            fac_max = 1.0
            continue
        if onset_in_step(m, w):
            # a contact whose law remembers its approach speed began inside the step:
            # end the step at the onset (if located before the end) and take it there
            th = first_contact_switch(y, K[0], y_new, K[s], h, m, ev)
            if th < 1.0 and th * h > h_min:
                rejected += 1
                h *= th
                at_switch = True
                fac_max = 1.0
                continue
        steps, h_lo, h_hi = counted(h, steps, h_lo, h_hi)
        status, n_new = accept_step(t, h, n_out, (at_switch, e_ref, r_ref), m, w, ev, lw, ctl, out)
        at_switch = False
        n_rhs += n_new - n_out
        n_out = n_new
        t += h
        h = after_acceptance_pi(h, err, err_old, expo, ctl.pi_beta, fac_max, h_max)
        err_old = max(err, ERR_OLD_MIN)
        fac_max = FAC_MAX
    finish_stats(out.stats, status, t, steps, rejected, n_rhs, n_out, h_lo, h_hi)
    out.resume[RS_N_OUT] = n_out
