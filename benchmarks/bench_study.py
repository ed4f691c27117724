"""Study benchmark: whole commands, per-run overhead, storage, dask, a 1,000-run study.

    python benchmarks/bench_study.py [--repeat 5] [--parts fixed,sweep,long,storage,dask,big]
                                     [--reference RESULTS_DIR] [--against CHECKOUT]

Every figure is a whole `trackbench study run` command in a fresh process on a fresh results
folder (as a user runs it), the numba cache warm (one warm-up command first). The machine may be
shared, so the commands compared are alternated run by run and the medians compared.

sweep    the shipped studies/speed_sweep.toml (15 runs of 0.5 s) with 1 and 2 workers:
         whole-command speed-up, sum of the solve times / (2 x wall) with 2 workers, and the
         per-run overhead outside the solve from run.json ((wall_time - solve_time) / solve_time)
storage  the same sweep with --storage compact: the largest run folder full / compact / as
         written before (xarray, uncompressed: rebuilt from the full files), and the time of
         open_study and of open_study_dataset + loading chassis_y on the three
--reference  compare the sweep's summary.csv numbers and every array of every timeseries.nc
         bit for bit with a results folder of the same sweep written by another version
dask     the sweep on a dask LocalCluster of 2 worker processes against the process pool
fixed    what every command pays: a one-run study of 0.01 s, and `trackbench run --duration 0.01`,
         each a whole command in its own process; with --against DIR, beside another version's
long     benchmarks/long_runs.toml (16 runs of ~2 s solve) with 1 and 2 workers: speed-up, and
         the per-run work outside the solve from run.json
big      1,000 runs of 0.01 s (recordings off, in the command's own process): its memory as
         runs accumulate, then `study status`, write_summary and open_study_dataset on the folder
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

REPO = Path(__file__).resolve().parents[1]
CLI = [sys.executable, "-c", "from trackbench.cli import main; main()"]
# the commands run this checkout's trackbench
os.environ["PYTHONPATH"] = os.pathsep.join([str(REPO)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
sys.path.insert(0, str(REPO))


def command(cwd, study, *args):
    """Run `trackbench study run STUDY ARGS` in ``cwd`` on a fresh results folder (a user's
    first run: no file replaced); returns its wall time (s)."""
    shutil.rmtree(cwd / "results" / Path(study).stem, ignore_errors=True)
    t = time.perf_counter()
    r = subprocess.run(
        CLI + ["study", "run", study, *args],
        cwd=cwd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    wall = time.perf_counter() - t
    if r.returncode != 0:
        raise SystemExit(f"study run {study} {' '.join(args)} failed: {r.stderr[-2000:]}")
    return wall


def records(folder):
    return [json.loads(p.read_text()) for p in sorted(Path(folder).glob("runs/*/run.json"))]


def overhead(recs):
    """(median, max) of (wall_time - solve_time) / solve_time over the runs, and the solve total."""
    r = [(x["wall_time"] - x["solve_time"]) / x["solve_time"] for x in recs]
    return statistics.median(r), max(r), sum(x["solve_time"] for x in recs)


def idle_fraction(seconds=2.0):
    """The machine's idle CPU fraction over ``seconds`` (Linux /proc/stat), or None."""
    try:
        a = [int(x) for x in open("/proc/stat").readline().split()[1:]]
        time.sleep(seconds)
        b = [int(x) for x in open("/proc/stat").readline().split()[1:]]
    except OSError:
        return None
    d = [y - x for x, y in zip(a, b)]
    return (d[3] + d[4]) / max(sum(d), 1)


def wait_quiet(limit):
    """Wait (at most ``limit`` s) until the machine is 90 % idle over 2 s: other jobs on a
    shared machine take a core from the 2-worker case. Returns the idle fraction last seen."""
    t0, idle = time.time(), None
    while time.time() - t0 < limit:
        idle = idle_fraction()
        if idle is None or idle > 0.9:
            break
    return idle


QUIET = {"limit": 0.0, "seen": []}


