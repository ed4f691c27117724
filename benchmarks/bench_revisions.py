"""This checkout against another git revision, side by side: the solve time of each model
kind, the two alternating in fresh processes round after round (a busy spell of the shared
machine hits both alike), best of the rounds, and the ratio. Prints figures; asserts nothing.

    python benchmarks/bench_revisions.py BASE_REVISION [--rounds 4] [--kinds dopri5,lee]

BASE_REVISION is checked out once into a temporary git work tree (its numba cache is its
own: the first round compiles it).
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]

# kind: (scenario overrides, repeats in one process)
KINDS = {
    "dopri5": ({}, 10),
    "dop853": ({"method": "dop853"}, 10),
    "lee": ({"solver": "lee"}, 5),
    "damped": ({"preset": "damped"}, 10),
    "closed": (
        {
            "preset": "damped",
            "duration": 0.1,
            "track": {"layout": "closed"},
            "drive": {"kind": "speed"},
            "contact": {"friction": 0.6},
        },
        3,
    ),
    "soil": (
        {
            "preset": "damped",
            "duration": 0.1,
            "speed": 3.0,
            "terrain": {"kind": "flat", "soil": "lete_sand"},
            "track": {"layout": "closed"},
            "drive": {"kind": "speed"},
        },
        3,
    ),
}

CHILD = """
import json, sys
sys.path.insert(0, sys.argv[1])
import trackbench as tb
over, repeats = json.loads(sys.argv[2])
sc = tb.Scenario.from_dict(over)
tb.simulate(sc.with_overrides({"duration": 0.01}))
best = min(tb.simulate(sc).attrs["solve_time"] for _ in range(repeats))
print(json.dumps({"solve": best, "file": tb.__file__}))
"""


def solve_time(root, kind):
    out = subprocess.run(
        [sys.executable, "-c", CHILD, str(root), json.dumps(KINDS[kind])],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    got = json.loads(out.strip().splitlines()[-1])
    assert Path(got["file"]).resolve().is_relative_to(Path(root).resolve()), got["file"]
    return got["solve"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("base")
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--kinds", default=",".join(KINDS))
    args = ap.parse_args()
    kinds = args.kinds.split(",")
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp) / "base"
        subprocess.run(
            ["git", "-C", str(HERE), "worktree", "add", "--detach", str(base), args.base],
            check=True,
            capture_output=True,
        )
        try:
            best = {(k, w): float("inf") for k in kinds for w in ("this", "base")}
            for r in range(args.rounds):
                for k in kinds:
                    for which, root in (("this", HERE), ("base", base)):
                        best[k, which] = min(best[k, which], solve_time(root, k))
                print(f"round {r + 1} of {args.rounds} done", file=sys.stderr)
        finally:
            subprocess.run(["git", "-C", str(HERE), "worktree", "remove", "--force", str(base)], check=False)
    print(f"solve time, best of {args.rounds} rounds; this checkout against {args.base}")
    print(f"{'kind':8} {'this (s)':>10} {'base (s)':>10} {'this/base':>10}")
    for k in kinds:
        print(
            f"{k:8} {best[k, 'this']:10.4f} {best[k, 'base']:10.4f} {best[k, 'this'] / best[k, 'base']:10.3f}"
        )


if __name__ == "__main__":
    main()
