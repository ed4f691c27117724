"""Study files: expansion, run ids, and every bad-input case (no simulation runs here)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from trackbench.study.spec.study_file import StudyError, load_study, resolved_toml

REPO = Path(__file__).resolve().parents[1]
CLI = [sys.executable, "-c", "from trackbench.cli import main; main()"]


def study(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_speed_sweep_expands_to_the_cartesian_grid():
    s = load_study(REPO / "studies" / "speed_sweep.toml")
    assert s.name == "speed_sweep" and s.output == Path("results/speed_sweep")
    assert len(s.runs) == 15
    assert s.param_names == ["speed", "terrain.height"]
    combos = [(r.params["speed"], r.params["terrain.height"]) for r in s.runs]
    assert combos[:3] == [(5.0, 0.05), (5.0, 0.1), (5.0, 0.15)]
    assert len(set(combos)) == 15
    for r in s.runs:
        assert r.scenario["speed"] == r.params["speed"]
        assert r.scenario["terrain"] == {
            "kind": "step",
            "height": r.params["terrain.height"],
            "first_contact_time": 0.0568,
        }
        assert r.scenario["duration"] == 0.5


def test_run_ids_are_stable_and_follow_the_parameters(tmp_path):
    text = "[scenario]\nduration = 0.05\n[grid]\nspeed = [5.0, 10.0]\n"
    a = load_study(study(tmp_path, text))
    b = load_study(study(tmp_path, text.replace("[grid]", "# same\n[grid]"), "t.toml"))
    assert [r.run_id for r in a.runs] == [r.run_id for r in b.runs]
    assert len({r.run_id for r in a.runs}) == 2 and all(len(r.run_id) == 16 for r in a.runs)
    c = load_study(study(tmp_path, text.replace("0.05", "0.06"), "u.toml"))
    assert not {r.run_id for r in a.runs} & {r.run_id for r in c.runs}
    # an integer and a float of the same value are the same scenario
    d = load_study(study(tmp_path, text.replace("5.0, 10.0", "5, 10"), "v.toml"))
    assert [r.run_id for r in a.runs] == [r.run_id for r in d.runs]


def test_ranges_zip_runs_and_replicates(tmp_path):
    s = load_study(
        study(
            tmp_path,
            """