def alternate(repeat, cases):
    """Run each case (name -> function returning a dict) in turn, ``repeat`` times (with
    --quiet-wait, each round once the machine is idle); returns name -> list of results."""
    out = {name: [] for name in cases}
    for _ in range(repeat):
        if QUIET["limit"]:
            QUIET["seen"].append(wait_quiet(QUIET["limit"]))
        for name, fn in cases.items():
            out[name].append(fn())
    return out


def sweep_case(cwd, workers, extra=()):
    def fn():
        wall = command(cwd, "speed_sweep.toml", "-w", str(workers), *extra)
        med, worst, solve = overhead(records(cwd / "results" / "speed_sweep"))
        return {"wall": wall, "solve": solve, "med": med, "max": worst}

    return fn


def med(results, key):
    return statistics.median(r[key] for r in results)


def part_sweep(cwd, repeat):
    res = alternate(repeat, {1: sweep_case(cwd, 1), 2: sweep_case(cwd, 2)})
    ratios = [a["wall"] / b["wall"] for a, b in zip(res[1], res[2])]
    eff = [b["solve"] / (2 * b["wall"]) for b in res[2]]
    print(f"\n== speed_sweep, whole command, {repeat} alternating pairs (median [min, max])")
    for w in (1, 2):
        walls = [r["wall"] for r in res[w]]
        print(
            f"{w} worker{'s' if w > 1 else ' '}: {statistics.median(walls):.2f} s [{min(walls):.2f}, "
            f"{max(walls):.2f}]; solve total {med(res[w], 'solve'):.2f} s; per-run overhead outside the "
            f"solve (run.json): median {100 * med(res[w], 'med'):.0f} %, largest "
            f"{100 * max(r['max'] for r in res[w]):.0f} %"
        )
    print(
        f"speed-up 2 vs 1 workers: median {statistics.median(ratios):.2f}x [{min(ratios):.2f}, "
        f"{max(ratios):.2f}] (target >= 1.8x)"
    )
    print(
        f"sum of solve times / (2 x wall), 2 workers: median {statistics.median(eff):.2f} "
        f"[{min(eff):.2f}, {max(eff):.2f}] (target >= 0.4)"
    )


def folder_bytes(run):
    return sum(p.stat().st_size for p in run.iterdir() if p.is_file())


def as_before(src, dst):
    """A copy of the study folder ``src`` whose timeseries.nc are written as before storage.py
    (xarray's to_netcdf, uncompressed): the yardstick for size and reading time."""
    import xarray as xr

    shutil.copytree(src, dst)
    for p in dst.glob("runs/*/timeseries.nc"):
        ds = xr.load_dataset(p).drop_encoding()
        ds.attrs.pop("storage", None)
        ds.to_netcdf(p, engine="netcdf4", encoding={k: {"_FillValue": None} for k in ds.coords})


def reading_case(folder):
    import trackbench as tb

    def fn():
        t = time.perf_counter()
        tb.open_study(folder)
        t1 = time.perf_counter()
        ds = tb.open_study_dataset(folder)
        ds.chassis_y.load()
        ds.close()
        return {"summary": t1 - t, "dataset": time.perf_counter() - t1}

    return fn


def part_storage(cwd, repeat):
    results, full, compact = cwd / "results" / "speed_sweep", cwd / "full", cwd / "compact"
    for folder, storage in ((full, "full"), (compact, "compact")):
        command(cwd, "speed_sweep.toml", "-w", "2", "--storage", storage)
        shutil.rmtree(folder, ignore_errors=True)
        shutil.copytree(results, folder)
    before = cwd / "before"
    shutil.rmtree(before, ignore_errors=True)
    as_before(full, before)
    print("\n== storage of the speed sweep (largest run folder; whole study)")
    for name, folder in (
        ("before (xarray, uncompressed)", before),
        ("full (default)", full),
        ("compact", compact),
    ):
        sizes = [folder_bytes(r) for r in folder.glob("runs/*")]
        nc = max(p.stat().st_size for p in folder.glob("runs/*/timeseries.nc"))
        rrd = max((p.stat().st_size for p in folder.glob("runs/*/recording.rrd")), default=0)
        print(
            f"{name:30s} largest folder {max(sizes) / 1e6:.2f} MB (timeseries.nc up to {nc / 1e6:.2f} MB, "
            f"recording up to {rrd / 1e6:.2f} MB); study {sum(sizes) / 1e6:.0f} MB"
        )
    res = alternate(
        repeat, {"before": reading_case(before), "full": reading_case(full), "compact": reading_case(compact)}
    )
    print(f"reading, median of {repeat} alternating: open_study / open_study_dataset + chassis_y.load()")
    for name in res:
        print(
            f"  {name:8s} {1e3 * med(res[name], 'summary'):6.1f} ms / "
            f"{1e3 * med(res[name], 'dataset'):6.1f} ms"
        )
    return full


