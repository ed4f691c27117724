"""Reduced-coordinate solver: an additive Runge-Kutta (IMEX) pair (ark_tableau.py) with the
pins' block Jacobian J (common/pin_jacobian.py) as its implicit part, the whole time loop
compiled. The right-hand side is split f = (f - J y) + J y: the explicit tableau takes the
first, the ESDIRK tableau the second, a linear term, so a stage is one solve with the blocks
of I - h gamma J and no Newton iteration. In the stage increments Z_i = Y_i - y (the J y
terms of the two tableaus cancel, their rows summing alike):

    (I - h gamma J) Z_i = h sum_j<i [AE_ij F_j + (AI_ij - AE_ij) J Z_j],   F_j = f(y + Z_j),
    y_new = y + h sum_i b_i F_i,   the estimate h sum_i (b_i - b_hat_i) F_i.

Both parts are smooth functions of y for any fixed J, so the pair keeps its order whatever J
is (J is reused while steps are accepted); J decides only where the step is stable: friction
holding a loaded pin stuck (up to -7.6e5 1/s) is integrated implicitly, the rest at the
explicit pair's accuracy. Everything around the step is the explicit pairs'
(solvers/common/stepping.py). Scratch: ``lw`` (ArkWork below), ``jw`` (JacobianWork)."""

from collections import namedtuple

import numpy as np
from numba import njit

from ...model.contact.onsets import onset_in_step
from ...model.core.indices import PN_NQ, RS_AGE, RS_IN_ROW, RS_N_OUT
from ...model.core.jit import BORROW, INLINE
from ...model.dynamics.rhs import rhs
from ...model.ground.memory import has_ground_memory
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
from ..common.pin_jacobian import J_AGE, J_REJECTIONS, factor, pin_jacobian, solve, times_j
from ..common.stepping import accept_step, chunk_full, end_of_step, error_norm, keep_state, loop_resume

ArkWork = namedtuple("ArkWork", [
    "K",      # (stages + 1, ny) F_i = f(y + Z_i); row 0 f at the step's start, the last f at its end
    "JZ",     # (stages, ny) J Z_i
    "y",      # (ny,) state at the step start
    "y_new",  # (ny,) state at the step end
    "ys",     # (ny,) stage state, then the state at an output sample
    "fs",     # (ny,) a stage's right side, then f at an output sample
    "z",      # (ny,) a stage's increment Z_i
    "er",     # (ny,) the error estimate
    "diag",   # (n_diag,) diagnostics of the last evaluation
    "end",    # stepping.EndOfStep: the ground's state at the end of the accepted step
])


def loop_arrays(stages, ny, n_diag, n_pins):
    return ArkWork(np.zeros((stages + 1, ny)), np.zeros((stages, ny)), np.empty(ny), np.empty(ny),
                   np.empty(ny), np.empty(ny), np.empty(ny), np.empty(ny), np.zeros(n_diag),
                   end_of_step(n_pins))


@njit(**INLINE)
def _stage(i, h, tab, nq, m, w, lw, jw):
    """Stage i >= 1: its increment Z_i (lw.z), J Z_i (lw.JZ[i]) and F_i = f(y + Z_i) (lw.K[i])."""
    K, JZ, fs, z = lw.K, lw.JZ, lw.fs, lw.z
    n = fs.shape[0]
    hg = h * tab.gamma
    for k in range(n):
        fs[k] = 0.0
    for j in range(i):
        a, d = tab.AE[i, j], tab.D[i, j]
        for k in range(n):
            fs[k] += a * K[j, k] + d * JZ[j, k]
    for k in range(n):
        fs[k] *= h / hg   # (I / (h gamma) - J) Z = R / (h gamma)
    solve(hg, nq, jw, fs, z)
    times_j(nq, jw, z, JZ[i])
    for k in range(n):
        lw.ys[k] = lw.y[k] + z[k]
    rhs(lw.ys, m, w, K[i], lw.diag)


@njit(**INLINE)
def _step(h, tab, m, w, lw, jw):
    """The stages from lw.y; y_new, its derivative (the last row of lw.K) and the error
    estimate. Returns the right-hand sides it took."""
    y, y_new, er, K = lw.y, lw.y_new, lw.er, lw.K
    n = y.shape[0]
    nq = m.pins[PN_NQ]
    s = tab.b.shape[0]
    factor(h * tab.gamma, jw)
    for k in range(n):
        lw.JZ[0, k] = 0.0
    for i in range(1, s):
        _stage(i, h, tab, nq, m, w, lw, jw)
    for k in range(n):
        y_new[k] = y[k]
        er[k] = 0.0
    for i in range(s):
        bi, ei = h * tab.b[i], h * (tab.b[i] - tab.b_hat[i])
        for k in range(n):
            y_new[k] += bi * K[i, k]
            er[k] += ei * K[i, k]
    # the estimate through (I - h gamma J)^-1, as stiff solvers filter theirs (Hairer & Wanner
    # II, IV.8, (8.20)): unfiltered, the stiff pins' large derivatives swamp it
    hg = h * tab.gamma
    for k in range(n):
        lw.fs[k] = er[k] / hg
    solve(hg, nq, jw, lw.fs, er)
    rhs(y_new, m, w, K[s], lw.diag)
    return s


@njit(**BORROW)
def integrate(y0, ctl, tab, m, w, ev, lw, jw, out):
    y, y_new, K = lw.y, lw.y_new, lw.K
    nq = m.pins[PN_NQ]
    s = tab.b.shape[0]
    status, at, counts, refs = loop_resume(y0, min(ctl.h0, ctl.h_max), m, w, lw, out)
    t, h, n_out, n_rhs = at
    steps, rejected, h_lo, h_hi, fac_max, at_switch = counts
    e_ref, r_ref = refs
    age = int(out.resume[RS_AGE])        # J_AGE at the start: no Jacobian yet
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
        if age >= J_AGE or in_row >= J_REJECTIONS:
            if has_ground_memory(m.par):   # f at y with the soil's memory as moved since K[0]
                rhs(y, m, w, lw.fs, lw.diag)
                n_rhs += 1 + pin_jacobian(y, lw.fs, m, w, jw, lw.diag)
            else:
                n_rhs += pin_jacobian(y, K[0], m, w, jw, lw.diag)
            age = 0
            in_row = 0
        n_rhs += _step(h, tab, m, w, lw, jw)
        err = error_norm(y, y_new, lw.er, ctl.rtol, ctl.atol, 2 * nq)
        if not (err <= 1.0):  # also catches NaN
            rejected += 1
            th = 2.0
            if err == err and err > 0.0:
                th = first_contact_switch(y, K[0], y_new, K[s], h, m, ev)
            h, at_switch = after_rejection(h, err, tab.expo, th, ctl.h_min)
            fac_max = 1.0
            if age > 0:
                in_row += 1   # a stale Jacobian may be why
            continue
        if onset_in_step(m, w):
            th = first_contact_switch(y, K[0], y_new, K[s], h, m, ev)
            if th < 1.0 and th * h > ctl.h_min:
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
        h = after_acceptance(h, err, tab.expo, fac_max, ctl.h_max)
        fac_max = FAC_MAX
        age += 1
        in_row = 0
    finish_stats(out.stats, status, t, steps, rejected, n_rhs, n_out, h_lo, h_hi)
    out.resume[RS_N_OUT] = n_out
