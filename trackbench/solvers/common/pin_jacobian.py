"""The Jacobian J the IMEX pairs solve with (solvers/imex: their implicit part J y): one
dense block per pin over the pin's own state components (x, y, vx, vy) and, with the
bristle law, its bristle's deflection z; the velocity (and z) columns from finite differences
of the whole right-hand side, and the exact kinematic identity d q / dt = qd for every
coordinate.

Why per pin: what limits an explicit step on the driven vehicle is local to each pin: the
regularised Coulomb law holding a loaded pin stuck (a damper mu p / (v_eps m_pin), up to
7.6e5 1/s), its impacts on pads and teeth, its soil's pressure and shear. A pin's force
depends on its own state and its two neighbours' (the links, Eq. 8; the load of a contact
on a link, Eq. 7), so pins two apart are perturbed together (a colouring of the ring or
chain of pins): a Jacobian costs colours x 4 right-hand sides, whatever the number of pins.
The pairs keep their order with any J; what the blocks leave out (the links'
coupling between pins, the chassis and wheels) is integrated as accurately as the rest, only
explicitly. Why velocity columns only: the stiff terms are dampers (friction's slope, the
pads' and links' dashpots); the position columns hold the links' stiffness between pins,
and a block keeps only its diagonal part: measured on paper_step (0.1 s, tolerance 1e-6),
a Rosenbrock-W method (ROS34PW2) with position columns took 108,570 steps + 55,383 rejected
against 1,419 + 49 without: a linearly implicit step is stable only where J is close to the
Jacobian in the stiff directions, and the diagonal part of the links' coupling is not."""

import math
from collections import namedtuple

import numpy as np
from numba import njit

from ...model.core import indices as L
from ...model.core.jit import BORROW, INLINE
from ...model.dynamics.rhs import rhs
from .arrays import copy_into

N_KINEMATIC = 2   # a block's first rows are positions: d (x, y) / dt = (vx, vy), exact
SQRT_EPS = math.sqrt(np.finfo(float).eps)
SCALE_VELOCITY = 1e-1   # m/s: the least velocity (1.5e-9 m/s, well inside v_eps = 0.01 m/s)
SCALE_DEFLECTION = 1e-3   # m: the least bristle deflection (1.5e-11 m; mu p / k_t is ~3e-3 m)

JacobianWork = namedtuple("JacobianWork", [
    "blk",      # (n_pins, nb) the state indices of each pin's block: x, y, vx, vy
    "colours",  # (n_colours, n_per) the pins perturbed together (row numbers of blk), -1 padded
    "free",     # (n_free,) coordinates in no block: u_q = h gamma (r_q + u_qd)
    "scale",    # (nb,) the least magnitude of each block component's perturbation (0: J's column
                #       of that component is left 0, not differenced)
    "jac",      # (n_pins, nb, nb) the blocks of J
    "lu",       # (n_pins, nb, nb) LU factors of I / (h gamma) - J
    "piv",      # (n_pins, nb) their row pivots
    "dlt",      # (n_pins,) the perturbation of the component being differenced
    "yp",       # (ny,) perturbed state
    "fp",       # (ny,) its derivative
    "rb",       # (nb,) one block's right-hand side
])

J_AGE = 20           # accepted steps one Jacobian serves at most
J_REJECTIONS = 2     # rejections in a row after which it is renewed


def ring_colours(n, closed, reach=2):
    """Colours of pins 0..n-1 along a chain (closed: a ring) such that pins of one colour are
    at least reach + 1 apart (reach 2: neither neighbours nor sharing a neighbour). Runs of
    0, 1, .., reach (a chain: all of them), on a ring whose length they do not divide ending
    in enough runs one longer (0, .., reach + 1): reach + 2 colours, the fewest such a ring
    takes (the greedy colouring below, the fallback, took 5 for the closed track's 65 pins)."""
    p = reach + 1
    q, rem = divmod(n, p)
    if not closed or rem == 0 or q >= rem:
        sizes = [p] * (q - (rem if closed else 0)) + ([p + 1] * rem if closed else [rem] if rem else [])
        colour = [c for size in sizes for c in range(size)]
        return _groups(colour)
    colour = []
    for b in range(n):
        near = range(1, reach + 1)
        taken = {colour[b - d] for d in near if b - d >= 0}
        if closed:
            taken |= {colour[(b + d) % n] for d in near if (b + d) % n < b}
        colour.append(min(set(range(2 * reach + 1)) - taken))
    return _groups(colour)