def compare(a, b):
    """Differences between the sweep's results in folders a and b (summary numbers, arrays)."""
    import xarray as xr

    da, db = pd.read_csv(a / "summary.csv"), pd.read_csv(b / "summary.csv")
    if list(da.run_id) != list(db.run_id):
        return ["the run ids differ"]
    bad = [
        f"summary.csv {c}"
        for c in da.columns
        if c not in ("wall_time", "solve_time") and not da[c].equals(db[c])
    ]
    for rid in da.run_id:
        x, y = (xr.load_dataset(f / "runs" / rid / "timeseries.nc") for f in (a, b))
        if set(x.variables) != set(y.variables):
            bad.append(f"{rid}: variables differ")
        bad += [
            f"{rid} {k}"
            for k in x.variables
            if k in y.variables
            and not (x[k].dtype == y[k].dtype and np.array_equal(x[k].values, y[k].values, equal_nan=True))
        ]
    return bad


def part_reference(cwd, reference):
    full = cwd / "results" / "speed_sweep"
    command(cwd, "speed_sweep.toml", "-w", "2")
    bad = compare(Path(reference), full)
    print(
        f"\n== results against {reference}: "
        + (
            "summary numbers and every array bit for bit the same"
            if not bad
            else f"{len(bad)} differences: {bad[:10]}"
        )
    )


def part_dask(cwd, repeat):
    res = alternate(repeat, {"pool": sweep_case(cwd, 2), "dask": sweep_case(cwd, 2, ("--executor", "dask"))})
    ratios = [d["wall"] / p["wall"] for p, d in zip(res["pool"], res["dask"])]
    print(f"\n== dask LocalCluster (2 worker processes) against the process pool (2 workers), {repeat} pairs")
    print(
        f"pool {med(res['pool'], 'wall'):.2f} s, dask {med(res['dask'], 'wall'):.2f} s: dask / pool median "
        f"{statistics.median(ratios):.2f} [{min(ratios):.2f}, {max(ratios):.2f}] (target <= 1.3)"
    )


ONE = '[study]\nname = "one"\n[scenario]\nduration = 0.01\n'


def timed(cwd, args, env=None):
    """Wall time (s) of one whole trackbench command in ``cwd``, its output thrown away."""
    t = time.perf_counter()
    r = subprocess.run(CLI + args, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                       env=env)
    if r.returncode != 0:
        raise SystemExit(f"trackbench {' '.join(args)} failed: {r.stderr[-2000:]}")
    return time.perf_counter() - t


