"""Work against precision of the driven vehicle: what each (method, tolerance) costs and how
far its figures land from a tight reference run. Used by bench_closed.py and bench_soil.py
(their `precision` and `spread` parts); prints markdown tables and asserts nothing.

    python benchmarks/bench_closed.py precision --methods dopri5,dop853 --tolerances 1e-7,1e-8,1e-9
    python benchmarks/bench_closed.py spread --methods dopri5 --tolerances 1e-8
    python benchmarks/bench_soil.py precision spread --repeats 1
    python benchmarks/bench_closed.py energy --methods ros34pw2,dopri5 --tolerances 1e-5,1e-6,1e-7 \
        --pin-ratios 1,10

energy: the work-based energy residual (over the accepted steps, over the samples, at the end)
beside the cost (wall / simulated time against the paper's model's in the same process).

criterion: benchmarks/accuracy.py (the reference ensembles, each variant judged beside the
paper's model). --pin-ratios 1,10 gives the methods that take tolerance_pin_velocity (PIN_METHODS)
one variant per ratio of it to the tolerance.

A variant is a dict of scenario overrides, {"method": ..., "tolerance": ...}: a method the
registry does not know yet (a Rosenbrock-W method under way, say) gets a line saying so and
the others run. The default methods are those of solvers.registry.SOLVERS["reduced"].

precision: the reference is `REFERENCE` (dopri5 at 1e-11); its figures are cached in
benchmarks/.cache/ under a hash of the model, the reference settings, MODEL_VERSION, the git
HEAD of the package (its tree, trackbench/ at HEAD, and its uncommitted diff) and the
toolchain, so that reruns skip it.
Each variant's figures, one line each:
  - solve s, wall s: attrs solve_time and the whole simulate() call, each the best of
    `repeats` rounds in which the variants alternate (benchmarks/side_by_side.py's rule: a
    busy spell of this shared machine hits them alike); wall / sim: wall over simulated time;
    solve / first: the solve time over the first variant's (the ratios are the figures);
  - steps, rejected steps, right-hand sides (attrs); counts a solver adds later (attrs or
    scalar variables named *_evaluations, *jacobian*, *decomposition*) in the last column;
  - peak dev: the largest |x - x_ref| / |x_ref| over every "peak" quantity of
    trackbench/quantities.py the run has (road-wheel forces per wheel, ground force, link
    tension, chassis accelerations, least speed, sprocket torque, idler force, sinkage),
    with the worst one named, and the median over them (the peaks are of the motion after the
    first link compression, which varies between correct runs: quantities.py `late`);
  - end dev: chassis x, y, pitch and vx at t_end against the reference's, each scaled as the
    step control scales errors (atol = rtol): |x - x_ref| / (1 + |x_ref|), SI units; worst named;
  - energy res: max_energy_residual, the work-based energy residual over every accepted step
    relative to the initial total energy (output.py: residual / S_E0);
  - speed hold: max |chassis_vx - drive.target| / drive.target over the run's second half
    (bench_closed.drive()'s "worst" speed figure, over t >= t_end / 2).

spread: for each variant (method, tol), the spread (max - min) / |mean| of every peak over six
runs: tolerances tol, tol / 10, tol / 100, and three runs at tol nudged by the scenario's
`perturbation` (1e-9 m, seeds 1-3: every free pin of the initial state moved by a uniform
random amount in [-1e-9, 1e-9] m, as a study's replicates are). Also the worst spread over
the three tolerances alone and over the unnudged run and the three nudged ones alone.
Runs are shared between the parts within one process.
"""

import argparse
import hashlib
import json
import math
import subprocess
import time
from pathlib import Path

import numpy as np

import trackbench as tb
from trackbench.outputs import quantities
from trackbench.solvers import registry

