"""Vehicles as data: the catalogue (lee2000.toml is the paper's vehicle bit for bit), a user's
own file with per-wheel values on a closed track through a study, the one-line errors of bad
files, and the commands that list and show vehicles."""

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from golden.cases import differences

import trackbench as tb
from trackbench.model.vehicle.parameters import closed_defaults, paper_track, paper_vehicle
from trackbench.scenario import ScenarioError
from trackbench.study.spec.runid import run_id
from trackbench.vehicles import GROUPS, catalogue, catalogue_path, known_names, read

HERE = Path(__file__).parent
EXPECTED = json.loads((HERE / "golden" / "hashes.json").read_text())
CLI = [sys.executable, "-m", "trackbench.cli"]

# six road wheels, unequal spacing, two wheel radii (and arms), support rollers, the closed track
SIX = """
[source]
description = "a user's six-wheel vehicle"

[vehicle]
chassis_mass = 18000.0
chassis_inertia = 45000.0
n_wheels = 6
wheel_radius = [0.30, 0.28, 0.28, 0.28, 0.28, 0.30]
arm_length = [0.45, 0.5, 0.5, 0.5, 0.5, 0.45]
arm_angle = [44.0, 45.0, 45.0, 45.0, 45.0, 44.0]
torsion_stiffness = [220000.0, 191000.0, 191000.0, 191000.0, 191000.0, 220000.0]
arm_mass = [320.0, 300.0, 300.0, 300.0, 300.0, 320.0]
arm_inertia = [14.0, 12.5, 12.5, 12.5, 12.5, 14.0]
first_pivot_x = 1.85
pivot_spacing = [0.78, 0.70, 0.70, 0.70, 0.78]
arm_damping = [8000.0, 0.0, 0.0, 0.0, 0.0, 8000.0]

[track]
layout = "closed"

[rollers]
positions = [[1.0, 0.13], [-1.0, 0.13]]
"""


def paper_values():
    out = {f"vehicle.{k}": v for k, v in paper_vehicle().items()}
    out.update({f"track.{k}": v for k, v in paper_track().items()})
    for g in ("sprocket", "idler", "rollers"):
        out.update({f"{g}.{k}": v for k, v in closed_defaults()[g].items()})
    return out


def without_model(sc):
    d = sc.to_dict()
    d["vehicle"].pop("model")
    return d


def test_lee2000_holds_the_paper_defaults_exactly():
    values = read("lee2000").values
    assert values == paper_values()
    assert all(type(values[k]) is type(v) for k, v in paper_values().items())
    assert known_names() == frozenset(paper_values())


@pytest.mark.parametrize("over", [{}, {"track.layout": "closed"}, {"preset": "damped"},
                                  {"terrain.kind": "flat", "vehicle.chassis_mass": 21000.0}])
def test_lee2000_named_resolves_as_the_default(over):
    named = tb.Scenario.from_dict({"vehicle.model": "lee2000", **over})
    assert without_model(named) == tb.Scenario.from_dict(over).to_dict()
    assert named.given == frozenset()


def test_run_ids_of_scenarios_without_a_vehicle_stay():
    """Scenarios resolve to what they did before vehicles became data: no vehicle.model, no new
    key (run ids pinned then, at model version 5; the closed track's tolerance set to the 1e-9
    it had by default then)."""
    assert run_id(tb.Scenario.paper().to_dict(), "5") == "62a3ccc40bca026c"
    closed = {"track.layout": "closed", "preset": "damped", "terrain.kind": "flat", "tolerance": 1e-9}
    assert run_id(tb.Scenario.from_dict(closed).to_dict(), "5") == "67c22e592858a6f9"
    assert "model" not in tb.Scenario.paper()["vehicle"]


def test_paper_step_from_the_catalogue_is_golden():
    ds = tb.simulate(tb.Scenario.from_dict({"vehicle.model": "lee2000"}))
    arrays, attrs = differences("paper_step", ds, EXPECTED)
    assert not arrays
    assert [a for a in attrs if not a.startswith("scenario:")] == []


