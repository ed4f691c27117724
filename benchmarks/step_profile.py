"""Where the step goes: which state component carries the error norm of the steps of a
run, for the explicit pair (DOPRI5), the IMEX pair (ARK5(4)8L[2]SA) and the Rosenbrock-W
method (ROS34PW2, its pins' velocities at its default multiple of the tolerance). Prints
figures; asserts nothing; takes a minute or two.

A copy of each method's step in Python (the compiled right-hand side and pin Jacobian, the
same tables and error norms, the plain controller of solvers/common/control.py without event
location) runs a window of the closed, driven track on paper_step from the compiled run's
state at its start, and records for every accepted step the component with the largest term
of the error norm: a pin's x or y velocity or position (the pin classed as on the ground,
stuck (|vx| < 0.05 m/s) or sliding, or off the ground), or a body coordinate.

    python benchmarks/step_profile.py                 # regularised friction, 0.20-0.23 s
    python benchmarks/step_profile.py --start 0.35 --window 0.02 --tolerance 1e-8
    python benchmarks/step_profile.py --set contact.friction_law=bristle
    python benchmarks/step_profile.py --methods ros34pw2 --tolerance 1e-6 --start 0.35 --window 0.05
"""

import argparse
import collections
import importlib

import numpy as np

import trackbench as tb
from trackbench.model.core import indices as L
from trackbench.model.dynamics.rhs import rhs
from trackbench.solvers.common import pin_jacobian as PJ
from trackbench.solvers.common.control import FAC_MIN, SAFETY
from trackbench.solvers.imex.ark_tableau import ARK_TABLEAUS
from trackbench.solvers.registry import SOLVERS, run_function
from trackbench.solvers.rk.tableau import TABLEAUS
from trackbench.solvers.rosenbrock import ros_run
from trackbench.solvers.rosenbrock.ros_tableau import ROS_TABLEAUS

S = importlib.import_module("trackbench.run.simulate")
CLOSED = {"track.layout": "closed", "preset": "damped", "contact.friction": 0.6,
          "drive.kind": "speed", "drive.target": 10.0}
GROUND_REACH = 0.05   # m: a pin this close above the ground's height under it counts as on it


class Window:
    """The model and the compiled run's state at `start`."""

    def __init__(self, overrides, start):
        sc = tb.Scenario.from_dict({**CLOSED, **overrides, "duration": start, "tolerance": 1e-9})
        eq = S.equilibrium(sc)
        self.ground, _ = S.build_ground(sc, eq)
        self.model = S.Model(sc, eq, self.ground)
        run = run_function("reduced", "dopri5")
        self.y0 = run(self.model, S.initial_state(sc, eq), SOLVERS["reduced"].controls(sc)).y[-1].copy()
        self.ny = self.y0.size
        self.nq = self.model.nq
        self.diag = np.empty(L.n_diag(self.model.nw, self.model.n_links))
        self.jw = PJ.jacobian_work(self.model, self.ny)
        self.pin_of = {}
        for b in range(self.jw.blk.shape[0]):
            for c, k in enumerate(self.jw.blk[b]):
                self.pin_of[k] = (b, "x y vx vy z".split()[c])

    def f(self, y):
        out = np.empty(self.ny)
        rhs(y, self.model.arrays, self.model.work, out, self.diag)
        return out

    def ground_y(self, x):
        v = np.asarray(self.ground.vertices)
        return np.interp(x, v[:, 0], v[:, 1])

    def kind(self, k, y):
        """Words for component k at state y."""
        if k not in self.pin_of:
            return "body " + ("velocity" if k >= self.nq else "position")
        b, comp = self.pin_of[k]
        ix = self.jw.blk[b, 0]
        on = y[ix + 1] - self.ground_y(y[ix]) < GROUND_REACH + 0.1
        place = ("pin on the ground, " + ("stuck" if abs(y[self.nq + ix]) < 0.05 else "sliding")) if on \
            else "pin off the ground"
        return f"{place}: {comp}"


def _scaled(w, y, yn, er, tol):
    """The squared terms of the error norm over (q, qd); tol a number or one per component."""
    sc = tol + tol * np.maximum(np.abs(y), np.abs(yn))
    return (er[: 2 * w.nq] / sc[: 2 * w.nq]) ** 2


def ros_step(w, y, f0, h, tol, tab):
    """ROS34PW2 as solvers/rosenbrock/ros_loop.py takes it (transformed variables, the
    velocity part's solve)."""
    s, hg = tab.m.size, h * tab.gamma
    PJ.factor_velocities(hg, w.jw)
    U = np.zeros((s, w.ny))
    for i in range(s):
        fi = f0 if i == 0 else w.f(y + tab.A[i, :i] @ U[:i])
        PJ.solve_velocities(hg, w.nq, w.jw, fi + tab.C[i, :i] @ U[:i] / h, U[i])
    yn = y + tab.m @ U
    return yn, w.f(yn), _scaled(w, y, yn, tab.e @ U, tol)