REFERENCE = {"method": "dopri5", "tolerance": 1e-11}
TOLERANCES = (1e-7, 1e-8, 1e-9)
REPEATS = 3
KINDS = ("peak",)  # the quantities.py kinds compared ("mean" ones may sit near zero)
END_STATE = ("chassis_x", "chassis_y", "chassis_pitch", "chassis_vx")
NUDGE = 1e-9  # m: the scenario's perturbation of the spread's nudged runs
NUDGE_SEEDS = (1, 2, 3)
SPREAD_DIVISORS = (1, 10, 100)
CACHE = Path(__file__).resolve().parent / ".cache"
_RUNS = {}  # scenario (JSON) -> figures, shared by the parts
_WARM = set()  # (model, method) compiled and loaded


def default_methods(solver="reduced"):
    from trackbench.solvers.registry import SOLVERS

    return list(SOLVERS[solver].methods)


# the methods whose error norm holds the pins' velocities to tolerance_pin_velocity
PIN_METHODS = registry.pin_tolerance_methods()


def variants(methods=None, tolerances=TOLERANCES, pin_ratios=(1.0,)):
    """[{"method": m, "tolerance": tol}] for every method (default: the registry's) and tolerance;
    for PIN_METHODS one per ratio r of pin_ratios, with tolerance_pin_velocity = r tol."""
    out = []
    for m in methods or default_methods():
        for t in tolerances:
            for r in pin_ratios if m in PIN_METHODS else (None,):
                v = {"method": m, "tolerance": float(t)}
                if r is not None:
                    v["tolerance_pin_velocity"] = float(f"{r * float(t):.12g}")
                out.append(v)
    return out


def command_line(argv, parts):
    """(part names, variants, repeats) of a benchmark's command line: part names as words,
    --methods a,b --tolerances 1e-7,1e-8 --repeats N for the precision and spread parts."""
    p = argparse.ArgumentParser(description="parts: " + ", ".join(parts) + " (none: all)")
    p.add_argument("parts", nargs="*")
    p.add_argument("--methods", default=None, help="comma-separated (default: the registry's)")
    p.add_argument("--tolerances", default=",".join(f"{t:g}" for t in TOLERANCES))
    # the criterion part: benchmarks/accuracy.py
    p.add_argument("--repeats", type=int, default=REPEATS, help="timing rounds (best of)")
    p.add_argument("--pin-ratios", default="1", help="tolerance_pin_velocity / tolerance, comma-separated")
    a = p.parse_args(argv)
    unknown = [n for n in a.parts if n not in parts]
    if unknown:
        p.error(f"unknown part(s) {', '.join(unknown)}; parts: {', '.join(parts)}")
    methods = a.methods.split(",") if a.methods else None
    tolerances = [float(t) for t in a.tolerances.split(",")]
    vs = variants(methods, tolerances, [float(r) for r in a.pin_ratios.split(",")])
    return a.parts or list(parts), vs, a.repeats


def _label(column):
    """A peak's short name: its study-table heading without the unit ("w1", "ground", "sprk")."""
    q, wheel = quantities.quantity_of(column)
    return q.heading.format(wheel).rsplit(" ", 1)[0] if q.heading else column


def _figures(ds, sc, wall):
    a = ds.attrs
    t = ds.time.values
    target = sc["drive.target"] if sc["drive.target"] is not None else sc["speed"]
    late = t >= 0.5 * t[-1]
    hold = float(np.max(np.abs(ds.chassis_vx.values[late] - target)) / abs(target)) if target else math.nan
    return {
        "status": a["status"],
        "t_final": a["t_final"],
        "steps": a["steps"],
        "rejected": a["rejected_steps"],
        "rhs": a["rhs_evaluations"],
        "solve": a["solve_time"],
        "wall": wall,
        "summary": quantities.without_nan(quantities.values(ds, times=False)),
        "end": {v: float(ds[v].values[-1]) for v in END_STATE},
        "energy": float(ds.max_energy_residual),
        "speed_hold": hold,
    }


def _scenario(model, variant, seed=0):
    over = {"perturbation": NUDGE, "seed": seed} if seed else {}
    return {**model, **variant, **over}


def warm(model, variant):
    """Compile and load a method's kernels for a model (a 0.02 s run) before timing it."""
    key = (json.dumps(model, sort_keys=True), variant["method"])
    if key not in _WARM:
        tb.simulate(tb.Scenario.from_dict({**model, **variant, "duration": 0.02}))
        _WARM.add(key)