def part_fixed(cwd, repeat, against=None):
    """What every command pays: a one-run study of 0.01 s and `trackbench run --duration 0.01`,
    whole commands (fresh process, fresh results); with ``against`` (another checkout of
    trackbench) the same commands of that version, alternated run by run."""
    (cwd / "one.toml").write_text(ONE)
    envs = {"": None}
    if against:   # the other version's commands in their own process (an older one's daemon off)
        envs[" other"] = {**os.environ, "PYTHONPATH": str(Path(against).resolve()),
                          "TRACKBENCH_DAEMON": "off"}
    for env in envs.values():   # warm-up: each version's kernels in the cache
        timed(cwd, ["run", "--duration", "0.01", "--out", str(cwd / "out"), "--force"], env)

    def study(env):
        def fn():
            shutil.rmtree(cwd / "results" / "one", ignore_errors=True)
            return {"wall": timed(cwd, ["study", "run", "one.toml"], env)}
        return fn

    def run(env):
        args = ["run", "--duration", "0.01", "--out", str(cwd / "out"), "--force"]
        return lambda: {"wall": timed(cwd, args, env)}

    cases = {}
    for tag, env in envs.items():
        cases["study" + tag], cases["run" + tag] = study(env), run(env)
    res = alternate(repeat, cases)
    print(f"\n== fixed cost, whole command in its own process, {repeat} alternating rounds "
          "(median [min, max])")
    for name, label in (("study", "study run of one 0.01 s run"), ("run", "trackbench run --duration 0.01")):
        w = [r["wall"] for r in res[name]]
        line = f"{label:32s} {statistics.median(w):.2f} s [{min(w):.2f}, {max(w):.2f}]"
        if against:
            o = [r["wall"] for r in res[name + " other"]]
            ratio = [a / b for a, b in zip(w, o)]
            line += (f"; {against}: {statistics.median(o):.2f} s [{min(o):.2f}, {max(o):.2f}]; ratio "
                     f"{statistics.median(ratio):.2f} [{min(ratio):.2f}, {max(ratio):.2f}]")
        print(line)


def long_case(cwd, workers):
    def fn():
        wall = command(cwd, "long_runs.toml", "-w", str(workers))
        med_o, worst, solve = overhead(records(cwd / "results" / "long_runs"))
        return {"wall": wall, "solve": solve, "med": med_o, "max": worst}

    return fn


def part_long(cwd, repeat):
    """benchmarks/long_runs.toml (16 runs of ~2 s solve): 1 against 2 workers, whole commands
    alternated, and the per-run work outside the solve from run.json."""
    shutil.copy(REPO / "benchmarks" / "long_runs.toml", cwd / "long_runs.toml")
    res = alternate(repeat, {1: long_case(cwd, 1), 2: long_case(cwd, 2)})
    ratios = [a["wall"] / b["wall"] for a, b in zip(res[1], res[2])]
    print(f"\n== long_runs (16 runs of ~2 s), whole command, {repeat} alternating pairs")
    for w in (1, 2):
        walls = [r["wall"] for r in res[w]]
        print(f"{w} worker{'s' if w > 1 else ' '}: {statistics.median(walls):.1f} s [{min(walls):.1f}, "
              f"{max(walls):.1f}]; solve total {med(res[w], 'solve'):.1f} s; (wall - solve) / solve per run: "
              f"median {100 * med(res[w], 'med'):.1f} %, largest {100 * max(r['max'] for r in res[w]):.0f} %"
              " (target: median <= 10 %)")
    print(f"speed-up 2 vs 1 workers: median {statistics.median(ratios):.2f}x [{min(ratios):.2f}, "
          f"{max(ratios):.2f}] (target >= 1.85x)")


BIG = """[study]
name = "big"
[scenario]
duration = 0.01
output_interval = 1e-3
record = {{ enabled = false }}
[grid]
speed = {{ start = 5.0, stop = {stop}, step = 0.01 }}
"""


def sample_memory(proc, out, every=0.2):
    """(seconds, runs finished, RSS of the command in MB) while ``proc`` runs."""
    import psutil

    p, rows, t0 = psutil.Process(proc.pid), [], time.perf_counter()
    while proc.poll() is None:
        try:
            rss = p.memory_info().rss / 1e6
        except psutil.Error:
            break
        rows.append((time.perf_counter() - t0, len(list(out.glob("runs/*/run.json"))), rss))
        time.sleep(every)
    return rows


