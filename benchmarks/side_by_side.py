"""Wall times of scenarios run side by side: the variants alternate round after round (so
that a busy spell of this shared machine hits them alike), each figure the best of `repeats`."""

import time

import numpy as np

import trackbench as tb


def best_walls(variants, repeats):
    """{name: best whole-call wall time (s)} of {name: Scenario}; each variant compiled and
    loaded first (a 0.02 s run), every run printed."""
    for sc in variants.values():
        tb.simulate(sc.with_overrides({"duration": 0.02}))
    best = {k: np.inf for k in variants}
    for _ in range(repeats):
        for name, sc in variants.items():
            t = time.perf_counter()
            ds = tb.simulate(sc)
            wall = time.perf_counter() - t
            best[name] = min(best[name], wall)
            print(
                f"  {name}: {wall:.2f} s wall, solve {ds.attrs['solve_time']:.2f} s, steps "
                f"{ds.attrs['steps']} (+{ds.attrs['rejected_steps']} rejected), {ds.attrs['status']}"
            )
    return best


def against_the_paper(variants, repeats, bar=4.0):
    """Wall / simulated time of each of {name: Scenario} beside the paper's model (paper_step at
    its defaults), run alternately in this process, best of `repeats`; a table of the ratios
    against the bar (docs/benchmarks.md: at most 4x the paper model's)."""
    paper = "the paper's model"
    scs = {paper: tb.Scenario.paper(), **variants}
    best = best_walls(scs, repeats)
    base = best[paper] / scs[paper]["duration"]
    print(f"\n| run | wall / simulated | / the paper model's | bar {bar:g}x |\n| --- | --- | --- | --- |")
    for name, sc in scs.items():
        ratio = best[name] / sc["duration"]
        met = "" if name == paper else ("met" if ratio / base <= bar else "**not met**")
        print(f"| {name} | {ratio:.3f} | {ratio / base:.1f}x | {met} |")
    return best