def run(model, variant, seed=0, again=False):
    """The figures of one run, memoised (a run's figures are the same to the last bit); again:
    run it anyway, for its times, and keep the best of them."""
    d = _scenario(model, variant, seed)
    key = json.dumps(d, sort_keys=True)
    if key in _RUNS and not again:
        return _RUNS[key]
    sc = tb.Scenario.from_dict(d)
    warm(model, variant)
    t = time.perf_counter()
    ds = tb.simulate(sc)
    fig = _figures(ds, sc, time.perf_counter() - t)
    old = _RUNS.get(key)
    if old is not None:
        fig["solve"], fig["wall"] = min(fig["solve"], old["solve"]), min(fig["wall"], old["wall"])
    _RUNS[key] = fig
    return fig


def known(model, variant):
    """None if the scenario takes the variant, else why not (one line)."""
    try:
        tb.Scenario.from_dict({**model, **variant})
    except tb.ScenarioError as e:
        return str(e).splitlines()[0]
    return None


def _git(*args):
    pkg = Path(tb.__file__).resolve().parent
    try:
        done = subprocess.run(["git", "-C", str(pkg), *args], capture_output=True, text=True, check=True)
        return done.stdout
    except (OSError, subprocess.CalledProcessError):
        return ""


def cache_key(model):
    from trackbench.version import MODEL_VERSION, __version__, toolchain

    diff = _git("diff", "HEAD", "--", ".")
    return {
        "model": model,
        "reference": REFERENCE,
        "model_version": MODEL_VERSION,
        # the package's tree at HEAD: a commit that leaves trackbench/ alone keeps the cache
        "package_tree": _git("rev-parse", "HEAD:./").strip() or f"trackbench {__version__}",
        "package_diff": hashlib.sha256(diff.encode()).hexdigest()[:16] if diff else "",
        "toolchain": toolchain(),
    }


def reference(model):
    """(figures of the reference run, cached: bool), from benchmarks/.cache/ when there."""
    key = cache_key(model)
    digest = hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()[:20]
    path = CACHE / f"reference-{digest}.json"
    if path.exists():
        return json.loads(path.read_text())["figures"], True
    fig = run(model, REFERENCE)
    CACHE.mkdir(exist_ok=True)
    tmp = path.with_suffix(".tmp")
    head = _git("rev-parse", "HEAD").strip()
    tmp.write_text(json.dumps({"key": key, "commit": head, "figures": fig}, indent=1, sort_keys=True))
    tmp.replace(path)
    return fig, False


def peaks(fig):
    """column -> value of the run's peaks (KINDS), NaN-free."""
    out = {}
    for c, v in fig["summary"].items():
        found = quantities.quantity_of(c)
        if found and found[0].kind in KINDS and v is not None:
            out[c] = v
    return out


def _worst(devs):
    """(largest value, its name) of {name: value}; NaN counts as largest."""
    if not devs:
        return math.nan, "-"
    name = max(devs, key=lambda k: math.inf if math.isnan(devs[k]) else devs[k])
    return devs[name], name


def deviations(fig, ref):
    """Cells: worst peak deviation, its name, the median peak deviation, worst end-state
    deviation, its name."""
    p, pr = peaks(fig), peaks(ref)
    dev = {c: abs(p[c] - pr[c]) / abs(pr[c]) if pr[c] else math.nan for c in pr if c in p}
    end = {v: abs(fig["end"][v] - ref["end"][v]) / (1 + abs(ref["end"][v])) for v in END_STATE}
    wp, np_ = _worst(dev)
    we, ne = _worst(end)
    if fig["t_final"] != ref["t_final"]:  # a failed run: its last sample against the reference's
        ne += f" at t = {fig['t_final']:.4f} s"
    median = float(np.median(list(dev.values()))) if dev else math.nan
    return [f"{wp:.1e}", _label(np_) if np_ != "-" else np_, f"{median:.1e}", f"{we:.1e}", ne]


def _row(cells):
    return "| " + " | ".join(cells) + " |"


