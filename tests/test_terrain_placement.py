"""A placement key given by the user replaces the default's: the paper's step is placed
by first_contact_time, and a user who gives position (or gap) means that instead."""

import numpy as np
import pytest

import trackbench as tb
from trackbench.cli.single_run import scenario_from_sets
from trackbench.scenario import ScenarioError
from trackbench.study.spec.study_file import load_study


def test_position_on_the_command_line_replaces_the_default_placement():
    t = scenario_from_sets(["terrain.position=2.2"])["terrain"]
    assert t == {"kind": "step", "height": 0.1, "position": 2.2}


def test_position_in_a_study_scenario_table(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(
        '[study]\nname = "placed"\n[scenario]\nduration = 0.01\n'
        'terrain = { kind = "step", height = 0.1, position = 2.2 }\n[grid]\nspeed = [5.0, 10.0]\n'
    )
    study = load_study(f, output=tmp_path / "out")
    terrains = [r.scenario["terrain"] for r in study.runs]
    assert len(terrains) == 2
    assert all(t["position"] == 2.2 and "first_contact_time" not in t for t in terrains)


def test_two_placements_in_one_table_are_still_an_error():
    with pytest.raises(ScenarioError, match="only one of"):
        tb.Scenario.paper(
            terrain={"kind": "step", "height": 0.1, "position": 2.0, "first_contact_time": 0.05}
        )


@pytest.mark.parametrize(
    "terrain, front",
    [
        ({"kind": "step", "height": 0.1, "position": 0.5}, 1.607),  # its top corner inside the track
        (
            {"kind": "bump", "height": 0.1, "length": 0.5, "position": 1.0},
            1.43,
        ),  # its foot under the ground run
    ],
)
def test_an_obstacle_under_the_resting_track_is_refused_before_the_run(terrain, front):
    """Placed by position behind where the resting track's ground side reaches its first
    corner's height, an obstacle would stand in the track at t = 0 (the run failed after
    5 ms with "a ground corner went through the track")."""
    with pytest.raises(ScenarioError, match=rf"terrain.position = .* under the resting track .*x = {front}"):
        tb.simulate(tb.Scenario.paper(terrain=terrain, duration=0.01))


def test_an_obstacle_just_ahead_of_the_track_is_accepted():
    ds = tb.simulate(
        tb.Scenario.paper(terrain={"kind": "step", "height": 0.1, "position": 1.65}, duration=0.01)
    )
    assert ds.attrs["status"] == "completed"


def test_placement_by_time_needs_a_speed():
    with pytest.raises(ScenarioError, match=r"first_contact_time = 0.0568 s needs speed > 0"):
        tb.Scenario.paper(speed=0.0)
    assert tb.Scenario.paper(speed=0.0, terrain={"kind": "flat"})["speed"] == 0.0


def test_one_road_wheel_is_not_a_vehicle():
    with pytest.raises(
        ScenarioError, match=r"vehicle.n_wheels = 1 is not allowed: expected an integer in \[2, 20\]"
    ):
        tb.Scenario.paper(**{"vehicle.n_wheels": 1})


def test_a_polyline_that_runs_straight_through_a_point_is_one_segment():
    """A points terrain whose flat ground is given in pieces (the resting track on x < 0
    and x > 0): one segment, so that the ground the vehicle starts on is not taken for an
    obstacle (first contact was reported at t = 0)."""
    from trackbench.model.ground.terrain import ground_from_points

    pts = [[0.0, 0.0], [3.0, 0.0], [3.5, 0.1], [4.0, 0.2], [5.0, 0.2]]
    merged = ground_from_points(pts, merge_straight=True)
    assert merged.vertices[:, 0].tolist() == [-1000.0, 3.0, 4.0, 1000.0]
    assert len(ground_from_points(pts).segments) == 6  # the other terrains keep their vertices


def test_a_points_terrain_starts_without_obstacle_contact():
    ds = tb.simulate(
        tb.Scenario.paper(
            duration=0.01,
            output_interval=1e-3,
            terrain={"kind": "points", "points": [[0.0, 0.0], [3.0, 0.0], [3.5, 0.1]]},
        )
    )
    assert ds.attrs["status"] == "completed"
    assert np.isnan(float(ds.first_contact_time))


def test_a_run_that_ends_before_the_planned_contact_says_so():
    from trackbench.cli.single_run import format_summary

    ds = tb.simulate(tb.Scenario.paper(duration=0.01, output_interval=1e-3))
    line = next(x for x in format_summary(ds).splitlines() if "first obstacle contact" in x)
    assert "none (placed to be met at 0.0568 s, after the run's end at 0.01 s)" in line