def part_big(cwd, n=1000, repeat=5):
    """A study of ``n`` runs of 0.01 s (recordings off, 2 workers): the command's memory as runs
    accumulate, then `study status`, write_summary and open_study_dataset on its folder."""
    (cwd / "big.toml").write_text(BIG.format(stop=round(5.0 + 0.01 * (n - 0.5), 3)))
    out = cwd / "results" / "big"
    shutil.rmtree(out, ignore_errors=True)
    t = time.perf_counter()
    proc = subprocess.Popen(CLI + ["study", "run", "big.toml"], cwd=cwd, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    rows = sample_memory(proc, out)
    wall = time.perf_counter() - t
    recs = records(out)
    print(f"\n== {n}-run study (0.01 s runs, 2 workers, recordings off): exit {proc.returncode}, "
          f"{len(recs)} runs, whole command {wall:.1f} s ({n / wall:.0f} runs/s)")
    marks = [rows[min(range(len(rows)), key=lambda i: abs(rows[i][1] - k))]
             for k in (n // 10, n // 2, n * 9 // 10)]
    print("memory of the command (coordinator) as runs accumulate: "
          + ", ".join(f"{r[1]} runs {r[2]:.0f} MB" for r in marks)
          + f"; peak {max(r[2] for r in rows):.0f} MB")
    status = [timed(cwd, ["study", "status", str(out)]) for _ in range(repeat)]
    print(f"study status (whole command): median {statistics.median(status):.2f} s [{min(status):.2f}, "
          f"{max(status):.2f}] (target < 1 s)")
    part_reading(out, repeat)


def part_reading(out, repeat):
    """write_summary and open_study_dataset on a study folder, in this process, median of ``repeat``."""
    import trackbench as tb
    from trackbench.study.read.folder import _study_of
    from trackbench.study.read.summary import write_summary

    study, summary, opened, first = _study_of(out), [], [], []
    for _ in range(repeat):
        t = time.perf_counter()
        write_summary(study)
        summary.append(time.perf_counter() - t)
        t = time.perf_counter()
        ds = tb.open_study_dataset(out)
        opened.append(time.perf_counter() - t)
        t = time.perf_counter()
        ds.chassis_y.isel(run=0).load()
        first.append(time.perf_counter() - t)
        ds.close()
    print(f"write_summary (summary.csv + .parquet): median {statistics.median(summary):.2f} s "
          f"(target < 2 s); open_study_dataset: {statistics.median(opened):.2f} s, lazy (chunks "
          f"{ds.chassis_y.chunks is not None}); one run's chassis_y read: "
          f"{1e3 * statistics.median(first):.0f} ms")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5, help="alternating repeats of each comparison")
    ap.add_argument("--parts", default="fixed,sweep,long,storage,dask,big")
    ap.add_argument(
        "--reference", help="results folder of the speed sweep from another version (bit for bit)"
    )
    ap.add_argument("--against", help="another checkout of trackbench: part fixed times its commands beside")
    ap.add_argument(
        "--quiet-wait",
        type=float,
        default=0.0,
        help="before each round, wait up to this many seconds for an idle machine",
    )
    args = ap.parse_args()
    QUIET["limit"] = args.quiet_wait
    parts = args.parts.split(",")
    print(f"load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as tmp:
        cwd = Path(tmp)
        shutil.copy(REPO / "studies" / "speed_sweep.toml", cwd / "speed_sweep.toml")
        command(cwd, "speed_sweep.toml", "-w", "2")  # warm-up: numba cache and page cache
        if "sweep" in parts:
            part_sweep(cwd, args.repeat)
        if "storage" in parts:
            part_storage(cwd, args.repeat)
        if args.reference:
            part_reference(cwd, args.reference)
        if "dask" in parts:
            part_dask(cwd, args.repeat)
        if "fixed" in parts:
            part_fixed(cwd, args.repeat, args.against)
        if "long" in parts:
            part_long(cwd, args.repeat)
        if "big" in parts:
            part_big(cwd, repeat=args.repeat)
    seen = [f"{x:.2f}" for x in QUIET["seen"] if x is not None]
    print(
        f"load average after: {os.getloadavg()[0]:.2f}"
        + (f"; idle fraction before each round: {', '.join(seen)}" if seen else "")
    )


if __name__ == "__main__":
    main()