def _line(name, fig, ref, first_solve):
    devs = deviations(fig, ref) if ref is not None else ["-", "(ref)", "-", "-", "(ref)"]
    return _row(
        [
            name[0],
            f"{name[1]:.0e}" + (f" (pins {name[2]:.0e})" if len(name) > 2 else ""),
            fig["status"],
            f"{fig['solve']:.2f}",
            f"{fig['wall']:.2f}",
            f"{fig['wall'] / fig['t_final']:.2f}" if fig["t_final"] else "-",
            f"{fig['solve'] / first_solve:.2f}" if first_solve else "-",
            str(fig["steps"]),
            str(fig["rejected"]),
            str(fig["rhs"]),
            *devs,
            f"{fig['energy']:.1e}",
            f"{fig['speed_hold']:.2e}",
        ]
    )


HEAD = (
    "method",
    "tol",
    "status",
    "solve s",
    "wall s",
    "wall / sim",
    "solve / first",
    "steps",
    "rejected",
    "rhs",
    "peak dev",
    "worst peak",
    "median peak dev",
    "end dev",
    "worst end",
    "energy res",
    "speed hold",
)


def _runnable(model, vs):
    out = []
    for v in vs:
        why = known(model, v)
        if why:
            print(f"- {v['method']} at {v['tolerance']:g}: skipped ({why})")
        else:
            out.append(v)
    return out


def precision(name, model, vs, repeats=REPEATS):
    """The precision table of one model: the reference, then one line per variant."""
    t0 = time.perf_counter()
    ref_name = f"{REFERENCE['method']} at {REFERENCE['tolerance']:g}"
    print(f"\n### {name}: work against precision, reference {ref_name}")
    ref, cached = reference(model)
    vs = _runnable(model, vs)
    best = {}
    for _ in range(max(repeats, 1)):  # the variants alternate round after round
        for v in vs:
            pins = (v["tolerance_pin_velocity"],) if "tolerance_pin_velocity" in v else ()
            best[(v["method"], v["tolerance"], *pins)] = run(model, v, again=True)
    print()
    print(_row(HEAD))
    print(_row(["---"] * len(HEAD)))
    print(_line((REFERENCE["method"], REFERENCE["tolerance"]), ref, None, None))
    first = best[next(iter(best))]["solve"] if best else None
    for key, fig in best.items():
        print(_line(key, fig, ref, first))
    print(
        f"\nreference {'from the cache' if cached else 'run now'} (its times are "
        f"{'of the run that filled the cache' if cached else 'of one run'}); best of {repeats} rounds; "
        f"part took {time.perf_counter() - t0:.0f} s"
    )


def energy(name, model, vs, repeats=REPEATS, bar=1e-6):
    """The work-based energy residual of each variant beside its cost: wall / simulated time,
    best of `repeats` rounds alternating with the paper's model (paper_step at its defaults) in
    this process, and the residual's largest |value| / E0 over the accepted steps (the run's
    max_energy_residual), over the output samples (energy_residual: the dense output between
    steps) and at the end, against `bar`."""
    t0 = time.perf_counter()
    print(f"\n### {name}: energy residual against cost (bar {bar:g} of E0)")
    vs = _runnable(model, vs)
    paper = tb.Scenario.paper()
    scs = {None: paper, **{json.dumps(v, sort_keys=True): tb.Scenario.from_dict({**model, **v}) for v in vs}}
    for sc in scs.values():
        tb.simulate(sc.with_overrides({"duration": 0.02}))   # compiled and loaded first
    best, fig = dict.fromkeys(scs, math.inf), {}
    for _ in range(max(repeats, 1)):
        for key, sc in scs.items():
            t = time.perf_counter()
            ds = tb.simulate(sc)
            best[key] = min(best[key], time.perf_counter() - t)
            if key is not None:
                r = np.abs(ds.energy_residual.values)
                fig[key] = (ds.attrs["steps"], ds.attrs["rejected_steps"], float(ds.max_energy_residual),
                            float(np.nanmax(r)), float(ds.energy_residual.values[-1]))
    base = best[None] / paper["duration"]
    print(f"\nthe paper's model: {base:.3f} s wall / simulated s\n")
    head = ("method", "tolerance", "pins' velocities", "wall / simulated", "/ the paper model's",
            "steps (+ rejected)", "residual, steps", "samples", "end", f"<= {bar:g}")
    print(_row(head))
    print(_row(["---"] * len(head)))
    for key, sc in scs.items():
        if key is None:
            continue
        v = json.loads(key)
        steps, rej, at_steps, at_samples, end = fig[key]
        ratio = best[key] / sc["duration"]
        pins = f"{v['tolerance_pin_velocity']:g}" if "tolerance_pin_velocity" in v else "-"
        print(_row([v["method"], f"{v['tolerance']:g}", pins, f"{ratio:.3f}", f"{ratio / base:.1f}x",
                    f"{steps:,} (+{rej:,})", f"{at_steps:.1e}", f"{at_samples:.1e}", f"{end:+.1e}",
                    "met" if max(at_steps, at_samples) <= bar else "**not met**"]))
    print(f"\nbest of {repeats} rounds; part took {time.perf_counter() - t0:.0f} s")


