"""Reduced-coordinate solver: a Rosenbrock-W method (ros_tableau.py) with the pins' block
Jacobian W (common/pin_jacobian.py), the whole time loop compiled. In the transformed
variables of Hairer & Wanner (IV.7, (7.25)) a stage is one block solve, no Newton iteration
and no product with W:

    (I / (h gamma) - W) u_i = f(y + sum_j<i A_ij u_j) + sum_j<i C_ij u_j / h,
    y_new = y + sum_i m_i u_i,   the error estimate sum_i e_i u_i = y_new - y_hat.

The first stage's f is f(y), the previous step's last evaluation; with f(y_new), needed by
the dense output, the event location and the next step, a step takes s right-hand sides
(ROS34PW2: 4), and a Jacobian colours x 2 more (x 3 with the bristle law's deflections) and
f(y) afresh (the soil's memory moved since the last evaluation).

A W-method keeps its order whatever W is (3 for ROS34PW2): W decides only where the step is
stable, and a W from an earlier step serves while it holds the stiff terms close enough
(RosControl.jacobian_age: the accepted steps one W serves; 1 renews it at every step; a W
older than one step is renewed after J_REJECTIONS rejections in a row). The error norm holds
the pins' velocities to their own tolerance (stepping.error_norm_pins). Everything around the
step (peaks, event location, the memories) is the explicit pairs' (solvers/common/stepping.py),
and so are the samples' positions (the quintic Hermite interpolant); their velocities are the
cubic Hermite of (qd, qdd), of order 3 as the method (stepping.dense_state). Scratch: ``lw``
(RosWork), ``jw`` (JacobianWork)."""

from collections import namedtuple

import numpy as np
from numba import njit

from ...model.contact.onsets import onset_in_step
from ...model.core.indices import PN_NQ, RS_AGE, RS_IN_ROW, RS_N_OUT
from ...model.core.jit import BORROW, INLINE
from ...model.dynamics.rhs import rhs
from ...status import SUCCESSFUL
from ..common.control import (
    FAC_MAX,
    after_acceptance,
    after_rejection,
    before_step,
    counted,
    finish_stats,
)
from ..common.events import first_contact_switch
from ..common.pin_jacobian import J_REJECTIONS, factor_velocities, pin_jacobian, solve_velocities
from ..common.stepping import accept_step, chunk_full, end_of_step, error_norm_pins, keep_state, loop_resume

# The loop's settings beside base.Control: the pins' velocities in y (lo..hi-1) and their
# tolerance, and the accepted steps one Jacobian serves.
RosControl = namedtuple("RosControl", ["pin_lo", "pin_hi", "tol_pin_velocity", "jacobian_age"])

RosWork = namedtuple("RosWork", [
    "K",      # (2, ny) f at the step's start (row 0) and at its end (row 1)
    "U",      # (stages, ny) the stages' u_i
    "y",      # (ny,) state at the step start
    "y_new",  # (ny,) state at the step end
    "ys",     # (ny,) stage state, then the state at an output sample
    "fs",     # (ny,) a stage's right side, then f at an output sample
    "z",      # (ny,) a stage's solution
    "er",     # (ny,) the error estimate
    "diag",   # (n_diag,) diagnostics of the last evaluation
    "counts",  # (4,) Jacobians formed; rejections at a located contact switch, by the error alone,
               # at an onset (kept across the chunks of a streamed run)
    "end",    # stepping.EndOfStep: the ground's state at the end of the accepted step
])

# the samples' velocities by the cubic Hermite of (qd, qdd), of the method's order 3
# (stepping.dense_state; the quintic's derivative would leave them of order 2)
RosWork.CUBIC_VELOCITIES = True


def loop_arrays(stages, ny, n_diag, n_pins):
    return RosWork(np.zeros((2, ny)), np.zeros((stages, ny)), np.empty(ny), np.empty(ny), np.empty(ny),
                   np.empty(ny), np.empty(ny), np.empty(ny), np.zeros(n_diag), np.zeros(4, dtype=np.int64),
                   end_of_step(n_pins))


