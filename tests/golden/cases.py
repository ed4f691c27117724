"""The runs whose every output array is pinned bit for bit (tests/test_golden.py) and the
script that records their hashes: `python tests/golden/cases.py > tests/golden/hashes.json`.
Record only when a change is meant to change results, and say so in CHANGELOG.md."""

import hashlib
import json

import numpy as np

CASES = {
    "paper_step": {},
    "paper_step_lee": {"solver": "lee"},
    "flat": {"terrain": {"kind": "flat"}, "duration": 0.2},
    "sequence": {"duration": 0.3, "terrain": {
        "kind": "sequence", "obstacles": [{"kind": "step", "height": 0.05, "first_contact_time": 0.03},
                                          {"kind": "bump", "height": 0.05, "length": 0.3, "gap": 0.5}]}},
}

# attributes that vary from run to run (timings) or name the code, not the numbers
VOLATILE = {"wall_time", "solve_time", "trackbench_version"}


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


if __name__ == "__main__":
    print(json.dumps({name: fingerprint(simulate_case(name)) for name in CASES}, indent=1, sort_keys=True,
                     default=str))