def _spread(values):
    v = np.array(values, dtype=float)
    return float((v.max() - v.min()) / abs(v.mean())) if len(v) and v.mean() else math.nan


def spread_figures(model, variant):
    """(run figures of the six runs, per-peak spreads over all, over the tolerances alone,
    over the nudges alone)."""
    tol = variant["tolerance"]
    # rounded so that tol / 100 is the tolerance asked for elsewhere (1e-9 / 100 != 1e-11)
    by_tol = [run(model, {**variant, "tolerance": float(f"{tol / d:.12g}")}) for d in SPREAD_DIVISORS]
    nudged = [run(model, variant, seed) for seed in NUDGE_SEEDS]
    runs = by_tol + nudged
    cols = [c for c in peaks(runs[0]) if all(c in peaks(f) for f in runs)]

    def over(group):
        return {c: _spread([peaks(f)[c] for f in group]) for c in cols}

    return runs, over(runs), over(by_tol), over([by_tol[0], *nudged])


def spread(name, model, vs):
    """The spread table of one model: one line per variant, every peak's spread."""
    t0 = time.perf_counter()
    print(
        f"\n### {name}: spread (max - min) / |mean| of the peaks over tol, tol/10, tol/100 and "
        f"{len(NUDGE_SEEDS)} runs at tol nudged by {NUDGE:g} m"
    )
    rows, labels = [], None
    for v in _runnable(model, vs):
        runs, every, tols, nudges = spread_figures(model, v)
        labels = labels or list(every)
        failed = sum(f["status"] != "completed" for f in runs)
        w, wn = _worst(every)
        cells = [v["method"], f"{v['tolerance']:.0e}", f"{w:.1e}", _label(wn), f"{_worst(tols)[0]:.1e}"]
        cells += [f"{_worst(nudges)[0]:.1e}", str(failed)] + [f"{every.get(c, math.nan):.1e}" for c in labels]
        rows.append(cells)
    if labels is None:
        return
    print()
    head = ["method", "tol", "worst", "peak", "tols only", "nudges only", "failed"]
    head += [_label(c) for c in labels]
    print(_row(head))
    print(_row(["---"] * len(head)))
    for cells in rows:
        print(_row(cells))
    print(f"\npart took {time.perf_counter() - t0:.0f} s")


def main(argv, parts, models):
    """Run a benchmark script's parts named on its command line; the "precision" and "spread"
    parts run precision() and spread() on each of `models` (name -> scenario overrides)."""
    names, vs, repeats = command_line(argv, [*parts, "precision", "spread", "criterion", "energy"])
    for name in names:
        if name in parts:
            parts[name]()
        for label, model in models.items():
            if name == "precision":
                precision(label, model, vs, repeats)
            elif name == "spread":
                spread(label, model, vs)
            elif name == "energy":
                energy(label, model, vs, repeats)
            elif name == "criterion":
                import accuracy

                accuracy.criterion(label, model, vs, repeats)
