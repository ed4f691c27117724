"""Exponential Rosenbrock methods on the closed, driven track, in Python: the true one-step
error of each method against 400 DOPRI5 substeps beside its own estimate, and the steps a
window takes with a plain controller. Prints figures; asserts nothing; takes a few minutes.

The methods (Hochbruck, Ostermann & Schweitzer, "Exponential Rosenbrock-type methods", SIAM
J. Numer. Anal. 47 (2009) 786-803): with J the pins' block Jacobian at the step's start
(common/pin_jacobian.py: one 4x4 block per pin over x, y, vx, vy, the kinematic identity
elsewhere; renewed every step), g(u) = f(u) - J u and D_i = g(U_i) - g(y),

    exprb32:  U2 = y + h phi1(hJ) f(y),   y_new = U2 + 2 h phi3(hJ) D2;   estimate 2 h phi3(hJ) D2
    exprb43:  U2 = y + h/2 phi1(hJ/2) f(y),   U3 = y + h phi1(hJ) (f(y) + D2),
              y_new = y + h phi1 f(y) + h phi3 (16 D2 - 2 D3) + h phi4 (-48 D2 + 12 D3);
              estimate h phi4(hJ) (-48 D2 + 12 D3) (the order-3 solution drops the phi4 terms)

beside DOPRI5, ARK5(4)8L[2]SA (step_profile.py) and Cox & Matthews' ETDRK4 with the same
blocks (velocity block symmetrised) as a fixed linear part. The phi functions of each pin's
block come from the exponential of an augmented matrix (scipy); the coordinates without a
block have the nilpotent [[0, 1], [0, 0]].

A method name ending in x takes the whole Jacobian f'(y) (forward differences of every
column) as J, in p only the pins' rows and columns of it, in b every pin's own block and the
bodies' rows and columns (no coupling between pins): exprb43x, exprb43p, exprb43b.

    python benchmarks/exprb_profile.py                       # one step from 0.20 s and 0.35 s
    python benchmarks/exprb_profile.py one --starts 0.35 --advance 2.5e-6 --where
    python benchmarks/exprb_profile.py one --methods exprb43,exprb43x,exprb43p,exprb43b
    python benchmarks/exprb_profile.py window --start 0.20 --window 0.03
    python benchmarks/exprb_profile.py one --blocks full     # J's position columns differenced too
"""

import argparse
import math

import numpy as np
import scipy.linalg
from step_profile import Window, _scaled, ark_step, dopri5_step

from trackbench.solvers.common import pin_jacobian as PJ
from trackbench.solvers.common.control import FAC_MIN, SAFETY
from trackbench.solvers.imex.ark_tableau import ARK_TABLEAUS
from trackbench.solvers.rk.tableau import TABLEAUS

K_PHI = 4   # phi_0 .. phi_4
DOPRI5 = TABLEAUS["dopri5"].arrays()
ARK5 = ARK_TABLEAUS["ark548l2sa"].arrays()


class Linear:
    """A linear operator: each pin's 4x4 block, the kinematic identity on every other (q, qd)
    pair, 0 on the rest; its phi functions applied to vectors."""

    def __init__(self, w, blocks):
        self.nq, self.blk, self.free, self.J = w.nq, w.jw.blk[:, :4], w.jw.free, blocks
        self.cache = {}

    def times(self, x):
        out = np.zeros_like(x)
        out[: self.nq] = x[self.nq: 2 * self.nq]
        out[self.blk[:, 2:]] = np.einsum("nij,nj->ni", self.J[:, 2:, :], x[self.blk])
        return out

    def _phis(self, eta):
        if eta not in self.cache:
            n, m = self.J.shape[0], 4 * (K_PHI + 1)
            M = np.zeros((n, m, m))
            M[:, :4, :4] = eta * self.J
            for i in range(K_PHI):
                M[:, 4 * i: 4 * i + 4, 4 * i + 4: 4 * i + 8] = np.eye(4)
            E = scipy.linalg.expm(M)
            self.cache[eta] = np.stack([E[:, :4, 4 * k: 4 * k + 4] for k in range(K_PHI + 1)], axis=1)
        return self.cache[eta]

    def phi(self, k, eta, x):
        """phi_k(eta L) x."""
        out = x / math.factorial(k)
        q = self.free
        out[q] += eta * x[self.nq + q] / math.factorial(k + 1)
        out[self.blk] = np.einsum("nij,nj->ni", self._phis(eta)[:, k], x[self.blk])
        return out