def _groups(colour):
    """(n_colours, n_per) pins of each colour, -1 padded."""
    n_col = max(colour) + 1
    groups = [[b for b, c_b in enumerate(colour) if c_b == c] for c in range(n_col)]
    out = np.full((n_col, max(len(g) for g in groups)), -1, dtype=np.int64)
    for c, g in enumerate(groups):
        out[c, : len(g)] = g
    return out


def jacobian_work(model, ny):
    """The blocks of the model's free pins (the closed track's every pin, the paper's pins
    1..n-1) and the scratch of the finite differences and factors."""
    nq = model.nq
    n_pins = model.n_links if model.closed else model.n_links - 1
    bristles = model.has_bristles   # the bristle's deflection z joins its pin's block
    blk = np.empty((n_pins, 5 if bristles else 4), dtype=np.int64)
    for i in range(n_pins):
        k = L.q_pin(model.nw, i + 1)
        blk[i, :4] = (k, k + 1, nq + k, nq + k + 1)
        if bristles:
            blk[i, 4] = L.bristle_state(nq, i + 1)
    in_block = set(blk[:, :N_KINEMATIC].ravel().tolist())
    free = np.array([k for k in range(nq) if k not in in_block], dtype=np.int64)
    nb = blk.shape[1]
    scale = np.array([0.0, 0.0, SCALE_VELOCITY, SCALE_VELOCITY, SCALE_DEFLECTION][:nb])
    return JacobianWork(blk, ring_colours(n_pins, model.closed), free, scale, np.zeros((n_pins, nb, nb)),
                        np.zeros((n_pins, nb, nb)), np.zeros((n_pins, nb), dtype=np.int64), np.zeros(n_pins),
                        np.empty(ny), np.empty(ny), np.empty(nb))


@njit(**INLINE)
def _perturb(y, jw, pins, j):
    """jw.yp = y with component j of every pin in `pins` moved by a step sized to it; the step
    actually taken (a difference of two doubles) into jw.dlt."""
    copy_into(jw.yp, 0, y)
    for i in range(pins.shape[0]):
        b = pins[i]
        if b < 0:
            break
        k = jw.blk[b, j]
        d = SQRT_EPS * max(abs(y[k]), jw.scale[j])
        jw.yp[k] = y[k] + d
        jw.dlt[b] = jw.yp[k] - y[k]


@njit(**BORROW)
def pin_jacobian(y, f0, m, w, jw, diag):
    """The pins' blocks of J at (y, f0 = f(y)) by forward differences; returns the number of
    right-hand sides it took. Leaves w as evaluated at a perturbed state: call it before a
    step's stages, never between the step's end and the memories' moves. f0 must be f with the
    memories as they are now: not the last step's f(y_new) once the soil's memory has moved
    after it (each difference would carry the memory's jump over a 1e-9 perturbation)."""
    blk, jac, nb = jw.blk, jw.jac, jw.blk.shape[1]
    for b in range(blk.shape[0]):
        for r in range(N_KINEMATIC):
            for j in range(nb):
                jac[b, r, j] = 1.0 if j == r + N_KINEMATIC else 0.0
    n = 0
    for c in range(jw.colours.shape[0]):
        pins = jw.colours[c]
        for j in range(nb):
            if jw.scale[j] == 0.0:
                for b in range(blk.shape[0]):
                    for r in range(N_KINEMATIC, nb):
                        jac[b, r, j] = 0.0
                continue
            _perturb(y, jw, pins, j)
            rhs(jw.yp, m, w, jw.fp, diag)
            n += 1
            for i in range(pins.shape[0]):
                b = pins[i]
                if b < 0:
                    break
                for r in range(N_KINEMATIC, nb):
                    k = blk[b, r]
                    jac[b, r, j] = (jw.fp[k] - f0[k]) / jw.dlt[b]
    return n