[study]
name = "mix"
output = "elsewhere/mix"
replicates = 3
[grid]
speed = { start = 5.0, stop = 6.0, step = 0.5 }
[[zip]]
"vehicle.torsion_stiffness" = { start = 1.5e5, stop = 2.5e5, num = 2 }
"track.link_length" = [0.188, 0.192]
[[runs]]
speed = 20.0
terrain = { kind = "bump", height = 0.1, length = 0.6, position = 3.5 }
""",
        )
    )
    assert s.output == Path("elsewhere/mix")
    assert sorted({r.params["speed"] for r in s.runs if r.variant < 6}) == [5.0, 5.5, 6.0]
    pairs = {
        (r.params["vehicle.torsion_stiffness"], r.params["track.link_length"])
        for r in s.runs
        if r.variant < 6
    }
    assert pairs == {(1.5e5, 0.188), (2.5e5, 0.192)}
    assert len(s.runs) == (3 * 2 + 1) * 3
    last = [r for r in s.runs if r.variant == 6]
    assert last[0].scenario["terrain"]["kind"] == "bump" and last[0].scenario["speed"] == 20.0
    assert [r.scenario["seed"] for r in last] == [1, 2, 3]
    assert all(r.scenario["perturbation"] == 1e-9 for r in s.runs)
    assert len({r.run_id for r in s.runs}) == len(s.runs)
    # the resolved copy expands to the same runs
    again = load_study(study(tmp_path, resolved_toml(s), "copy.toml"), output=s.output)
    assert [r.run_id for r in again.runs] == [r.run_id for r in s.runs]


def test_no_grid_is_one_run_of_the_base_scenario():
    s = load_study(REPO / "studies" / "paper_step.toml")
    assert len(s.runs) == 1 and s.runs[0].params == {}
    assert s.runs[0].scenario["terrain"]["height"] == 0.1


@pytest.mark.parametrize("name", sorted(p.stem for p in (REPO / "studies").glob("*.toml")))
def test_shipped_studies_validate(name):
    s = load_study(REPO / "studies" / f"{name}.toml")  # every run's scenario validated
    assert len(s.runs) >= 1 and s.description


BAD = [
    ("[grid]\nspeed = [5.0, 10.0\n", r"s\.toml: TOML syntax error at line 2, column 19: Unclosed array"),
    ("[study]\nnmae = 'x'\n", r"\[study\]: unknown key 'nmae'; did you mean name\?"),
    ("[sutdy]\nname = 'x'\n", r"unknown key 'sutdy'; did you mean study\?"),
    ("[grid]\nsped = [5.0]\n", r"\[grid\]: unknown parameter 'sped'; did you mean speed"),
    (
        '[grid]\n"vehicle.chasis_mass" = [1e4]\n',
        r"unknown parameter 'vehicle.chasis_mass'; did you mean vehicle.chassis_mass",
    ),
    ("[scenario]\nsped = 5.0\n", r"\[scenario\]: unknown parameter 'sped'; did you mean speed"),
    (
        "[grid]\nspeed = [5.0, 'fast']\n",
        r"run 2 \(speed = fast\): speed = 'fast' is not allowed: expected a number in \[0, 100\] m/s",
    ),
    ("[grid]\nspeed = [5.0, 500.0]\n", r"speed = 500.0 is not allowed: expected a number in \[0, 100\]"),
    ("[grid]\nspeed = 5.0\n", r"\[grid\] speed = 5.0: expected a list of values or a range table"),
    (
        "[grid]\nspeed = { start = 1.0, stop = 2.0, stpe = 0.5 }\n",
        r"unknown key 'stpe'; did you mean stop, step\?",
    ),
    ("[grid]\nspeed = { start = 2.0, stop = 1.0, step = 0.5 }\n", r"speed\.step = 0\.5 is not allowed"),
    ("[study]\nreplicates = 0\n", r"replicates = 0 is not allowed: expected an integer in \[1, 1000\]"),
    ("[grid]\nspeed = []\n", r"\[grid\] speed is empty"),
    ("[grid]\n", r"\[grid\] is empty"),
    (
        "[grid]\nspeed = [5.0, 10.0, 5.0]\n",
        r"duplicate runs: run 1 and run 3 resolve to the same scenario \(speed = 5.0\)",
    ),
    (
        '[[zip]]\nspeed = [5.0, 6.0]\n"terrain.height" = [0.1]\n',
        r"zipped axes must have equal lengths, got speed: 2, terrain.height: 1",
    ),
    ('[grid]\n"track.link_length" = [0.15]\n', r"track\.link_length|track is too short"),
    # unquoted dotted axes are tables to TOML: say to quote them
    (
        "[grid]\nterrain.height = [0.05, 0.1]\n",
        r"\[grid\]: terrain\.height = \.\.\. is read by TOML as a table "
        r"'terrain'; quote dotted names: \"terrain\.height\" = \[0\.05, 0\.1\]",
    ),
    (
        "[grid]\ncontact.friction = [0.1, 0.2]\n",
        r"quote dotted names: \"contact\.friction\" = \[0\.1, 0\.2\]",
    ),
    (
        "[[zip]]\nspeed = [1.0, 2.0]\nterrain.height = { start = 0.05, stop = 0.1, num = 2 }\n",
        r"\[\[zip\]\] #1: terrain\.height = \.\.\. is read by TOML as a table 'terrain'; quote dotted names",
    ),
]


@pytest.mark.parametrize("text,pattern", BAD)
def test_bad_input_is_one_line_naming_the_culprit(tmp_path, text, pattern):
    with pytest.raises(StudyError, match=pattern) as e:
        load_study(study(tmp_path, text))
    assert "\n" not in str(e.value)


def test_duplicate_explicit_runs(tmp_path):
    with pytest.raises(StudyError, match="duplicate runs: run 1 and run 2"):
        load_study(study(tmp_path, "[[runs]]\nspeed = 5.0\n[[runs]]\nspeed = 5\n"))


def test_missing_file():
    with pytest.raises(StudyError, match="nope.toml: cannot read the study file"):
        load_study("nope.toml")


@pytest.mark.parametrize(
    "text,args,pattern",
    [
        ("[grid]\nspeed = [5.0, 10.0\n", [], "TOML syntax error"),
        ("[grid]\nspeed = [5.0, 500.0]\n", [], "speed = 500.0 is not allowed"),
        ("[grid]\nspeed = [5.0]\n", ["--executor", "spark"], "--executor 'spark' is not allowed"),
        ("[grid]\nspeed = [5.0]\n", ["--workers", "0"], "--workers 0 is not allowed"),
    ],
)
def test_cli_bad_input_exits_2_and_touches_nothing(tmp_path, text, args, pattern):
    p = study(tmp_path, "[study]\nname = 'bad'\n" + text)
    existing = tmp_path / "results" / "bad"
    existing.mkdir(parents=True)
    (existing / "summary.csv").write_text("old\n")
    before = sorted((str(q), q.stat().st_mtime_ns) for q in existing.rglob("*"))
    r = subprocess.run(
        CLI + ["study", "run", str(p)] + args, cwd=tmp_path, capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 2, r.stderr
    err = r.stderr.strip()
    assert err.startswith("error: ") and pattern in err and "\n" not in err
    assert sorted((str(q), q.stat().st_mtime_ns) for q in existing.rglob("*")) == before
    assert not (existing / "runs").exists() and not (existing / ".lock").exists()
    assert os.listdir(tmp_path / "results") == ["bad"]
