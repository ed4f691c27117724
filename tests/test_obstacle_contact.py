"""first_contact_time is the first contact of the track with any part of an obstacle."""

import json

import pytest

import trackbench as tb


def test_paper_step_first_contact_unchanged(paper_run):
    assert float(paper_run.first_contact_time) == pytest.approx(0.0568, abs=2e-6)
    assert float(paper_run.first_corner_contact_time) == pytest.approx(0.0568, abs=2e-6)


def test_a_ramp_is_first_touched_on_its_slope():
    """A ramp's foot is a concave corner (no contact of its own); the track first meets
    its slope, long before its top corner: first_contact_time is that first meeting."""
    ds = tb.simulate(
        tb.Scenario.paper(
            terrain={"kind": "ramp", "height": 0.2, "length": 1.0, "position": 2.6}, duration=0.25
        )
    )
    slope, corner = float(ds.first_contact_time), float(ds.first_corner_contact_time)
    print(f"slope {slope:.5f} s, top corner {corner:.5f} s")
    assert 0.0 < slope < corner - 0.02


def test_a_higher_step_time_is_its_first_contact(paper_run):
    """A 0.15 m step where the paper's 0.1 m step stands: whichever part of it the track
    meets first. Here that is the top corner, on link 5 (the nearest pin, 6, is still
    7 cm in front of the face), so both times agree."""
    x = json.loads(paper_run.attrs["terrain_resolved"])["obstacle_0_position"]
    ds = tb.simulate(
        tb.Scenario.paper(terrain={"kind": "step", "height": 0.15, "position": x}, duration=0.06)
    )
    assert float(ds.first_contact_time) == pytest.approx(float(ds.first_corner_contact_time), abs=1e-12)
    assert 0.05 < float(ds.first_contact_time) < 0.0568
