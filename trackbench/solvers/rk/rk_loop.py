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

from ...model.contact.onsets import onset_in_step, remember_onsets
from ...model.core.indices import D_E_GRAVITY, D_STATUS, N_GRIP, Q_X, S_E0, Y_WORK
from ...model.core.indices_jit import nq_of
from ...model.core.jit import BORROW, INLINE
from ...model.dynamics.rhs import rhs
from ...model.ground.memory import has_ground_memory, remember_ground
from ...status import NAN, SUCCESSFUL
from ..common.arrays import copy_into, set_row
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

# What the soil's and the bristles' memories are moved from after an accepted step (Work's
# fields of the same names, at the step's end), kept while the output samples inside the step
# are evaluated: the step was integrated with the memories as they were before it, and so are
# its samples.
EndOfStep = namedtuple("EndOfStep", ["apos", "sink", "grip"])


def loop_arrays(stages, ny, n_diag, n_pins):
    end = EndOfStep(np.zeros((n_pins, 2)), np.zeros(n_pins), np.full((n_pins, N_GRIP), np.nan))
    return RkWork(np.zeros((stages + 1, ny)), np.empty(ny), np.empty(ny), np.empty(ny), np.empty(ny),
                    np.empty(ny), np.empty(ny), np.empty(n_diag), end)


@njit(**INLINE)
def _keep_end(w, end):
    for b in range(w.sink.shape[0]):
        end.apos[b, 0] = w.apos[b, 0]
        end.apos[b, 1] = w.apos[b, 1]
        end.sink[b] = w.sink[b]
        for k in range(N_GRIP):
            end.grip[b, k] = w.grip[b, k]


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


@njit(**BORROW)
def _start(y0, m, w, lw, out):
    """t = 0: the first derivative (row 0 of K), the energy references, the first sample.
    Returns (status, e_ref, r_ref)."""
    ny = y0.shape[0]
    nq = nq_of(ny)
    copy_into(lw.y, 0, y0)
    rhs(lw.y, m, w, lw.K[0], lw.diag)
    e_ref = energy_balance(lw.diag)
    r_ref = energy_residual(lw.diag, lw.y[2 * nq + Y_WORK])
    out.stats[S_E0] = e_ref - lw.diag[D_E_GRAVITY]  # kinetic + elastic: gravity potential measured from t = 0
    init_peaks(out.peaks)
    update_peaks(out.peaks, 0.0, lw.diag, lw.y[nq + Q_X], lw.y[2 * nq + Y_WORK], e_ref, r_ref, False)
    remember_onsets(m, w)
    remember_ground(m, w)
    set_row(out.y, 0, lw.y)
    set_row(out.diag, 0, lw.diag)
    if lw.diag[D_STATUS] != 0.0:
        return int(lw.diag[D_STATUS]), e_ref, r_ref
    return SUCCESSFUL, e_ref, r_ref


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


@njit(**INLINE)
def _samples(t, h, n_out, dt_out, m, w, lw, out):
    """Output samples in (t, t + h] by Hermite interpolation; returns the new sample count."""
    y, K, y_new, ys, fs = lw.y, lw.K, lw.y_new, lw.ys, lw.fs
    out_y, out_diag = out.y, out.diag
    nq = nq_of(y.shape[0])
    s = K.shape[0] - 1
    t_new = t + h
    while n_out < out_y.shape[0] and n_out * dt_out <= t_new * (1.0 + 1e-12):
        theta = min(1.0, (n_out * dt_out - t) / h)
        hermite_second_order(y, K[0], y_new, K[s], h, theta, nq, ys)
        set_row(out_y, n_out, ys)
        rhs(ys, m, w, fs, out_diag[n_out])
        n_out += 1
    return n_out


@njit(**INLINE)
def _accepted_status(y_new, diag):
    """NAN for a state that diverged, unless the evaluation found why (diag's status)."""
    status = SUCCESSFUL
    for k in range(y_new.shape[0]):
        if not math.isfinite(y_new[k]):
            status = NAN
    if diag[D_STATUS] != 0.0:
        status = int(diag[D_STATUS])
    return status


@njit(**BORROW)
def integrate(y0, ctl, tab, m, w, ev, lw, out):
    A, b, e, e3, expo = tab.A, tab.b, tab.e, tab.e3, tab.expo
    K, y, y_new, ys, er5, er3, diag = lw.K, lw.y, lw.y_new, lw.ys, lw.er5, lw.er3, lw.diag
    peaks = out.peaks
    rtol, atol, h_min, h_max, t_end = ctl.rtol, ctl.atol, ctl.h_min, ctl.h_max, ctl.t_end
    ny = y0.shape[0]
    nq = nq_of(ny)
    s = b.shape[0]
    status, e_ref, r_ref = _start(y0, m, w, lw, out)
    h = min(ctl.h0, h_max)
    n_rhs = n_out = 1
    t, steps, rejected, h_lo, h_hi, fac_max, at_switch = loop_start()
    memory = has_ground_memory(m.par)   # soil or bristles: their memories move after each accepted step
    while status == SUCCESSFUL and t < t_end * (1.0 - 1e-14):
        status, h = before_step(t, h, t_end, steps, rejected, ctl.max_steps, h_min)
        if status != SUCCESSFUL:
            break
        _stages(h, A, b, m, w, y, K, ys, y_new, diag)
        n_rhs += s
        err = _error_norm(y, y_new, K, e, e3, h, rtol, atol, 2 * nq, er5, er3)  # (q, qd): W and D follow
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
        t_new = t + h
        steps, h_lo, h_hi = counted(h, steps, h_lo, h_hi)
        status = _accepted_status(y_new, diag)
        update_peaks(peaks, t_new, diag, y_new[nq + Q_X], y_new[2 * nq + Y_WORK], e_ref, r_ref, at_switch)
        at_switch = False
        remember_onsets(m, w)
        if memory:
            _keep_end(w, lw.end)
        n_new = _samples(t, h, n_out, ctl.dt_out, m, w, lw, out)
        if memory:
            remember_ground(m, lw.end)  # from the accepted end state, after the samples inside the step
        n_rhs += n_new - n_out
        n_out = n_new
        t = t_new
        for k in range(ny):
            y[k] = y_new[k]
            K[0, k] = K[s, k]
        h = after_acceptance(h, err, expo, fac_max, h_max)
        fac_max = FAC_MAX
    finish_stats(out.stats, status, t, steps, rejected, n_rhs, n_out, h_lo, h_hi)
