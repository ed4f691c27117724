"""Cost of the damped preset and of the continuous contact geometry against the paper's
model on paper_step (0.5 s), measured side by side in one process: the variants
alternate, and each figure is the best of REPEATS.
Prints figures; asserts nothing.

    python benchmarks/bench_damping.py
"""

import sys

import trackbench as tb

REPEATS = 7


def main():
    variants = {
        "paper": tb.Scenario.paper(),
        "damped": tb.Scenario.paper(preset="damped"),
        "continuous": tb.Scenario.paper(**{"contact.geometry": "continuous"}),
    }
    for sc in variants.values():
        tb.simulate(sc.with_overrides({"duration": 0.02}))  # compiled / loaded before timing
    best = {k: float("inf") for k in variants}
    runs = {}
    for _ in range(REPEATS):
        for name, sc in variants.items():
            ds = tb.simulate(sc)
            runs[name] = ds
            best[name] = min(best[name], ds.attrs["solve_time"])
    for name, ds in runs.items():
        a = ds.attrs
        print(
            f"{name:10s} solve {best[name]:.4f} s (best of {REPEATS})  steps {a['steps']} "
            f"(+{a['rejected_steps']} rejected)  rhs {a['rhs_evaluations']}  residual "
            f"{float(ds.max_energy_residual):.1e}"
        )
    print(f"damped / paper: {best['damped'] / best['paper']:.2f}  (target: at most 1.2)")
    print(f"continuous / paper: {best['continuous'] / best['paper']:.2f}")


if __name__ == "__main__":
    main(*sys.argv[1:])
