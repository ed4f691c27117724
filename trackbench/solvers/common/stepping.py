"""What the compiled time loops of the reduced state share around their steps: the start at
t = 0, what follows an accepted step (its status, peaks, output samples by Hermite
interpolation between the step's ends, the memories moved, the end made the next start), and
the ground's state at a step's end kept while the samples are evaluated. A loop's scratch
bundle has the fields y, y_new, ys, fs, diag, end and K (row 0: f at the step's start; last
row: f at its end)."""

import math
from collections import namedtuple

import numpy as np
from numba import njit
from numba.extending import overload

from ...model.contact.onsets import remember_onsets
from ...model.core.indices import (
    D_E_GRAVITY,
    D_STATUS,
    N_Y_EXTRA,
    PN_NQ,
    Q_X,
    RS_AT_SWITCH,
    RS_BASE,
    RS_E_REF,
    RS_FAC_MAX,
    RS_H,
    RS_H_HI,
    RS_H_LO,
    RS_N_OUT,
    RS_N_RHS,
    RS_PAUSED,
    RS_R_REF,
    RS_REJECTED,
    RS_STARTED,
    RS_STEPS,
    RS_T,
    S_E0,
    Y_WORK,
)
from ...model.core.jit import BORROW, INLINE, KERNEL
from ...model.dynamics.rhs import rhs
from ...model.ground.memory import has_ground_memory, remember_ground
from ...status import NAN, SUCCESSFUL
from .arrays import copy_into, set_row
from .control import loop_start
from .hermite import hermite_second_order, hermite_velocities
from .monitor import energy_balance, energy_residual, init_peaks, update_peaks
from .sinkage import remember_inside_step

# What the soil's memory is moved from after an accepted step (Work's fields of the same
# names, at the step's end), kept while the output samples inside the step are evaluated: the
# step was integrated with the memory as it was before it, and so are its samples.
EndOfStep = namedtuple("EndOfStep", ["apos", "sink"])


def end_of_step(n_pins):
    return EndOfStep(np.zeros((n_pins, 2)), np.zeros(n_pins))


@njit(**INLINE)
def keep_end(w, end):
    for b in range(w.sink.shape[0]):
        end.apos[b, 0] = w.apos[b, 0]
        end.apos[b, 1] = w.apos[b, 1]
        end.sink[b] = w.sink[b]


@njit(**BORROW)
def loop_first(y0, m, w, lw, out):
    """t = 0: the first derivative (row 0 of K), the energy references, the first sample.
    Returns (status, e_ref, r_ref)."""
    nq = m.pins[PN_NQ]
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
def loop_resume(y0, h0, m, w, lw, out):
    """The loop's state: at t = 0 (loop_first) on a run's first call, else where its last call
    paused (keep_state). Returns (status, (t, h, n_out, n_rhs), (steps, rejected, h_lo, h_hi,
    fac_max, at_switch), (e_ref, r_ref))."""
    rs = out.resume
    if rs[RS_STARTED] == 0.0:
        status, e_ref, r_ref = loop_first(y0, m, w, lw, out)
        rs[RS_STARTED] = 1.0
        t, steps, rejected, h_lo, h_hi, fac_max, at_switch = loop_start()
        return status, (t, h0, 1, 1), (steps, rejected, h_lo, h_hi, fac_max, at_switch), (e_ref, r_ref)
    rs[RS_PAUSED] = 0.0
    counts = (int(rs[RS_STEPS]), int(rs[RS_REJECTED]), rs[RS_H_LO], rs[RS_H_HI], rs[RS_FAC_MAX],
              rs[RS_AT_SWITCH] != 0.0)
    return SUCCESSFUL, (rs[RS_T], rs[RS_H], int(rs[RS_N_OUT]), int(rs[RS_N_RHS])), counts, (rs[RS_E_REF],
                                                                                          rs[RS_R_REF])


@njit(**INLINE)
def keep_state(rs, at, counts, refs):
    """Pause: the loop's state into rs (Outputs.resume) for loop_resume; at = (t, h, n_out, n_rhs)."""
    rs[RS_PAUSED] = 1.0
    rs[RS_T], rs[RS_H], rs[RS_N_OUT], rs[RS_N_RHS] = at
    steps, rejected, h_lo, h_hi, fac_max, at_switch = counts
    rs[RS_STEPS], rs[RS_REJECTED] = steps, rejected
    rs[RS_H_LO], rs[RS_H_HI], rs[RS_FAC_MAX] = h_lo, h_hi, fac_max
    rs[RS_AT_SWITCH] = 1.0 if at_switch else 0.0
    rs[RS_E_REF], rs[RS_R_REF] = refs


@njit(**INLINE)
def chunk_full(t, h, n_out, ctl, out):
    """Whether the samples a step from t to t + h would take overrun the chunk (out.y's rows,
    row 0 being sample out.resume[RS_BASE]): the loop then pauses before the step and tries the
    same step when resumed, so a run streamed in chunks takes the steps of a run in one piece."""
    n = n_out
    t_new = t + h
    while n < ctl.n_samples and n * ctl.dt_out <= t_new * (1.0 + 1e-12):
        n += 1
    return n - int(out.resume[RS_BASE]) > out.y.shape[0]


def _cubic_velocities(lw):
    """Whether the loop's scratch asks for velocities of order 3 (its class says
    CUBIC_VELOCITIES = True: the Rosenbrock-W loop's)."""
    return getattr(getattr(lw, "instance_class", None), "CUBIC_VELOCITIES", False)