@njit(**BORROW)
def factor(hg, jw):
    """LU factors (partial pivoting, a fixed order) of each block of I / (h gamma) - J."""
    lu, piv, nb = jw.lu, jw.piv, jw.blk.shape[1]
    for b in range(lu.shape[0]):
        for r in range(nb):
            for j in range(nb):
                lu[b, r, j] = (1.0 / hg if r == j else 0.0) - jw.jac[b, r, j]
        for col in range(nb):
            p = col
            for r in range(col + 1, nb):
                if abs(lu[b, r, col]) > abs(lu[b, p, col]):
                    p = r
            piv[b, col] = p
            if p != col:
                for j in range(nb):
                    lu[b, col, j], lu[b, p, j] = lu[b, p, j], lu[b, col, j]
            for r in range(col + 1, nb):
                lu[b, r, col] /= lu[b, col, col]
                for j in range(col + 1, nb):
                    lu[b, r, j] -= lu[b, r, col] * lu[b, col, j]


@njit(**INLINE)
def _block_solve(b, jw, rb):
    """rb <- (block b of I / (h gamma) - J)^-1 rb, from its factors."""
    lu, piv, nb = jw.lu, jw.piv, rb.shape[0]
    for col in range(nb):
        p = piv[b, col]
        if p != col:
            rb[col], rb[p] = rb[p], rb[col]
        for r in range(col + 1, nb):
            rb[r] -= lu[b, r, col] * rb[col]
    for r in range(nb - 1, -1, -1):
        s = rb[r]
        for j in range(r + 1, nb):
            s -= lu[b, r, j] * rb[j]
        rb[r] = s / lu[b, r, r]


@njit(**BORROW)
def times_j(nq, jw, z, out):
    """out = J z (the pins' blocks, the kinematic identity elsewhere, 0 after (q, qd))."""
    for k in range(nq):
        out[k] = z[nq + k]
    for k in range(nq, out.shape[0]):
        out[k] = 0.0
    blk, nb = jw.blk, jw.blk.shape[1]
    for b in range(blk.shape[0]):
        for r in range(N_KINEMATIC, nb):
            s = 0.0
            for j in range(nb):
                s += jw.jac[b, r, j] * z[blk[b, j]]
            out[blk[b, r]] = s


@njit(**BORROW)
def solve(hg, nq, jw, r, u):
    """u = (I / (h gamma) - J)^-1 r: the pins' blocks from their factors; every other
    coordinate with J's kinematic identity only (u_qd = h gamma r_qd, u_q = h gamma (r_q +
    u_qd)); the first-order components after (q, qd) with J = 0."""
    for k in range(2 * nq, r.shape[0]):
        u[k] = hg * r[k]
    for i in range(jw.free.shape[0]):
        k = jw.free[i]
        u[nq + k] = hg * r[nq + k]
        u[k] = hg * (r[k] + u[nq + k])
    blk, rb, nb = jw.blk, jw.rb, jw.blk.shape[1]
    for b in range(blk.shape[0]):
        for j in range(nb):
            rb[j] = r[blk[b, j]]
        _block_solve(b, jw, rb)
        for j in range(nb):
            u[blk[b, j]] = rb[j]


# --- The same solve by the blocks' structure (the Rosenbrock-W loop's) ------------------------
# A block of J is [[0, I, 0], [0, D]] over (x, y | vx, vy (| z)): its position columns are 0
# (scale 0: not differenced) and its position rows the kinematic identity. So (I / (h gamma) -
# J) u = r is (I / (h gamma) - D) u_v = r_v, then u_x = h gamma (r_x + u_v): an LU of the
# (nb - 2)-square velocity part D (a 2x2 one inverted outright), a fraction of the whole
# block's work.


