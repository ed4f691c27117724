"""Every output array of a few reference runs is bit for bit what it was when
tests/golden/hashes.json was recorded (tests/golden/cases.py says how): a refactoring
that changes one rounding anywhere shows here, long before it shows in a tolerance."""

import json
from pathlib import Path

import pytest

from golden.cases import CASES, fingerprint, simulate_case

EXPECTED = json.loads((Path(__file__).parent / "golden" / "hashes.json").read_text())


@pytest.mark.parametrize("name", sorted(CASES))
def test_outputs_bit_for_bit(name, paper_run):
    ds = paper_run if name == "paper_step" else simulate_case(name)
    got = json.loads(json.dumps(fingerprint(ds), default=str))
    want = EXPECTED[name]
    changed = sorted(k for k in set(want) | set(got) if k != "attrs" and want.get(k) != got.get(k))
    assert not changed, f"{name}: arrays changed: {changed}"
    attrs = {k for k in set(want["attrs"]) | set(got["attrs"]) if want["attrs"].get(k) != got["attrs"].get(k)}
    assert not attrs, f"{name}: attributes changed: " + ", ".join(
        f"{k}: {want['attrs'].get(k)!r} -> {got['attrs'].get(k)!r}" for k in sorted(attrs))