def dense_state(y0, f0, y1, f1, h, theta, nq, lw):
    """The state at t0 + theta h of the step (y0, f0) -> (y1, f1) into lw.ys: hermite.py's
    quintic for positions and its derivative for velocities, or, for a loop of order 3 (by the
    type of lw), the cubic Hermite of the velocities themselves."""
    raise NotImplementedError("compiled only")


@overload(dense_state, jit_options=KERNEL)
def _dense_state_impl(y0, f0, y1, f1, h, theta, nq, lw):
    if _cubic_velocities(lw):
        def cubic(y0, f0, y1, f1, h, theta, nq, lw):
            hermite_second_order(y0, f0, y1, f1, h, theta, nq, lw.ys)
            hermite_velocities(y0, f0, y1, f1, h, theta, nq, lw.ys)
        return cubic
    return lambda y0, f0, y1, f1, h, theta, nq, lw: hermite_second_order(y0, f0, y1, f1, h, theta, nq, lw.ys)


@njit(**INLINE)
def samples(t, h, n_out, ctl, m, w, lw, out):
    """Output samples in (t, t + h] by Hermite interpolation into the chunk's rows; returns the
    new sample count."""
    y, K, y_new, ys, fs = lw.y, lw.K, lw.y_new, lw.ys, lw.fs
    out_y, out_diag = out.y, out.diag
    nq = m.pins[PN_NQ]
    s = K.shape[0] - 1
    t_new = t + h
    dt_out = ctl.dt_out
    base = int(out.resume[RS_BASE])
    while n_out < ctl.n_samples and n_out * dt_out <= t_new * (1.0 + 1e-12):
        theta = min(1.0, (n_out * dt_out - t) / h)
        dense_state(y, K[0], y_new, K[s], h, theta, nq, lw)
        set_row(out_y, n_out - base, ys)
        rhs(ys, m, w, fs, out_diag[n_out - base])
        n_out += 1
    return n_out


@njit(**INLINE)
def accepted_status(y_new, diag):
    """NAN for a state that diverged, unless the evaluation found why (diag's status)."""
    status = SUCCESSFUL
    for k in range(y_new.shape[0]):
        if not math.isfinite(y_new[k]):
            status = NAN
    if diag[D_STATUS] != 0.0:
        status = int(diag[D_STATUS])
    return status


@njit(**INLINE)
def _squares(y, y_new, er, rtol, atol, lo, hi):
    s = 0.0
    for k in range(lo, hi):
        sc = atol + rtol * max(abs(y[k]), abs(y_new[k]))
        s += (er[k] / sc) ** 2
    return s


@njit(**INLINE)
def error_norm(y, y_new, er, rtol, atol, n):
    """RMS norm of an error estimate er over the first n components (q, qd) and the bristle
    deflections after the extras: the linearly implicit methods' (the explicit pairs' own,
    rk_loop.py, folds in h)."""
    ny = y.shape[0]
    s = _squares(y, y_new, er, rtol, atol, 0, n)
    if ny > n + N_Y_EXTRA:   # the bristle law's states
        s += _squares(y, y_new, er, rtol, atol, n + N_Y_EXTRA, ny)
    return math.sqrt(s / (ny - N_Y_EXTRA))


@njit(**INLINE)
def error_norm_pins(y, y_new, er, tol, n, pins):
    """error_norm with tolerances per component: the pins' velocities, components pins = (lo,
    hi, tol_v) lo..hi-1, held to tol_v (atol = rtol = tol_v), every other one to tol; the RMS
    over the same components (q, qd, the bristle deflections). The Rosenbrock-W method's."""
    lo, hi, tol_v = pins
    ny = y.shape[0]
    s = _squares(y, y_new, er, tol, tol, 0, lo)
    s += _squares(y, y_new, er, tol_v, tol_v, lo, hi)
    s += _squares(y, y_new, er, tol, tol, hi, n)
    if ny > n + N_Y_EXTRA:   # the bristle law's states
        s += _squares(y, y_new, er, tol, tol, n + N_Y_EXTRA, ny)
    return math.sqrt(s / (ny - N_Y_EXTRA))


@njit(**INLINE)
def accept_step(t, h, n_out, step_refs, m, w, ev, lw, ctl, out):
    """After the step from t to t + h was accepted: its status, the peaks (step_refs = (at_switch,
    e_ref, r_ref)), the approach speeds, the output samples inside it, the ground's memories
    (after the samples: they were integrated with the memories as they were), and y_new, f(y_new)
    as the next step's start. Returns (status, the new sample count)."""
    at_switch, e_ref, r_ref = step_refs
    y, y_new, K, diag = lw.y, lw.y_new, lw.K, lw.diag
    nq = m.pins[PN_NQ]
    s = K.shape[0] - 1
    memory = has_ground_memory(m.par)   # soil: its memory moves after each accepted step
    status = accepted_status(y_new, diag)
    update_peaks(out.peaks, t + h, diag, y_new[nq + Q_X], y_new[2 * nq + Y_WORK], e_ref, r_ref, at_switch)
    remember_onsets(m, w)
    if memory:
        keep_end(w, lw.end)
    n_new = samples(t, h, n_out, ctl, m, w, lw, out)
    if memory:
        remember_inside_step(y, K[0], y_new, K[s], h, m, ev, lw.end)   # the soil's, along the step
        remember_ground(m, lw.end)  # from the accepted end state, after the samples inside the step
    for k in range(y.shape[0]):
        y[k] = y_new[k]
        K[0, k] = K[s, k]
    return status, n_new