class DenseLinear:
    """The whole Jacobian f'(y) (forward differences, ny right-hand sides) and its phi
    functions: what the methods' order asks for, too dear for a run, measured on one step."""

    def __init__(self, w, y, f0, part="x"):
        n = y.size
        self.J = np.empty((n, n))
        for j in range(n):
            yp = y.copy()
            yp[j] += PJ.SQRT_EPS * max(abs(y[j]), 1e-3 if j < w.nq else 1e-1)
            self.J[:, j] = (w.f(yp) - f0) / (yp[j] - y[j])
        if part == "b":   # every pin's own block and the bodies' rows and columns; no pin-pin coupling
            pin = np.full(n, -1)
            for b in range(w.jw.blk.shape[0]):
                pin[w.jw.blk[b, :4]] = b
            between = (pin[:, None] >= 0) & (pin[None, :] >= 0) & (pin[:, None] != pin[None, :])
            self.J[between] = 0.0
        if part == "p":   # the pins' rows and columns (their coupling too); the kinematic identity elsewhere
            keep = np.zeros(n, dtype=bool)
            keep[w.jw.blk[:, 2:].ravel()] = True
            kin = self.J[: w.nq].copy()
            self.J[~keep, :] = 0.0
            self.J[:, ~np.isin(np.arange(n), w.jw.blk[:, :4].ravel())] = 0.0
            self.J[: w.nq] = kin
        self.cache = {}

    def times(self, x):
        return self.J @ x

    def phi(self, k, eta, x):
        if eta not in self.cache:
            n = self.J.shape[0]
            M = np.zeros(((K_PHI + 1) * n, (K_PHI + 1) * n))
            M[:n, :n] = eta * self.J
            for i in range(K_PHI):
                M[i * n: i * n + n, i * n + n: i * n + 2 * n] = np.eye(n)
            self.cache[eta] = scipy.linalg.expm(M)[:n]
        n = self.J.shape[0]
        return self.cache[eta][:, k * n: k * n + n] @ x


def blocks(w, y, f0, full=False):
    """The pins' blocks of f' at y (velocity columns; with `full` the position columns too)."""
    scale = w.jw.scale.copy()
    if full:
        w.jw.scale[:2] = 1.0
    n = PJ.pin_jacobian(y, f0, w.model.arrays, w.model.work, w.jw, w.diag)
    w.jw.scale[:] = scale
    return w.jw.jac[:, :4, :4].copy(), n


def symmetrised(J):
    S = J.copy()
    S[:, :, :2] = 0.0
    off = 0.5 * (J[:, 2, 3] + J[:, 3, 2])
    S[:, 2, 3] = S[:, 3, 2] = off
    return S


def exprb32_step(w, y, f0, h, lin):
    U2 = y + h * lin.phi(1, h, f0)
    D2 = w.f(U2) - f0 - lin.times(U2 - y)
    er = 2.0 * h * lin.phi(3, h, D2)
    yn = U2 + er
    return yn, w.f(yn), er, 2


def exprb43_step(w, y, f0, h, lin):
    U2 = y + 0.5 * h * lin.phi(1, 0.5 * h, f0)
    D2 = w.f(U2) - f0 - lin.times(U2 - y)
    U3 = y + h * lin.phi(1, h, f0 + D2)
    D3 = w.f(U3) - f0 - lin.times(U3 - y)
    er = h * lin.phi(4, h, -48.0 * D2 + 12.0 * D3)
    yn = y + h * lin.phi(1, h, f0) + h * lin.phi(3, h, 16.0 * D2 - 2.0 * D3) + er
    return yn, w.f(yn), er, 3


