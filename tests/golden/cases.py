"""The runs whose every output array is pinned bit for bit (tests/test_golden.py) and the
script that records their hashes: `python tests/golden/cases.py > tests/golden/hashes.json`.
Record only when a change is meant to change results, and say so in CHANGELOG.md.
`python tests/golden/cases.py --check` compares instead: one line per case that differs,
exit status 1 (the test that runs it under other CPU kernels reads it)."""

import hashlib
import json
import sys
from pathlib import Path

import numpy as np

CASES = {
    "paper_step": {},
    "paper_step_lee": {"solver": "lee"},
    "flat": {"terrain": {"kind": "flat"}, "duration": 0.2},
    "sequence": {
        "duration": 0.3,
        "terrain": {
            "kind": "sequence",
            "obstacles": [
                {"kind": "step", "height": 0.05, "first_contact_time": 0.03},
                {"kind": "bump", "height": 0.05, "length": 0.3, "gap": 0.5},
            ],
        },
    },
}

# attributes that vary from run to run (timings) or name the code, not the numbers
VOLATILE = {"wall_time", "solve_time", "trackbench_version", "toolchain"}


def digest(a):
    a = np.ascontiguousarray(np.asarray(a))
    return hashlib.sha1(str(a.dtype).encode() + str(a.shape).encode() + a.tobytes()).hexdigest()


def fingerprint(ds):
    """sha1 of every variable and coordinate, and the run's attributes."""
    out = {name: digest(ds[name].values) for name in sorted(ds.variables)}
    out["attrs"] = {k: v for k, v in sorted(ds.attrs.items()) if k not in VOLATILE}
    return out


def simulate_case(name):
    import trackbench as tb

    return tb.simulate(tb.Scenario.from_dict(CASES[name]))


def differences(name, ds, expected):
    """The arrays and attributes of a case that differ from the recorded hashes."""
    got = json.loads(json.dumps(fingerprint(ds), default=str))
    want = expected[name]
    arrays = sorted(k for k in set(want) | set(got) if k != "attrs" and want.get(k) != got.get(k))
    attrs = sorted(
        k for k in set(want["attrs"]) | set(got["attrs"]) if want["attrs"].get(k) != got["attrs"].get(k)
    )
    return arrays, [f"{k}: {want['attrs'].get(k)!r} -> {got['attrs'].get(k)!r}" for k in attrs]


def check():
    expected = json.loads((Path(__file__).parent / "hashes.json").read_text())
    bad = 0
    for name in sorted(CASES):
        arrays, attrs = differences(name, simulate_case(name), expected)
        if arrays or attrs:
            bad += 1
            print(f"{name}: arrays changed: {arrays}; attributes changed: {attrs}")
    return 1 if bad else 0


if __name__ == "__main__":
    if sys.argv[1:] == ["--check"]:
        sys.exit(check())
    print(
        json.dumps(
            {name: fingerprint(simulate_case(name)) for name in CASES}, indent=1, sort_keys=True, default=str
        )
    )
