"""Benchmark: the reduced and the lee solver on paper_step (0.5 s), in one process,
after a warm-up run of each (numba compilation and the equilibrium solve excluded).

    /work/venv/bin/python benchmarks/bench_lee.py [--repeat 3] [--duration 0.5]

Prints, per solver: best solve wall time over the repeats, accepted and rejected
steps, right-hand-side (track_loads) evaluations, and for lee the lambda iterations
per accepted step at each level; then the lee / reduced wall-time ratio (target <= 3).
"""

import argparse
import time

import trackbench as tb


def _solve_time(scenario):
    t = time.perf_counter()
    ds = tb.simulate(scenario)
    return time.perf_counter() - t, ds


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--duration", type=float, default=0.5)
    args = ap.parse_args(argv)
    scen = {
        "reduced": tb.Scenario.paper(duration=args.duration),
        "lee": tb.Scenario.paper(duration=args.duration, solver="lee"),
        "lee n=1": tb.Scenario.paper(duration=args.duration, solver="lee", **{"lee.accel_order": 1}),
        "lee A_n every step": tb.Scenario.paper(
            duration=args.duration, solver="lee", **{"lee.matrix_update_angle": 0.0}
        ),
    }
    for s in scen.values():  # warm-up: compile / load caches, solve the equilibrium
        tb.simulate(s.with_overrides({"duration": 0.01}))
    best = {}
    for name, s in scen.items():
        runs = [_solve_time(s) for _ in range(args.repeat)]
        wall = min(r[0] for r in runs)
        solve = min(float(r[1].attrs["solve_time"]) if "solve_time" in r[1].attrs else r[0] for r in runs)
        ds = runs[0][1]
        best[name] = wall
        steps = ds.attrs["steps"]
        line = (
            f"{name:18s} wall {wall:6.3f} s (solver {solve:6.3f} s)  status {ds.attrs['status']}  "
            f"steps {steps}  rejected {ds.attrs['rejected_steps']}  rhs "
            f"{ds.attrs.get('rhs_evaluations', '?')}"
        )
        print(line)
        if name.startswith("lee"):
            per = {
                lvl: float(ds[f"lee_total_iterations_{lvl}"]) / steps
                for lvl in ("position", "velocity", "acceleration")
            }
            print(
                f"         iterations per accepted step: position {per['position']:.3f}  "
                f"velocity {per['velocity']:.3f}  acceleration {per['acceleration']:.3f}  "
                f"(totals {int(ds['lee_total_iterations_position'])} / "
                f"{int(ds['lee_total_iterations_velocity'])} / "
                f"{int(ds['lee_total_iterations_acceleration'])}); RKN passes {int(ds['lee_step_passes'])}; "
                f"eps1 {float(ds['lee_eps1']):.4f}; A_n builds {int(ds['lee_matrix_builds'])}"
            )
    print(f"lee / reduced wall-time ratio: {best['lee'] / best['reduced']:.2f} (target <= 3)")
    for name in ("lee n=1", "lee A_n every step"):
        print(f"{name} / reduced wall-time ratio: {best[name] / best['reduced']:.2f}")


if __name__ == "__main__":
    main()