def etdrk4_step(w, y, f0, h, lin):
    """Cox & Matthews' ETDRK4, N = f - L y; the estimate with N(y_new) in place of N(c)."""
    def N(x, fx=None):
        return (w.f(x) if fx is None else fx) - lin.times(x)

    hh = 0.5 * h
    n0 = N(y, f0)
    a = lin.phi(0, hh, y) + hh * lin.phi(1, hh, n0)
    na = N(a)
    b = lin.phi(0, hh, y) + hh * lin.phi(1, hh, na)
    nb = N(b)
    c = lin.phi(0, hh, a) + hh * lin.phi(1, hh, 2.0 * nb - n0)
    nc = N(c)

    def F(k, x):
        return sum(wt * lin.phi(j, h, x) for j, wt in k)

    f1, f2, f3 = ((1, 1.0), (2, -3.0), (3, 4.0)), ((2, 1.0), (3, -2.0)), ((2, -1.0), (3, 4.0))
    yn = lin.phi(0, h, y) + h * (F(f1, n0) + 2.0 * F(f2, na + nb) + F(f3, nc))
    fn = w.f(yn)
    er = h * F(f3, nc - N(yn, fn))
    return yn, fn, er, 4


EXPONENTIAL = {"exprb32": (exprb32_step, -1.0 / 3.0), "exprb43": (exprb43_step, -0.25),
               "etdrk4": (etdrk4_step, -0.25), "etdrk4j": (etdrk4_step, -0.25)}
SYMMETRISED = ("etdrk4",)   # L's velocity blocks symmetrised; "etdrk4j": J's blocks as they are


def norm(w, y, yn, e, tol):
    return float(np.sqrt(_scaled(w, y, yn, e, tol).mean()))


def reference(w, y, f0, h, n=400):
    for _ in range(n):
        y, f0, _ = dopri5_step(w, y, f0, h / n, 1.0, DOPRI5)
    return y


def one_step(w, method, y, f0, h, tol, full):
    """(y_new, the estimate's norm) of one step of `method` from y."""
    if method == "dopri5":
        yn, _, r = dopri5_step(w, y, f0, h, tol, DOPRI5)
        return yn, float(np.sqrt(r.mean()))
    if method == "ark548l2sa":
        blocks(w, y, f0)
        yn, _, r = ark_step(w, y, f0, h, tol, ARK5)
        return yn, float(np.sqrt(r.mean()))
    if method[-1] in "xpb":   # the whole Jacobian (x), the pins' part of it (p), no pin-pin coupling (b)
        lin = DenseLinear(w, y, f0, method[-1])
        yn, _, er, _ = EXPONENTIAL[method[:-1]][0](w, y, f0, h, lin)
        return yn, norm(w, y, yn, er, tol)
    J, _ = blocks(w, y, f0, full and method not in SYMMETRISED)
    lin = Linear(w, symmetrised(J) if method in SYMMETRISED else J)
    yn, _, er, _ = EXPONENTIAL[method][0](w, y, f0, h, lin)
    return yn, norm(w, y, yn, er, tol)


def largest(w, y, yn, e, tol):
    """The share of the squared norm in each kind of component, the largest two."""
    r = _scaled(w, y, yn, e, tol)
    shares = {}
    for k in np.argsort(r)[::-1][:40]:
        what = w.kind(int(k), yn)
        shares[what] = shares.get(what, 0.0) + r[k] / r.sum()
    top = sorted(shares.items(), key=lambda kv: -kv[1])[:2]
    return ", ".join(f"{what} {s:.0%}" for what, s in top)


