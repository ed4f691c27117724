"""Long runs: steps against the output interval, samples against the capped run, what the
samples show of an obstacle's impacts, and a long flat run's files and peak memory.

    python benchmarks/bench_long_run.py [steps] [detail] [long] [--duration 60]

steps   the 5 s flat run (paper's model) at output intervals 1e-4, 1e-3, 1e-2 s: steps,
        rejected steps and solve time, freed (the default) and held to the output interval
        (max_step = output_interval, as every run was before); the freed run's samples
        against the run held to 1e-4 s (today's) and against a reference at tolerance 1e-12
detail  paper_step sampled at 1e-4, 5e-4 and 1e-3 s: the samples' maxima against the exact
        peaks (located along the steps), per wheel, and the chassis acceleration
long    `trackbench run --set terrain.kind=flat --duration D` at the defaults in a fresh
        process under /usr/bin/time -v (peak resident memory, wall time), the files' sizes,
        the recording checked by `rerun rrd verify` and its frames counted with rerun's reader;
        the same for D / 12 (how memory grows with the run)

Prints figures and asserts nothing (the machine is shared; docs/benchmarks.md, "Long runs").
"""

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import trackbench as tb

FLAT = {"terrain": {"kind": "flat"}}
STATES = ("chassis_y", "chassis_pitch", "pin_x", "pin_y", "chassis_vy", "wheel_y")


def _run(**kw):
    return tb.simulate(tb.Scenario.from_dict({**FLAT, **kw}))


def _worst(ds, ref, stride):
    """The largest difference over STATES at the common sample times, and its variable."""
    worst = (0.0, "")
    for name in STATES:
        a, b = ds[name].values, ref[name].values[::stride]
        d = float(np.nanmax(np.abs(a - b)))
        worst = max(worst, (d, name))
    return worst


def steps(duration):
    _run(duration=0.01)   # compiled or loaded before anything is timed
    print(f"\n## The {duration:g} s flat run: steps against the output interval\n")
    print("| output_interval (s) | freed: steps + rejected | solve (s) | held: steps + rejected "
          "| solve (s) |")
    print("| --- | --- | --- | --- | --- |")
    runs = {}
    for dt in (1e-4, 1e-3, 1e-2):
        free = _run(duration=duration, output_interval=dt)
        held = _run(duration=duration, output_interval=dt, max_step=dt)
        runs[dt] = free
        fa, ha = free.attrs, held.attrs
        print(f"| {dt:g} | {fa['steps']:,} + {fa['rejected_steps']:,} | {fa['solve_time']:.3f} | "
              f"{ha['steps']:,} + {ha['rejected_steps']:,} | {ha['solve_time']:.3f} |")
    today = _run(duration=duration, output_interval=1e-4, max_step=1e-4)
    ref = _run(duration=duration, output_interval=1e-4, max_step=1e-4, tolerance=1e-12)
    print(f"\nsamples (largest difference over {', '.join(STATES)}; tolerance {today.attrs['tolerance']:g}):")
    for dt, ds in runs.items():
        stride = round(dt / 1e-4)
        d_today, n_today = _worst(ds, today, stride)
        d_ref, n_ref = _worst(ds, ref, stride)
        print(f"  freed at {dt:g} s: against today's {d_today:.2e} ({n_today}), against the reference "
              f"{d_ref:.2e} ({n_ref})")
    print(f"  today's against the reference: {_worst(today, ref, 1)[0]:.2e}")
    for name in ("peak_wheel_force_y", "peak_ground_force_y", "peak_link_tension"):
        d = float(np.max(np.abs(runs[1e-3][name].values - ref[name].values)))
        print(f"  {name}: freed against the reference {d:.3g} N of {float(np.max(ref[name].values)):.4g} N")


def detail():
    print("\n## paper_step: what the samples show of the impacts\n")
    print("| output_interval (s) | sampled max / peak, wheels 1-5 | chassis ay | ground force |")
    print("| --- | --- | --- | --- |")
    for dt in (1e-4, 5e-4, 1e-3):
        ds = tb.simulate(tb.Scenario.paper(output_interval=dt, max_step=1e-4))  # the same steps
        wheels = ds.wheel_force_y.max("time").values / ds.peak_wheel_force_y.values
        ay = float(ds.chassis_ay.max() / ds.peak_chassis_ay)
        ground = float(ds.ground_force_y.max() / ds.peak_ground_force_y)
        print(f"| {dt:g} | {', '.join(f'{w:.3f}' for w in wheels)} | {ay:.3f} | {ground:.3f} |")


def _timed_run(duration, out):
    """(peak resident MB, wall s, the command's output) of one `trackbench run` at the defaults."""
    exe = Path(sys.executable).with_name("trackbench")
    cmd = ["/usr/bin/time", "-v", str(exe), "run", "--set", "terrain.kind=flat", "--duration", str(duration),
           "--name", "flat", "--out", str(out)]
    t = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    peak = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
    return (int(peak.group(1)) / 1024 if peak else float("nan")), wall, p.stdout + p.stderr


def _frames(rrd):
    """Rows of the side view's chassis and of the wheel-force plot in the recording."""
    from rerun.chunk import RrdReader

    from trackbench.outputs.recording.entities import E_CHASSIS, E_WHEEL_FY, TIMELINE
    rows = {E_CHASSIS: 0, E_WHEEL_FY: 0}
    for c in RrdReader(rrd).stream().to_chunks():
        if c.entity_path in rows and TIMELINE in c.timeline_names:   # not the static styles
            rows[c.entity_path] += c.to_record_batch().num_rows
    return rows[E_CHASSIS], rows[E_WHEEL_FY]


def long(duration):
    print("\n## Long flat runs at the defaults (`trackbench run --set terrain.kind=flat --duration D`)\n")
    print("| D (s) | peak memory (MB) | wall (s) | netCDF (MB) | recording (MB) | side-view frames | "
          "plot rows | rerun rrd verify |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    rerun = shutil.which("rerun") or str(Path(sys.executable).with_name("rerun"))
    for d in (duration / 12, duration):
        out = Path(tempfile.mkdtemp(prefix="bench_long_"))
        try:
            peak, wall, text = _timed_run(d, out)
            nc, rrd = out / "flat.nc", out / "flat.rrd"
            if not nc.exists():
                print(f"| {d:g} | run failed: {text.strip().splitlines()[-1:]} |")
                continue
            verify = subprocess.run([rerun, "rrd", "verify", str(rrd)], capture_output=True, text=True)
            frames, rows = _frames(rrd)
            print(f"| {d:g} | {peak:.0f} | {wall:.1f} | {nc.stat().st_size / 1e6:.1f} | "
                  f"{rrd.stat().st_size / 1e6:.1f} | {frames:,} | {rows:,} | "
                  f"{'ok' if verify.returncode == 0 else 'failed'} |")
        finally:
            shutil.rmtree(out, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("parts", nargs="*", default=["steps", "detail", "long"])
    ap.add_argument("--duration", type=float, default=60.0, help="the long run (s)")
    ap.add_argument("--steps-duration", type=float, default=5.0, help="the flat run of `steps` (s)")
    a = ap.parse_args()
    for part in a.parts:
        if part == "steps":
            steps(a.steps_duration)
        elif part == "detail":
            detail()
        elif part == "long":
            long(a.duration)
        else:
            raise SystemExit(f"unknown part {part!r}: steps, detail or long")


if __name__ == "__main__":
    main()
