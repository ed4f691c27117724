"""Bad input: a clear one-line error naming the parameter and what is allowed, before anything runs."""

import math
import subprocess
import sys

import pytest

import trackbench as tb
from trackbench.scenario import ScenarioError


def error_of(**kw):
    with pytest.raises(ScenarioError) as e:
        tb.Scenario.from_dict(kw)
    msg = str(e.value)
    assert "\n" not in msg
    return msg


def test_unknown_names_list_close_matches():
    assert "vehicle.chassis_mass" in error_of(**{"vehicle.chasis_mass": 1.0})
    assert "speed" in error_of(sped=10.0)
    assert "track.link_length" in error_of(track={"link_lenght": 0.2})


@pytest.mark.parametrize(
    "name",
    [
        "vehicle.chassis_mass",
        "vehicle.arm_inertia",
        "track.pin_mass",
        "track.link_stiffness",
        "track.wheel_stiffness",
        "track.link_length",
        "vehicle.wheel_radius",
        "duration",
        "output_interval",
    ],
)
@pytest.mark.parametrize("value", [0.0, -1.0, math.nan])
def test_non_positive_or_nan_values(name, value):
    msg = error_of(**{name: value})
    assert name in msg and ("> 0" in msg or "in (0" in msg)


def test_wrong_types_and_choices():
    assert "one of reduced, lee" in error_of(solver="rk4")
    assert "integer" in error_of(**{"vehicle.n_wheels": 2.5})
    assert "terrain.height" in error_of(terrain={"kind": "step", "height": -0.1})
    assert "terrain.kind" in error_of(terrain={"kind": "cliff"})
    assert "does not apply" in error_of(terrain={"kind": "flat", "height": 0.1})
    assert "x must be non-decreasing" in error_of(terrain={"kind": "points", "points": [[0, 0], [-1, 0.1]]})


def test_geometry_that_does_not_fit():
    assert "too long" in error_of(**{"track.n_links": 40})
    assert "too short" in error_of(**{"track.link_length": 0.15})
    assert "overlap" in error_of(**{"vehicle.pivot_spacing": 0.5})
    assert "track_end" in error_of(**{"vehicle.front_track_end": [1.0, 0.0]})


def test_valid_overrides_resolve():
    sc = tb.Scenario.from_dict({"speed": 15, "terrain.height": 0.15})
    assert sc["speed"] == 15.0 and sc["terrain"]["height"] == 0.15
    assert sc["terrain"]["first_contact_time"] == 0.0568
    assert sc["vehicle"]["chassis_mass"] == 20000.0


def test_cli_bad_input_is_one_line_and_nothing_written(tmp_path):
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "trackbench.cli",
            "run",
            "--set",
            "vehicle.chassis_mas=1",
            "--out",
            str(tmp_path / "o"),
        ],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0 and "vehicle.chassis_mass" in r.stderr
    assert not (tmp_path / "o").exists()


def test_cli_run_writes_netcdf(tmp_path):
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "trackbench.cli",
            "run",
            "--set",
            "speed=12",
            "--duration",
            "0.07",
            "--out",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr
    assert "wheel 1" in r.stdout and "energy balance" in r.stdout
    import xarray as xr

    ds = xr.load_dataset(tmp_path / "paper_step.nc")
    assert ds.attrs["status"] == "completed"
    assert float(ds.chassis_vx[0]) == 12.0
    assert ds.sizes["time"] == 701
    for v in ("chassis_ay", "wheel_force_y", "link_tension", "pin_x", "energy_balance", "energy_residual"):
        assert "units" in ds[v].attrs


def test_cli_run_never_overwrites_and_marks_failures(tmp_path):
    run = [sys.executable, "-m", "trackbench.cli", "run", "--duration", "0.01", "--out", str(tmp_path)]
    assert subprocess.run(run, capture_output=True, text=True).returncode == 0
    first = (tmp_path / "paper_step.nc").stat().st_mtime_ns
    r = subprocess.run(run + ["--set", "speed=12"], capture_output=True, text=True)
    assert r.returncode == 2 and "--force" in r.stderr
    assert (tmp_path / "paper_step.nc").stat().st_mtime_ns == first
    # a run that fails is kept for diagnosis under a name that says so, exit code 1
    r = subprocess.run(run + ["--name", "short", "--set", "max_steps=5"], capture_output=True, text=True)
    assert r.returncode == 1 and "failed" in r.stdout
    assert (tmp_path / "short.failed.nc").exists() and not (tmp_path / "short.nc").exists()
