"""The accuracy criterion of the driven models, judged as the model allows (docs/validation.md,
"Judging a driven run"): a reference ensemble per model, and a run passes when every summary peak
is where the ensemble says it can be. Used by bench_closed.py and bench_soil.py (their
`criterion` part) and tests/test_accuracy_criterion.py; prints tables, asserts nothing.

    python benchmarks/bench_closed.py criterion --methods ros34pw2,dopri5 --tolerances 1e-5,1e-6
    python benchmarks/bench_closed.py criterion --methods ros34pw2 --tolerances 1e-5 --pin-ratios 1,10

The reference ensemble: dopri5 at 1e-11, ENSEMBLE runs each with every free pin nudged by a
seeded uniform amount in [-1e-7, 1e-7] m (`perturbation = 1e-7`, seeds 1-8, as a study's
replicates are). For each summary peak (quantities.py kind "peak": wheel forces, ground force,
link tensions, chassis accelerations, least speed, sprocket torque, idler force, sinkage) its
mean, least and largest value and spread = (max - min) / |mean|.

- well-conditioned (spread below WELL, 0.5 %): a run passes it within CLOSE (1 %) of the mean;
- ill-conditioned (the others: which ones is measured, per model): a run passes it inside the
  ensemble's range widened by half its width on each side, [min - w / 2, max + w / 2].

A run passes when it passes every peak (judge()). The ensembles' figures are cached in
benchmarks/.cache/ under a hash of the model, the reference, MODEL_VERSION, the git trees of the
code a dopri5 run depends on (trackbench/ but the linearly implicit solvers; uncommitted
changes included) and the toolchain.
"""

import hashlib
import json
import math
import time
from pathlib import Path

import numpy as np
import work_precision as wp

import trackbench as tb

REFERENCE = {"method": "dopri5", "tolerance": 1e-11}
NUDGE = 1e-7          # m: the ensemble's perturbation
ENSEMBLE = 8          # runs, seeds 1..ENSEMBLE
WELL = 0.005          # a peak whose ensemble spreads less is well-conditioned
CLOSE = 0.01          # ... and a run must be this close to its mean (relative)
WIDEN = 0.5           # an ill-conditioned peak's range widened by this fraction of its width a side
CACHE = Path(__file__).resolve().parent / ".cache"
# the code a dopri5 run does not depend on: a change there keeps the cached ensembles
NOT_THE_REFERENCE = ("solvers/rosenbrock/", "solvers/imex/", "solvers/lee/", "solvers/common/pin_jacobian.py",
                     "solvers/registry.py", "cli/", "figures/", "study/", "warm/")


def _code_key():
    """The trees of trackbench/'s folders a dopri5 run reads, and their uncommitted changes."""
    from trackbench.version import MODEL_VERSION, __version__, toolchain

    ls = [line.split("\t", 1) for line in wp._git("ls-tree", "-r", "HEAD", ".").splitlines()]
    kept = [f"{blob}\t{path}" for blob, path in ls if not path.startswith(NOT_THE_REFERENCE)]
    paths = [line.split("\t", 1)[1] for line in kept]
    diff = wp._git("diff", "HEAD", "--", *paths) if paths else ""
    return {
        "model_version": MODEL_VERSION,
        "tree": hashlib.sha256("\n".join(kept).encode()).hexdigest()[:16] if kept else __version__,
        "diff": hashlib.sha256(diff.encode()).hexdigest()[:16] if diff else "",
        "toolchain": toolchain(),
    }


def ensemble_runs(model, n=ENSEMBLE, reference=None, nudge=NUDGE, cache=True):
    """(figures of the n nudged reference runs (work_precision's), from the cache: bool);
    cache=False: run them, keep nothing."""
    reference = reference or REFERENCE
    key = {"model": model, "reference": reference, "nudge": nudge, "n": n, **_code_key()}
    digest = hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()[:20]
    path = CACHE / f"ensemble-{digest}.json"
    if cache and path.exists():
        return json.loads(path.read_text())["runs"], True
    runs = []
    for seed in range(1, n + 1):
        sc = tb.Scenario.from_dict({**model, **reference, "perturbation": nudge, "seed": seed})
        t = time.perf_counter()
        ds = tb.simulate(sc)
        runs.append(wp._figures(ds, sc, time.perf_counter() - t))
    if not cache:
        return runs, False
    CACHE.mkdir(exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps({"key": key, "runs": runs}, indent=1, sort_keys=True))
    tmp.replace(path)
    return runs, False