@njit(**INLINE)
def _stage(i, h, tab, nq, m, w, lw, jw):
    """Stage i: its u_i (row i of lw.U); returns the right-hand sides it took."""
    U, fs, ys, y = lw.U, lw.fs, lw.ys, lw.y
    n = y.shape[0]
    used = 0
    if i == 0:
        for k in range(n):
            fs[k] = lw.K[0, k]
    else:
        for k in range(n):
            ys[k] = y[k]
        for j in range(i):
            a = tab.A[i, j]
            if a != 0.0:
                for k in range(n):
                    ys[k] += a * U[j, k]
        rhs(ys, m, w, fs, lw.diag)
        used = 1
        for j in range(i):
            c = tab.C[i, j] / h
            if c != 0.0:
                for k in range(n):
                    fs[k] += c * U[j, k]
    solve_velocities(h * tab.gamma, nq, jw, fs, lw.z)
    for k in range(n):
        U[i, k] = lw.z[k]
    return used


@njit(**INLINE)
def _step(h, tab, m, w, lw, jw):
    """The stages from lw.y; y_new, f(y_new) (row 1 of lw.K) and the error estimate. Returns
    the right-hand sides it took."""
    y, y_new, er, U = lw.y, lw.y_new, lw.er, lw.U
    n = y.shape[0]
    nq = m.pins[PN_NQ]
    used = 0
    factor_velocities(h * tab.gamma, jw)
    for i in range(tab.m.shape[0]):
        used += _stage(i, h, tab, nq, m, w, lw, jw)
    for k in range(n):
        y_new[k] = y[k]
        er[k] = 0.0
    for i in range(tab.m.shape[0]):
        mi, ei = tab.m[i], tab.e[i]
        for k in range(n):
            y_new[k] += mi * U[i, k]
            er[k] += ei * U[i, k]
    rhs(y_new, m, w, lw.K[1], lw.diag)
    return used + 1


@njit(**BORROW)
def integrate(y0, ctl, rc, tab, m, w, ev, lw, jw, out):
    y, K = lw.y, lw.K
    nq = m.pins[PN_NQ]
    pins = (rc.pin_lo, rc.pin_hi, rc.tol_pin_velocity)
    status, at, counts, refs = loop_resume(y0, min(ctl.h0, ctl.h_max), m, w, lw, out)
    t, h, n_out, n_rhs = at
    steps, rejected, h_lo, h_hi, fac_max, at_switch = counts
    e_ref, r_ref = refs
    age = int(out.resume[RS_AGE])        # rc.jacobian_age at the start: no Jacobian yet
    in_row = int(out.resume[RS_IN_ROW])  # rejections in a row
    while status == SUCCESSFUL and t < ctl.t_end * (1.0 - 1e-14):
        status, h = before_step(t, h, ctl.t_end, steps, rejected, ctl.max_steps, ctl.h_min)
        if status != SUCCESSFUL:
            break
        if chunk_full(t, h, n_out, ctl, out):   # a run streamed in chunks: hand this one over
            counts = (steps, rejected, h_lo, h_hi, fac_max, at_switch)
            keep_state(out.resume, (t, h, n_out, n_rhs), counts, refs)
            out.resume[RS_AGE], out.resume[RS_IN_ROW] = age, in_row
            return
        if age >= rc.jacobian_age or in_row >= J_REJECTIONS:
            rhs(y, m, w, lw.fs, lw.diag)   # not K[0]: the memories moved since (pin_jacobian)
            n_rhs += 1 + pin_jacobian(y, lw.fs, m, w, jw, lw.diag)
            lw.counts[0] += 1
            age = 0
            in_row = 0
        n_rhs += _step(h, tab, m, w, lw, jw)
        err = error_norm_pins(y, lw.y_new, lw.er, ctl.rtol, 2 * nq, pins)
        if not (err <= 1.0):  # also catches NaN
            rejected += 1
            th = 2.0
            if err == err and err > 0.0:
                th = first_contact_switch(y, K[0], lw.y_new, K[1], h, m, ev)
            h, at_switch = after_rejection(h, err, tab.expo, th, ctl.h_min)
            lw.counts[1 if at_switch else 2] += 1
            fac_max = 1.0
            if age > 0:
                in_row += 1   # a stale Jacobian may be why
            continue
        if onset_in_step(m, w):
            th = first_contact_switch(y, K[0], lw.y_new, K[1], h, m, ev)
            if th < 1.0 and th * h > ctl.h_min:
                rejected += 1
                lw.counts[3] += 1
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
        h = after_acceptance(h, err, tab.expo, fac_max, ctl.h_max)
        fac_max = FAC_MAX
        age += 1
        in_row = 0
    finish_stats(out.stats, status, t, steps, rejected, n_rhs, n_out, h_lo, h_hi)
    out.resume[RS_N_OUT] = n_out
