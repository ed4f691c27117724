"""Cost of rough ground against flat ground for the driven vehicle (damped, closed track, mu
0.6, speed drive 5 m/s, 2 s; the rough ground ISO 8608 class D after a 5 m run-in, so the
last 1.5 s run on it), measured side by side in one process: the variants alternate, each
figure the best of REPEATS. Also the candidate rows' memory on a 600 m course, which a row
per ground segment would have made 2 GB an array. Prints figures; asserts nothing.

    python benchmarks/bench_rough.py [--repeats N]
"""

import argparse

import trackbench as tb
from trackbench.run.assemble import Model, equilibrium
from trackbench.run.simulate import build_ground

BASE = {"preset": "damped", "track.layout": "closed", "drive.kind": "speed", "contact.friction": 0.6,
        "speed": 5.0, "duration": 2.0, "output_interval": 1e-3}
ROUGH = {"kind": "random", "roughness_class": "D", "run_in": 5.0}


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    variants = {"flat": tb.Scenario.from_dict({**BASE, "terrain": {"kind": "flat"}}),
                "rough": tb.Scenario.from_dict({**BASE, "terrain": ROUGH})}
    # compiled / loaded before timing (on flat ground: 0.02 s would not reach the rough ground)
    tb.simulate(variants["flat"].with_overrides({"duration": 0.02}))
    best, runs = {k: float("inf") for k in variants}, {}
    for _ in range(args.repeats):
        for name, sc in variants.items():
            runs[name] = tb.simulate(sc)
            best[name] = min(best[name], runs[name].attrs["solve_time"])
    for name, ds in runs.items():
        a = ds.attrs
        print(f"{name:6s} solve {best[name]:.3f} s (best of {args.repeats}, {best[name] / 2.0:.2f} wall / "
              f"sim)  steps {a['steps']} (+{a['rejected_steps']} rejected)  ground segments "
              f"{ds.sizes['ground_vertex'] - 1}")
    per_step = {k: best[k] / runs[k].attrs["steps"] for k in runs}
    print(f"rough / flat: {best['rough'] / best['flat']:.2f}   per step: "
          f"{per_step['rough'] / per_step['flat']:.2f}")
    sc = tb.Scenario.paper(terrain={**ROUGH, "length": 600.0})
    eq = equilibrium(sc)
    ground, _ = build_ground(sc, eq)
    m = Model(sc, eq, ground).arrays
    rows = m.nbr.nbytes + m.v0.nbytes
    full = m.nbr.shape[0] * ground.segments.shape[0] * 16 / 1e9
    print(f"600 m course: {ground.segments.shape[0]} segments, candidate rows and their memory "
          f"{rows / 1e6:.0f} MB (a row per segment: {full:.1f} GB)")


if __name__ == "__main__":
    main()