def test_per_wheel_lists_of_one_value_equal_the_number():
    base = {"terrain.kind": "flat", "duration": 0.02}
    lists = {f"vehicle.{k}": [paper_vehicle()[k]] * 5 for k in
             ("wheel_radius", "arm_length", "arm_angle", "torsion_stiffness", "arm_mass", "arm_inertia",
              "pivot_y")}
    a = tb.simulate(tb.Scenario.from_dict(base))
    b = tb.simulate(tb.Scenario.from_dict({**base, **lists, "vehicle.pivot_spacing": [0.81] * 4}))
    for name in ("chassis_y", "chassis_pitch", "wheel_force_y", "pin_y", "link_tension"):
        assert np.array_equal(a[name].values, b[name].values), name


def test_catalogue_files_cite_every_number():
    assert catalogue()[0] == "lee2000"
    for name in catalogue():
        doc = tomllib.loads(catalogue_path(name).read_text())
        src = doc["source"]
        assert src["description"] and src["reference"], name
        cited = set(src["cite"])
        for g in GROUPS:
            for k in doc.get(g, {}):
                assert f"{g}.{k}" in cited or g in cited, f"{name}: {g}.{k} has no citation"


@pytest.fixture(scope="module")
def six(tmp_path_factory):
    d = tmp_path_factory.mktemp("six")
    (d / "six.toml").write_text(SIX)
    return d


def test_a_users_vehicle_resolves_with_its_own_values(six):
    sc = tb.Scenario.from_dict({"vehicle.model": "six.toml", "vehicle.chassis_mass": 17000.0},
                               folder=str(six))
    assert sc["vehicle.n_wheels"] == 6 and sc["vehicle.wheel_radius"][0] == 0.30
    assert sc["vehicle.chassis_mass"] == 17000.0            # explicit wins over the file
    assert sc["track.layout"] == "closed" and sc["rollers.positions"] == [[1.0, 0.13], [-1.0, 0.13]]
    assert sc["vehicle.arm_damping"][0] == 8000.0           # the file's shock absorbers stay
    damped = tb.Scenario.from_dict({"vehicle.model": "six.toml", "preset": "damped"}, folder=str(six))
    assert damped["vehicle.arm_damping"] == sc["vehicle.arm_damping"]   # a preset leaves the file's


def test_a_users_vehicle_runs_a_closed_track_study(six):
    from trackbench.study import load_study, run_study

    (six / "study.toml").write_text(
        '[study]\nname = "six"\n\n[scenario]\n"vehicle.model" = "six.toml"\nduration = 0.05\n'
        'output_interval = 0.001\nrecord = { enabled = false }\nterrain = { kind = "flat" }\n\n'
        "[grid]\nspeed = [2.0, 3.0]\n"
    )
    study = load_study(six / "study.toml", output=six / "results")
    assert len(study.runs) == 2 and study.runs[0].scenario["vehicle"]["model"] == "six.toml"
    run_study(six / "study.toml", workers=1, output=six / "results")
    runs = sorted((six / "results" / "runs").glob("*/run.json"))
    assert len(runs) == 2
    for r in runs:
        info = json.loads(r.read_text())
        assert info["status"] == "completed", info
    # the resolved copy carries every value: it loads beside the results, reading no vehicle file
    copy = load_study(six / "results" / "study.toml", output=six / "again")
    assert [r.scenario["vehicle"] for r in copy.runs] == [r.scenario["vehicle"] for r in study.runs]