def ensemble(runs):
    """{peak: (mean, min, max, spread)} over runs (work_precision figures) that all have it."""
    out = {}
    for c in wp.peaks(runs[0]):
        v = np.array([wp.peaks(f).get(c, math.nan) for f in runs], dtype=float)
        if np.all(np.isfinite(v)):
            mean = float(v.mean())
            spread = float((v.max() - v.min()) / abs(mean)) if mean else math.inf
            out[c] = (mean, float(v.min()), float(v.max()), spread)
    return out


def well_conditioned(ens):
    return {c for c, (_, _, _, spread) in ens.items() if spread < WELL}


def judge(peaks, ens):
    """{peak: (passes, how far: |x - mean| / |mean| for a well-conditioned peak, else where x
    lies in the widened range, 0 at its middle and 1 at its edges)} of a run's peaks."""
    out = {}
    for c, (mean, lo, hi, spread) in ens.items():
        x = peaks.get(c, math.nan)
        if spread < WELL:
            far = abs(x - mean) / abs(mean)
            out[c] = (far <= CLOSE, far)
        else:
            half = (hi - lo) * (0.5 + WIDEN)
            mid = 0.5 * (hi + lo)
            far = abs(x - mid) / half if half else math.inf
            out[c] = (far <= 1.0, far)
    return out


def verdict(peaks, ens):
    """(passes every peak, the failing peaks' short names)."""
    j = judge(peaks, ens)
    failed = [wp._label(c) for c, (ok, _) in j.items() if not ok]
    return not failed, failed


def describe(name, model, runs, cached):
    """The ensemble's table: every peak's mean, range and spread, well- or ill-conditioned."""
    ens = ensemble(runs)
    print(f"\n### {name}: reference ensemble, {REFERENCE['method']} at {REFERENCE['tolerance']:g}, "
          f"{len(runs)} runs nudged by {NUDGE:g} m ({'from the cache' if cached else 'run now'})\n")
    print("| peak | mean | min | max | spread | judged |\n| --- | --- | --- | --- | --- | --- |")
    for c, (mean, lo, hi, spread) in ens.items():
        kind = f"within {CLOSE:.0%} of the mean" if spread < WELL else "in the range widened by half"
        print(f"| {wp._label(c)} | {mean:.6g} | {lo:.6g} | {hi:.6g} | {spread:.2%} | {kind} |")
    worst = max(r["energy"] for r in runs)
    print(f"\nenergy residual of the ensemble's runs at most {worst:.1e}; ill-conditioned: "
          f"{', '.join(wp._label(c) for c in ens if c not in well_conditioned(ens)) or 'none'}")
    return ens


def criterion(name, model, variants, repeats=1, paper=None):
    """The criterion's table of one model: each variant's cost beside the paper's model (run
    alongside, best of `repeats` rounds), its steps and whether it passes."""
    runs, cached = ensemble_runs(model)
    ens = describe(name, model, runs, cached)
    best = {}
    for _ in range(max(repeats, 1)):   # the variants and the paper's model alternate
        best["paper"] = wp.run(paper or {}, {"method": "dopri5"}, again=True)
        for v in wp._runnable(model, variants):
            best[json.dumps(v, sort_keys=True)] = wp.run(model, v, again=True)
    p = best.pop("paper")
    p_ratio = p["wall"] / p["t_final"]
    print(f"\n### {name}: the criterion, beside the paper's model ({p_ratio:.3f} wall / simulated)\n")
    print("| method | tol | pins' velocities | wall / sim | / paper's | steps | rejected | passes | "
          "failing | worst well-cond. dev | energy res | speed hold |")
    print("| --- " * 12 + "|")
    well = well_conditioned(ens)
    for key, f in best.items():
        v = json.loads(key)
        ok, failed = verdict(wp.peaks(f), ens)
        j = judge(wp.peaks(f), ens)
        worst = max((j[c][1] for c in well if c in j), default=math.nan)
        ratio = f["wall"] / f["t_final"] if f["t_final"] else math.nan
        pins = v.get("tolerance_pin_velocity", math.nan)
        passes = "yes" if ok and f["status"] == "completed" else "NO"
        print(f"| {v['method']} | {v['tolerance']:.0e} | {pins:.0e} | {ratio:.2f} | {ratio / p_ratio:.1f}x | "
              f"{f['steps']} | {f['rejected']} | {passes} | {', '.join(failed) or '-'} | {worst:.2%} | "
              f"{f['energy']:.1e} | {f['speed_hold']:.2%} |")