def dopri5_step(w, y, f0, h, tol, tab):
    K = np.zeros((tab.b.size + 1, w.ny))
    K[0] = f0
    for i in range(1, tab.b.size):
        K[i] = w.f(y + h * tab.A[i, :i] @ K[:i])
    yn = y + h * tab.b @ K[:-1]
    K[-1] = w.f(yn)
    return yn, K[-1], _scaled(w, y, yn, h * tab.e @ K, tol)


def ark_step(w, y, f0, h, tol, tab):
    s, hg = tab.b.size, h * tab.gamma
    PJ.factor(hg, w.jw)
    K, JZ = np.zeros((s, w.ny)), np.zeros((s, w.ny))
    K[0] = f0
    for i in range(1, s):
        r = (tab.AE[i, :i] @ K[:i] + tab.D[i, :i] @ JZ[:i]) / tab.gamma
        z = np.empty(w.ny)
        PJ.solve(hg, w.nq, w.jw, r, z)
        PJ.times_j(w.nq, w.jw, z, JZ[i])
        K[i] = w.f(y + z)
    yn = y + h * tab.b @ K
    er = np.empty(w.ny)
    PJ.solve(hg, w.nq, w.jw, h * (tab.b - tab.b_hat) @ K / hg, er)
    return yn, w.f(yn), _scaled(w, y, yn, er, tol)


def _method(method, w, tol):
    """(table, step, Jacobian age, tolerance per component) of a method: the Rosenbrock-W
    method's pins' velocities at its default multiple of tol (ros_run.PIN_VELOCITY_RATIO)."""
    if method in TABLEAUS:
        return TABLEAUS[method].arrays(), dopri5_step, None, tol
    if method in ARK_TABLEAUS:
        return ARK_TABLEAUS[method].arrays(), ark_step, PJ.J_AGE, tol
    tols = np.full(w.ny, tol)
    lo, hi = ros_run.pin_velocities(w.jw)
    tols[lo:hi] = ros_run.PIN_VELOCITY_RATIO * tol
    return ROS_TABLEAUS[method].arrays(), ros_step, ros_run.JACOBIAN_AGE, tols


def profile(w, method, window, tol):
    tab, step, j_age, tol = _method(method, w, tol)
    y, h, t = w.y0.copy(), 1e-6, 0.0
    f0 = w.f(y)
    counts, hs, rejected, age, in_row = collections.Counter(), [], 0, j_age, 0
    while t < window:
        if j_age is not None and (age >= j_age or in_row >= PJ.J_REJECTIONS):
            PJ.pin_jacobian(y, f0, w.model.arrays, w.model.work, w.jw, w.diag)
            age, in_row = 0, 0
        yn, fn, r = step(w, y, f0, h, tol, tab)
        err = np.sqrt(r.mean())
        fac = SAFETY * err ** tab.expo if err > 0 else 10.0
        if not err <= 1.0:
            rejected += 1
            in_row += 1 if age else 0
            h *= max(FAC_MIN, fac)
            continue
        counts[w.kind(int(np.argmax(r)), yn)] += 1
        hs.append(h)
        t, y, f0, age, in_row = t + h, yn, fn, (age or 0) + 1, 0
        h *= min(10.0, fac)
    return counts, np.array(hs), rejected


def _value(text):
    try:
        return float(text)
    except ValueError:
        return text


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--start", type=float, default=0.20)
    ap.add_argument("--window", type=float, default=0.03)
    ap.add_argument("--tolerance", type=float, default=1e-7)
    ap.add_argument("--methods", default="dopri5,ark548l2sa")
    ap.add_argument("--set", action="append", default=[], help="dotted.name=value")
    a = ap.parse_args()
    overrides = {k: _value(v) for k, v in (s.split("=", 1) for s in a.set)}
    w = Window(overrides, a.start)
    print(f"closed track {overrides or ''}, {a.start}-{a.start + a.window} s, tolerance {a.tolerance}")
    for method in a.methods.split(","):
        counts, hs, rejected = profile(w, method, a.window, a.tolerance)
        n = hs.size
        print(f"\n{method}: {n} accepted + {rejected} rejected steps ({n / a.window:,.0f} per second), "
              f"step median {np.median(hs):.2e} s (10-90 %: {np.percentile(hs, 10):.2e} to "
              f"{np.percentile(hs, 90):.2e})")
        print("| the error's largest term | accepted steps |\n| --- | --- |")
        for what, c in counts.most_common(8):
            print(f"| {what} | {c / n:.0%} |")


if __name__ == "__main__":
    main()