def one_step_table(starts, steps, methods, tol, full, overrides, show_where=False, advance=0.0):
    print(f"one step, normalised as the error norm at tolerance {tol:g} (true / estimate); "
          f"blocks: {'full' if full else 'velocity columns'}")
    print("| start | step | " + " | ".join(methods) + " |\n| --- | --- |" + " --- |" * len(methods))
    for start in starts:
        w = Window(overrides, start)
        y = w.y0
        f0 = w.f(y)
        if advance > 0.0:   # past a contact switch just after the sample: 400 DOPRI5 substeps
            y = w.y0 = reference(w, y, f0, advance)
            f0 = w.f(y)
            start += advance
        for h in steps:
            ref = reference(w, y, f0, h)
            cells, where = [], []
            for m in methods:
                yn, est = one_step(w, m, y, f0, h, tol, full)
                cells.append(f"{norm(w, y, ref, yn - ref, tol):.3g} / {est:.3g}")
                where.append(f"{m}: {largest(w, y, ref, yn - ref, tol)}")
            print(f"| {start:.7g} s | {h:.0e} s | " + " | ".join(cells) + " |", flush=True)
            if show_where:
                print("    " + "; ".join(where))


def window(w, method, span, tol, full):
    """Accepted and rejected steps, right-hand sides and step sizes over `span` from the
    window's start, J renewed every attempt, the plain controller (no event location)."""
    dense = method[-1] in "xpb"
    step, expo = EXPONENTIAL[method[:-1] if dense else method]
    y, h, t = w.y0.copy(), 1e-6, 0.0
    f0 = w.f(y)
    hs, rejected, n_rhs = [], 0, 1
    while t < span * (1.0 - 1e-12):
        h = min(h, span - t)
        if dense:
            lin, nj = DenseLinear(w, y, f0, method[-1]), y.size
        else:
            J, nj = blocks(w, y, f0, full)
            lin = Linear(w, symmetrised(J) if method in SYMMETRISED else J)
        yn, fn, er, ns = step(w, y, f0, h, lin)
        n_rhs += nj + ns
        err = norm(w, y, yn, er, tol)
        fac = SAFETY * err ** expo if err > 0 else 10.0
        if not err <= 1.0:
            rejected += 1
            h *= max(FAC_MIN, fac)
            continue
        hs.append(h)
        t, y, f0 = t + h, yn, fn
        h *= min(10.0, fac)
    return np.array(hs), rejected, n_rhs


def window_table(start, span, methods, tol, full, overrides):
    from step_profile import profile
    w = Window(overrides, start)
    print(f"window {start:.4g}-{start + span:.4g} s, tolerance {tol:g}, blocks "
          f"{'full' if full else 'velocity columns'}")
    print("| method | accepted | rejected | right-hand sides | median step | 10-90 % |\n"
          "| --- | --- | --- | --- | --- | --- |")
    for m in methods:
        if m in ("dopri5", "ark548l2sa"):
            _, hs, rej = profile(w, m, span, tol)
            n_rhs = None
        else:
            hs, rej, n_rhs = window(w, m, span, tol, full)
        print(f"| {m} | {hs.size} | {rej} | {n_rhs if n_rhs else '-'} | {np.median(hs):.2e} | "
              f"{np.percentile(hs, 10):.2e}-{np.percentile(hs, 90):.2e} |", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("part", nargs="?", default="one", choices=("one", "window"))
    ap.add_argument("--starts", default="0.20,0.35")
    ap.add_argument("--steps", default="1e-5,2e-5,4e-5,8e-5")
    ap.add_argument("--start", type=float, default=0.20)
    ap.add_argument("--window", type=float, default=0.03)
    ap.add_argument("--tolerance", type=float, default=1e-7)
    ap.add_argument("--methods", default=None)
    ap.add_argument("--blocks", default="velocity", choices=("velocity", "full"))
    ap.add_argument("--advance", type=float, default=0.0, help="s: start this long after each start")
    ap.add_argument("--where", action="store_true", help="the kinds of component carrying each error")
    a = ap.parse_args()
    full = a.blocks == "full"
    if a.part == "one":
        methods = (a.methods or "dopri5,ark548l2sa,etdrk4,exprb32,exprb43").split(",")
        one_step_table([float(s) for s in a.starts.split(",")], [float(s) for s in a.steps.split(",")],
                       methods, a.tolerance, full, {}, a.where, a.advance)
    else:
        methods = (a.methods or "dopri5,exprb32,exprb43").split(",")
        window_table(a.start, a.window, methods, a.tolerance, full, {})


if __name__ == "__main__":
    main()
