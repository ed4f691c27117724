"""A placement key given by the user replaces the default's: the paper's step is placed
by first_contact_time, and a user who gives position (or gap) means that instead."""

import pytest

import trackbench as tb
from trackbench.runner import scenario_from_sets
from trackbench.scenario import ScenarioError
from trackbench.study.spec import load_study


def test_position_on_the_command_line_replaces_the_default_placement():
    t = scenario_from_sets(["terrain.position=2.2"])["terrain"]
    assert t == {"kind": "step", "height": 0.1, "position": 2.2}


def test_position_in_a_study_scenario_table(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text('[study]\nname = "placed"\n[scenario]\nduration = 0.01\n'
                 'terrain = { kind = "step", height = 0.1, position = 2.2 }\n[grid]\nspeed = [5.0, 10.0]\n')
    study = load_study(f, output=tmp_path / "out")
    terrains = [r.scenario["terrain"] for r in study.runs]
    assert len(terrains) == 2
    assert all(t["position"] == 2.2 and "first_contact_time" not in t for t in terrains)


def test_two_placements_in_one_table_are_still_an_error():
    with pytest.raises(ScenarioError, match="only one of"):
        tb.Scenario.paper(terrain={"kind": "step", "height": 0.1, "position": 2.0, "first_contact_time": 0.05})
