"""Speed of the core solver on paper_step (0.5 s simulated). Prints figures; asserts nothing.

    python benchmarks/bench_core.py [--quick]

1. cold and warm start of a whole run in a fresh process (empty / filled numba cache);
2. paper_step at the default settings after warm-up: wall time, simulated s per wall s,
   steps, right-hand sides, time per right-hand side (compiled loop on a mid-run state);
3. the same compiled right-hand side driven by scipy's solve_ivp (DOP853 and RK45) at
   the same tolerance, side by side with trackbench's own loop;
4. a work-precision table, tolerance 1e-6 .. 1e-11, errors against the tightest run.
"""

import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from numba import njit

import trackbench as tb
from trackbench.model.core import indices as L
from trackbench.model.dynamics.reduced import reduced_rhs
from trackbench.run.simulate import Model, build_ground, equilibrium, initial_state

REPEATS = 3


def fresh_process_seconds(cache_dir):
    code = "import trackbench as tb; tb.simulate(tb.Scenario.paper())"
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    t = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True, env=env)
    return time.perf_counter() - t


@njit(cache=True)
def _rhs_loop(n, y, m, w, dy, d):
    for _ in range(n):
        reduced_rhs(y, m, w, dy, d)


def rhs_microseconds(ds, sc):
    """Time of one right-hand side on the state at 0.3 s (track wrapped over the step)."""
    eq = equilibrium(sc)
    ground, _ = build_ground(sc, eq)
    m = Model(sc, eq, ground)
    nq = L.n_coordinates(m.nw, m.n_links)
    i = int(np.searchsorted(ds.time.values, 0.3))
    y = np.zeros(m.ny)
    y[[L.Q_X, L.Q_Y, L.Q_PITCH]] = [float(ds[v][i]) for v in ("chassis_x", "chassis_y", "chassis_pitch")]
    y[L.Q_ARM : L.Q_ARM + m.nw] = ds.arm_angle.values[i]
    off = L.pin_offset(m.nw)
    y[off:nq:2] = ds.pin_x.values[i, 1:-1]
    y[off + 1 : nq : 2] = ds.pin_y.values[i, 1:-1]
    y[nq] = 10.0
    y[nq + off : 2 * nq : 2] = 10.0
    dy = np.zeros_like(y)
    d = np.zeros(L.n_diag(m.nw, m.n_links))
    args = (m.arrays, m.work, dy, d)
    _rhs_loop(10, y, *args)
    n = 200_000
    best = np.inf
    for _ in range(REPEATS):
        t = time.perf_counter()
        _rhs_loop(n, y, *args)
        best = min(best, (time.perf_counter() - t) / n)
    return best * 1e6


def scipy_baseline(sc, method):
    """solve_ivp driving the same compiled right-hand side; returns (wall, steps, nfev)."""
    from scipy.integrate import solve_ivp

    eq = equilibrium(sc)
    ground, _ = build_ground(sc, eq)
    m = Model(sc, eq, ground)
    y0 = initial_state(sc, eq)
    d = np.zeros(L.n_diag(m.nw, m.n_links))
    args = (m.arrays, m.work)

    def f(t, y):
        dy = np.empty_like(y)
        reduced_rhs(y, *args, dy, d)
        return dy

    tol = sc["tolerance"]
    t = time.perf_counter()
    r = solve_ivp(
        f,
        (0.0, sc["duration"]),
        y0,
        method=method,
        rtol=tol,
        atol=tol,
        max_step=sc["output_interval"],
        first_step=1e-5,
        dense_output=False,
    )
    return time.perf_counter() - t, r.t.size - 1, r.nfev, r.status


def best_run(sc):
    best = None
    for _ in range(REPEATS):
        ds = tb.simulate(sc)
        if best is None or ds.attrs["solve_time"] < best.attrs["solve_time"]:
            best = ds
    return best


def main(quick=False):
    print("== start-up (fresh process, whole paper_step run) ==")
    with tempfile.TemporaryDirectory() as cache:
        cold = fresh_process_seconds(cache)
        warm = fresh_process_seconds(cache)
    print(f"cold (empty numba cache): {cold:6.2f} s   warm: {warm:6.2f} s   (targets 30 s / 3 s)")

    sc = tb.Scenario.paper()
    tb.simulate(sc.with_overrides({"duration": 0.02}))  # JIT warm-up
    print(f"\n== paper_step, default settings: {sc['method']}, tolerance {sc['tolerance']:g} ==")
    ds = best_run(sc)
    a = ds.attrs
    wall = a["solve_time"]
    print(
        f"wall {wall:.3f} s (best of {REPEATS})  simulated/wall {sc['duration'] / wall:.2f}  steps "
        f"{a['steps']} (+{a['rejected_steps']} rejected)  rhs {a['rhs_evaluations']}  "
        f"wall per rhs (loop included) {wall / a['rhs_evaluations'] * 1e6:.3f} us"
    )
    print(f"one right-hand side alone: {rhs_microseconds(ds, sc):.3f} us   (target < 1 us)")
    print(
        f"energy residual {float(ds.max_energy_residual):.2e}  energy balance "
        f"{100 * float(ds.max_energy_balance_error):.4f} %  peak wheel 1 "
        f"{float(ds.peak_wheel_force_y[0]) / 1e3:.2f} kN"
    )

    print("\n== trackbench loop vs scipy solve_ivp on the same compiled rhs, same tolerance ==")
    for method, ours in (("DOP853", "dop853"), ("RK45", "dopri5")):
        sco = sc.with_overrides({"method": ours})
        dso = best_run(sco)
        w, steps, nfev, status = scipy_baseline(sco, method)
        print(
            f"{method:7s} tol {sc['tolerance']:g}: trackbench {dso.attrs['solve_time']:.3f} s "
            f"({dso.attrs['steps']} steps, {dso.attrs['rhs_evaluations']} rhs)   solve_ivp {w:.2f} s "
            f"({steps} steps, {nfev} rhs, status {status})   ratio {w / dso.attrs['solve_time']:.1f}x"
        )

    print("\n== work-precision (0.5 s; errors against the tightest run of each method) ==")
    tols = [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11]
    if quick:
        tols = tols[1:4]
    for method in ("dopri5", "dop853"):
        runs = [best_run(sc.with_overrides({"method": method, "tolerance": t})) for t in tols]
        ref = runs[-1]
        p_ref = float(ref.peak_wheel_force_y[0])
        y_ref = float(ref.chassis_y.sel(time=0.2, method="nearest"))
        print(
            f"{method}: tol      wall[s]  steps  rejected  err peak wheel 1  err chassis_y(0.2)  "
            "energy residual  balance[%]"
        )
        for t, r in zip(tols, runs):
            ep = abs(float(r.peak_wheel_force_y[0]) - p_ref) / p_ref
            ey = abs(float(r.chassis_y.sel(time=0.2, method="nearest")) - y_ref)
            print(
                f"        {t:7.0e}  {r.attrs['solve_time']:7.3f}  {r.attrs['steps']:5d}  "
                f"{r.attrs['rejected_steps']:8d}  {ep:16.2e}  {ey:15.2e} m  "
                f"{float(r.max_energy_residual):15.2e}  {100 * float(r.max_energy_balance_error):9.4f}"
            )


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
