"""Cost of the rerun recording of paper_step against its solve time (target: < 20 %).

    python benchmarks/bench_replay.py [--repeat 5] [--duration 0.5]

Simulates paper_step (0.5 s, output every 1e-4 s = 5001 frames), then writes its recording
`repeat` times for every=1, 2, 5, 10 and reports the median wall time, the first (cold)
write of the process, the file size and the ratio to ds.attrs["solve_time"]. The exit
code is 1 when the every=1 median misses the target.

Each timed write goes to a path that does not exist yet (the previous file is removed
untimed), as in a study, where every run writes into its own new folder. Writing over an
existing file costs more on ext4: renaming onto an existing name makes the kernel start
writing the new file's data back at once (auto_da_alloc), ~4 ms for 6 MB on a 2-core VM,
charged to os.replace. --overwrite measures that case (the same path every time).
"""

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import trackbench as tb
from trackbench.outputs.recording.record import write_recording

TARGET = 0.20


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--duration", type=float, default=0.5)
    ap.add_argument(
        "--overwrite",
        action="store_true",
        help="write over the same file every time (ext4 charges the old file's replacement)",
    )
    args = ap.parse_args(argv)
    tb.simulate(tb.Scenario.paper(duration=0.01))  # compile / load the numba cache
    ds = tb.simulate(tb.Scenario.paper(duration=args.duration))
    solve = float(ds.attrs["solve_time"])
    n = ds.sizes["time"]
    print(
        f"paper_step {args.duration} s: {n} output frames, solve time {solve * 1e3:.1f} ms "
        f"(wall {ds.attrs['wall_time'] * 1e3:.1f} ms)"
    )
    ok = True
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "recording.rrd"
        t0 = time.perf_counter()
        write_recording(ds, p)
        cold = time.perf_counter() - t0
        print(
            f"first write in this process (imports, Arrow set-up): {cold * 1e3:.1f} ms = "
            f"{100 * cold / solve:.1f} %"
        )
        print(f"{'every':>5} {'frames':>7} {'median ms':>10} {'min ms':>8} {'% of solve':>11} {'MB':>6}")
        for every in (1, 2, 5, 10):
            times = []
            for _ in range(args.repeat):
                if not args.overwrite:
                    p.unlink(missing_ok=True)
                t0 = time.perf_counter()
                write_recording(ds, p, every=every)
                times.append(time.perf_counter() - t0)
            med = statistics.median(times)
            frames = len(range(0, n, every)) + (1 if (n - 1) % every else 0)
            print(
                f"{every:5d} {frames:7d} {med * 1e3:10.1f} {min(times) * 1e3:8.1f} "
                f"{100 * med / solve:10.1f}% {p.stat().st_size / 1e6:6.2f}"
            )
            if every == 1:
                ok = med < TARGET * solve
    print(
        f"target: recording (every=1, median) < {100 * TARGET:.0f} % of the solve time: "
        f"{'met' if ok else 'MISSED'}"
    )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
