"""The NG-NRMM benchmark's ground: half-round obstacles (terrain.kind = "halfround", its
radius) and random courses by NRMM's RMS in inches (terrain.rms_in)."""

import numpy as np
import pytest

import trackbench as tb
from trackbench.model.ground import rough
from trackbench.model.ground.terrain import HALFROUND_CHORDS, halfround_points
from trackbench.run.simulate import build_ground, equilibrium


def test_a_halfround_is_a_polygon_on_its_circle():
    pts = np.array(halfround_points(3.0, 0.2))
    assert len(pts) == HALFROUND_CHORDS + 1
    assert pts[0].tolist() == [3.0, 0.0] and pts[-1].tolist() == [3.4, 0.0]   # the feet on the base line
    assert np.allclose(np.hypot(pts[:, 0] - 3.2, pts[:, 1]), 0.2, rtol=0, atol=1e-15)
    assert np.all(np.diff(pts[:, 0]) > 0) and abs(pts[:, 1].max() - 0.2) < 1e-15   # height = radius


def test_a_halfround_in_the_ground_and_in_a_sequence():
    sc = tb.Scenario.paper(terrain={"kind": "halfround", "radius": 0.3, "position": 3.5})
    ground, _ = build_ground(sc, equilibrium(sc))
    on = (ground.vertices[:, 0] >= 3.5) & (ground.vertices[:, 0] <= 4.1)
    assert on.sum() == HALFROUND_CHORDS + 1 and ground.vertices[:, 1].max() == pytest.approx(0.3, abs=1e-15)
    assert len(ground.corners) == HALFROUND_CHORDS - 1   # every vertex but the feet is convex
    seq = tb.Scenario.paper(terrain={"kind": "sequence", "obstacles": [
        {"kind": "step", "height": 0.05, "first_contact_time": 0.03},
        {"kind": "halfround", "radius": 0.1, "gap": 1.0}]})
    g, _ = build_ground(seq, equilibrium(seq))
    assert g.vertices[:, 1].max() == pytest.approx(0.15, abs=1e-15)   # on top of the step's level


@pytest.mark.parametrize("terrain, message", [
    ({"kind": "halfround", "position": 3.0}, "terrain.radius is missing"),
    ({"kind": "halfround", "radius": 0.2, "height": 0.2, "position": 3.0}, "terrain.height does not apply"),
    ({"kind": "halfround", "radius": 0.2, "first_contact_time": 0.05}, "first_contact_time does not apply"),
    ({"kind": "halfround", "radius": -0.2, "position": 3.0}, "terrain.radius = -0.2 is not allowed"),
    ({"kind": "halfround", "radius": 0.2, "position": 0.5}, "puts the halfround under the resting track"),
    ({"kind": "random", "rms": 0.02, "rms_in": 1.0}, "are both given: expected one of them"),
    ({"kind": "random", "rms_in": 0.0}, "terrain.rms_in = 0.0 is not allowed"),
])
def test_bad_halfround_and_nrmm_terrains_are_one_line(terrain, message):
    # placement is checked as the ground is built: a ValueError there, which simulate says as a ScenarioError
    with pytest.raises((tb.ScenarioError, ValueError)) as e:
        sc = tb.Scenario.paper(terrain=terrain)
        build_ground(sc, equilibrium(sc))
    assert message in str(e.value) and "\n" not in str(e.value)


def test_nrmm_rms_in_inches_is_the_rms_below_60_ft():
    """terrain.rms_in = 1 in: the band ends at 60 ft (NRMM's detrending) and the profile's RMS
    over it is 0.0254 m; a wavelength_max given explicitly is kept."""
    sc = tb.Scenario.paper(terrain={"kind": "random", "rms_in": 1.0, "length": 200.0})
    t = sc["terrain"]
    assert t["wavelength_max"] == pytest.approx(18.288) and rough.rms_of(t) == pytest.approx(0.0254)
    x, h = rough.random_profile(t["length"], t["seed"], rms=rough.rms_of(t),
                                wavelength_min=t["wavelength_min"], wavelength_max=t["wavelength_max"],
                                run_in=0.0, blend=0.0)
    assert np.sqrt(np.mean(h[:-1] ** 2)) == pytest.approx(0.0254, rel=1e-9)
    given = tb.Scenario.paper(terrain={"kind": "random", "rms_in": 1.0, "wavelength_max": 10.0})
    assert given["terrain"]["wavelength_max"] == 10.0