@njit(**BORROW)
def factor_velocities(hg, jw):
    """Each block's velocity part I / (h gamma) - D, in rows and columns N_KINEMATIC.. of jw.lu:
    a 2x2 part (no bristles) as its inverse; a larger one as LU factors (partial pivoting, a
    fixed order)."""
    lu, piv, nb = jw.lu, jw.piv, jw.blk.shape[1]
    k = N_KINEMATIC
    for b in range(lu.shape[0]):
        for r in range(N_KINEMATIC, nb):
            for j in range(N_KINEMATIC, nb):
                lu[b, r, j] = (1.0 / hg if r == j else 0.0) - jw.jac[b, r, j]
        if nb == k + 2:
            a, c, d, e = lu[b, k, k], lu[b, k, k + 1], lu[b, k + 1, k], lu[b, k + 1, k + 1]
            det = a * e - c * d
            lu[b, k, k], lu[b, k, k + 1] = e / det, -c / det
            lu[b, k + 1, k], lu[b, k + 1, k + 1] = -d / det, a / det
            continue
        for col in range(N_KINEMATIC, nb):
            p = col
            for r in range(col + 1, nb):
                if abs(lu[b, r, col]) > abs(lu[b, p, col]):
                    p = r
            piv[b, col] = p
            if p != col:
                for j in range(N_KINEMATIC, nb):
                    lu[b, col, j], lu[b, p, j] = lu[b, p, j], lu[b, col, j]
            for r in range(col + 1, nb):
                lu[b, r, col] /= lu[b, col, col]
                for j in range(col + 1, nb):
                    lu[b, r, j] -= lu[b, r, col] * lu[b, col, j]


@njit(**BORROW)
def solve_velocities(hg, nq, jw, r, u):
    """u = (I / (h gamma) - J)^-1 r as solve(), each block by its velocity part's factors
    (factor_velocities), then its positions."""
    for k in range(2 * nq, r.shape[0]):
        u[k] = hg * r[k]
    for i in range(jw.free.shape[0]):
        k = jw.free[i]
        u[nq + k] = hg * r[nq + k]
        u[k] = hg * (r[k] + u[nq + k])
    blk, rb, lu, piv, nb = jw.blk, jw.rb, jw.lu, jw.piv, jw.blk.shape[1]
    k = N_KINEMATIC
    if nb == k + 2:   # the inverses of factor_velocities
        for b in range(blk.shape[0]):
            ix, iy, ivx, ivy = blk[b, 0], blk[b, 1], blk[b, k], blk[b, k + 1]
            vx = lu[b, k, k] * r[ivx] + lu[b, k, k + 1] * r[ivy]
            vy = lu[b, k + 1, k] * r[ivx] + lu[b, k + 1, k + 1] * r[ivy]
            u[ivx], u[ivy] = vx, vy
            u[ix], u[iy] = hg * (r[ix] + vx), hg * (r[iy] + vy)
        return
    for b in range(blk.shape[0]):
        for j in range(N_KINEMATIC, nb):
            rb[j] = r[blk[b, j]]
        for col in range(N_KINEMATIC, nb):
            p = piv[b, col]
            if p != col:
                rb[col], rb[p] = rb[p], rb[col]
            for i in range(col + 1, nb):
                rb[i] -= lu[b, i, col] * rb[col]
        for i in range(nb - 1, N_KINEMATIC - 1, -1):
            s = rb[i]
            for j in range(i + 1, nb):
                s -= lu[b, i, j] * rb[j]
            rb[i] = s / lu[b, i, i]
        for j in range(N_KINEMATIC, nb):
            u[blk[b, j]] = rb[j]
        for j in range(N_KINEMATIC):
            u[blk[b, j]] = hg * (r[blk[b, j]] + rb[j + N_KINEMATIC])