def test_vehicle_show_prints_the_statics_and_draws(six, tmp_path):
    res = subprocess.run(CLI + ["vehicle", "show", str(six / "six.toml"), "--out", str(tmp_path)],
                         capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    assert "the ground carries 208.85 kN, the weight 208.85 kN" in res.stdout
    assert "return run sag" in res.stdout and "ground pressure" in res.stdout and "seat" in res.stdout
    assert (tmp_path / "six_vehicle.png").stat().st_size > 10_000
    listing = subprocess.run(CLI + ["vehicles"], capture_output=True, text=True, timeout=300)
    assert listing.returncode == 0 and "22.08 t" in listing.stdout and "m113" in listing.stdout


BAD = {
    "missing": (None, "no such vehicle"),
    "malformed": ("[vehicle\nchassis_mass = 1", "not valid TOML"),
    "unknown table": ("[vehcile]\nchassis_mass = 1.0", "unknown table [vehcile]; did you mean [vehicle]?"),
    "unknown key": ("[vehicle]\nwheel_radus = 0.3", "unknown key vehicle.wheel_radus; did you mean "
                    "vehicle.wheel_radius?"),
    "not a table": ("vehicle = 3", "vehicle must be a table"),
    "list length": ("[vehicle]\nwheel_radius = [0.28, 0.3]", "vehicle.wheel_radius has 2 values for 5 "
                    "road wheels"),
    "gap count": ("[vehicle]\npivot_spacing = [0.81, 0.81]", "vehicle.pivot_spacing has 2 values for 4 gaps"),
    "bad value": ("[vehicle]\nwheel_radius = [0.28, 0.28, -0.1, 0.28, 0.28]",
                  "vehicle.wheel_radius[2] = -0.1 is not allowed: expected a number > 0"),
    "wrong type": ('[vehicle]\nchassis_mass = "heavy"', "vehicle.chassis_mass = 'heavy' is not allowed"),
    "wheels overlap": ("[vehicle]\npivot_spacing = [0.81, 0.81, 0.45, 0.81]", "road wheels 3 and 4 overlap"),
    "track too short": ("[track]\nn_links = 26", "the track is too short for the wheels"),
    "does not stand": ("[vehicle]\nfirst_pivot_x = -0.2", "the vehicle does not stand"),
    "idler off its guide": ('[track]\nlayout = "closed"\nn_links = 50', "the idler would leave its guide"),
}


@pytest.mark.parametrize("kind", sorted(BAD))
def test_bad_vehicle_files_fail_in_one_line(kind, tmp_path):
    text, words = BAD[kind]
    if text is not None:
        (tmp_path / "bad.toml").write_text(text)
    with pytest.raises(ScenarioError) as e:
        tb.Scenario.from_dict({"vehicle.model": "bad.toml"}, folder=str(tmp_path))
    msg = str(e.value)
    assert "\n" not in msg and words in msg, msg
    assert "bad.toml" in msg, msg


def test_a_bad_vehicle_stops_a_run_before_it_writes(tmp_path):
    (tmp_path / "bad.toml").write_text("[vehicle]\nwheel_radius = [0.28, 0.3]")
    res = subprocess.run(CLI + ["run", "--set", "vehicle.model=bad.toml", "--out", "out"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 2 and "vehicle.wheel_radius has 2 values" in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1 and not (tmp_path / "out").exists()


def test_m113_stands_on_one_track_and_its_track_closes():
    """The M113 (Chrono's M113a, one track): about half its 9.15 t, the ground carries the
    weight, every wheel is loaded, the 63 shoes close round sprocket and idler with the idler
    within its travel and the tensioner near Chrono's 5e4 N preload."""
    from trackbench.run.vehicle_report import statics, vehicle_mass, vehicle_scenario

    sc = vehicle_scenario("m113")
    assert 4.5e3 < vehicle_mass(sc) < 4.65e3 and sc["track.n_links"] == 63
    st = statics(sc)
    eq = st.eq
    assert abs(eq.ground_force - eq.weight) < 1e-3 * eq.weight
    assert np.all(eq.wheel_load > 0.0) and eq.residual < 1e-9 * eq.weight
    assert abs(eq.info["idler_slide"]) < sc["idler.travel"]
    assert 2e4 < eq.info["idler_force"] < 6e4
    assert 30e3 < st.ground_pressure < 60e3     # published: 7.3 psi (50 kPa) at 10.4 t on two tracks


def test_a_grid_over_vehicles_resolves_each(six):
    from trackbench.study import load_study

    (six / "grid.toml").write_text('[study]\nname = "fleet"\n\n[scenario]\nduration = 0.05\n\n'
                                   '[grid]\n"vehicle.model" = ["lee2000", "six.toml", "m113"]\n')
    study = load_study(six / "grid.toml", output=six / "fleet")
    wheels = [r.scenario["vehicle"]["n_wheels"] for r in study.runs]
    assert wheels == [5, 6, 5] and study.runs[2].scenario["track"]["n_links"] == 63
    assert study.runs[0].scenario["track"] == paper_track()


def test_a_vehicle_without_an_equilibrium_stops_vehicle_show_in_one_line(six, tmp_path):
    (tmp_path / "wobbly.toml").write_text(SIX.replace("arm_angle = [44.0,", "arm_angle = [40.0,")
                                          .replace("45.0, 44.0]", "45.0, 40.0]"))
    res = subprocess.run(CLI + ["vehicle", "show", "wobbly.toml"], cwd=tmp_path, capture_output=True,
                         text=True, timeout=600)
    assert res.returncode == 1 and "the vehicle does not stand" in res.stderr, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1 and not list(tmp_path.glob("*.png"))
