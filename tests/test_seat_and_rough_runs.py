"""The driver's seat and rough ground in whole runs: the seat's acceleration against the
chassis' and against its own height twice differentiated, the ride metrics as summary
quantities, a run on an ISO 8608 profile (the ground it had kept in the Dataset, drawn in the
recording) and the one-line errors of rough ground that cannot be stood on or read."""

import math

import numpy as np
import pytest

import trackbench as tb
from trackbench.model.ground.rough import SPACING, random_profile
from trackbench.outputs import quantities
from trackbench.outputs.metrics.ride import (
    absorbed_power,
    peak_seat_acceleration_g,
    vdv,
    weighted_rms_acceleration,
)
from trackbench.scenario import ScenarioError

ROUGH = {"kind": "random", "roughness_class": "D", "run_in": 3.0, "seed": 7}


@pytest.fixture(scope="module")
def rough_run():
    """The paper's vehicle at 10 m/s onto class D ground 3 m ahead (the track's front is at
    2.6 m): 0.8 s, the front road wheel past the rough section's 5 m fade-in from 0.6 s."""
    return tb.simulate(tb.Scenario.paper(duration=0.8, terrain=ROUGH))


def test_seat_at_the_mass_centre_has_the_chassis_acceleration():
    ds = tb.simulate(tb.Scenario.paper(duration=0.15, **{"vehicle.seat_x": 0.0, "vehicle.seat_y": 0.0}))
    assert np.abs(ds.chassis_pitch_rate.values).max() > 0.05     # it pitches: the terms are there
    np.testing.assert_array_equal(ds.seat_acceleration_y.values, ds.chassis_ay.values)


def test_seat_acceleration_is_the_rigid_body_formula(paper_run):
    ds = paper_run
    sc = tb.Scenario.paper()
    sx, sy = sc["vehicle.seat_x"], sc["vehicle.seat_y"]
    th, om, al = ds.chassis_pitch.values, ds.chassis_pitch_rate.values, ds.chassis_pitch_acceleration.values
    expected = ds.chassis_ay.values + al * (np.cos(th) * sx - np.sin(th) * sy) - om**2 * (
        np.sin(th) * sx + np.cos(th) * sy)
    assert np.abs(al).max() > 10.0 and abs(th).max() > 0.01      # a run with pitch
    np.testing.assert_allclose(ds.seat_acceleration_y.values, expected, rtol=0, atol=1e-9)


def test_seat_acceleration_is_its_height_twice_differentiated():
    """Independent of the formula: the seat's height from the chassis' samples, by central
    second differences, against seat_acceleration_y (the signs of pitch and its rates).
    Samples 2e-5 s apart: the pads ring at ~300 Hz, which 1e-4 s differences blur by 0.3 %."""
    sc = tb.Scenario.paper(duration=0.2, output_interval=2e-5)
    ds = tb.simulate(sc)
    th = ds.chassis_pitch.values
    height = ds.chassis_y.values + np.sin(th) * sc["vehicle.seat_x"] + np.cos(th) * sc["vehicle.seat_y"]
    dt = sc["output_interval"]
    fd = (height[2:] - 2 * height[1:-1] + height[:-2]) / dt**2
    a = ds.seat_acceleration_y.values[1:-1]
    early = ds.time.values[1:-1] < 0.2       # before the late impacts, whose kinks dt blurs
    err = np.sqrt(np.mean((fd[early] - a[early]) ** 2)) / np.sqrt(np.mean(a[early] ** 2))
    assert err < 1e-3
    # a seat ahead of the mass centre differs from the chassis' by the pitch acceleration
    assert np.abs(a - ds.chassis_ay.values[1:-1]).max() > 1.0


def test_ride_metrics_are_summary_quantities_computed_from_the_seat(paper_run):
    ds = paper_run
    a, dt = ds.seat_acceleration_y.values, tb.Scenario.paper()["output_interval"]
    settle = 0.5 * float(ds.time[-1])
    summary = quantities.run_summary(ds)
    assert summary["peak_seat_acceleration_g"] == peak_seat_acceleration_g(a, dt)
    assert summary["absorbed_power"] == absorbed_power(a, dt, settle)
    assert summary["weighted_rms_acceleration"] == weighted_rms_acceleration(a, dt, settle)
    assert summary["vdv"] == vdv(a, dt, settle)
    t_peak = summary["peak_seat_acceleration_g_time"]
    assert 0.0 < t_peak <= 0.5 and summary["peak_seat_acceleration_g"] > 0.5
    for name in ("peak_seat_acceleration_g", "absorbed_power", "weighted_rms_acceleration", "vdv"):
        assert name in quantities.summary_columns(5)


def test_ride_metrics_are_nan_for_samples_too_far_apart():
    ds = tb.simulate(tb.Scenario.paper(duration=0.05, output_interval=0.01))
    assert math.isnan(float(ds.absorbed_power)) and math.isnan(float(ds.peak_seat_acceleration_g))
    assert np.isfinite(ds.seat_acceleration_y.values).all()


def test_a_run_on_random_ground_keeps_its_profile(rough_run):
    ds = rough_run
    assert ds.attrs["status"] == "completed"
    x, h = random_profile(100.0, 7, "D", wavelength_min=0.5, wavelength_max=20.0, dx=SPACING, run_in=3.0)
    np.testing.assert_array_equal(np.interp(x, ds.ground_x.values, ds.ground_y.values), h)
    assert ds.ground_x.size > 2000 and np.ptp(h) > 0.05
    # the rough section is an obstacle: its first touch is a first contact
    assert 0.0 < float(ds.first_contact_time) < 0.2
    assert np.ptp(ds.wheel_y.sel(wheel=1).values) > 0.01


def test_the_recording_draws_the_rough_ground(rough_run):
    from trackbench.outputs.geometry import covered_x_range, ground_polyline

    v = ground_polyline(rough_run)
    lo, hi = covered_x_range(rough_run)
    inside = (rough_run.ground_x.values > lo) & (rough_run.ground_x.values < hi)
    assert len(v) >= inside.sum() > 50
    # every vertex inside, and the ends cut where the range ends (interpolated: to rounding)
    assert set(rough_run.ground_x.values[inside]) <= set(v[:, 0])
    on_ground = np.interp(v[:, 0], rough_run.ground_x, rough_run.ground_y)
    np.testing.assert_allclose(on_ground, v[:, 1], atol=1e-15)


def test_ground_the_vehicle_cannot_stand_on_is_refused_in_one_line(tmp_path):
    with pytest.raises(ScenarioError) as e:
        tb.simulate(tb.Scenario.paper(terrain={**ROUGH, "run_in": 0.0}))
    assert "cannot stand on the ground at the start" in str(e.value) and "\n" not in str(e.value)
    p = tmp_path / "course.csv"
    p.write_text("x,height\n-50,0.0\n0,0.0\n1,0.2\n50,0.2\n")     # a ramp under the resting track
    with pytest.raises(ScenarioError) as e:
        tb.simulate(tb.Scenario.paper(terrain={"kind": "profile", "file": str(p)}))
    assert "heights vary by 0.2 m" in str(e.value) and "\n" not in str(e.value)


def test_a_run_that_never_reaches_the_rough_ground_is_refused_in_one_line():
    with pytest.raises(ScenarioError) as e:
        tb.simulate(tb.Scenario.paper(duration=0.5, terrain={**ROUGH, "run_in": 10.0}))
    assert "the run ends before the track reaches the rough ground" in str(e.value)
    assert "run_in below 7.56 m" in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("terrain, fragment", [
    ({"kind": "random"}, "terrain: neither roughness_class nor rms is given"),
    ({"kind": "random", "roughness_class": "J"}, "terrain.roughness_class = 'J' is not allowed"),
    ({"kind": "random", "rms": 0.01, "wavelength_max": 300.0}, "terrain.wavelength_max = 300.0 m"),
    ({"kind": "random", "rms": 0.01, "height": 0.1}, "terrain.height does not apply to kind 'random'"),
    ({"kind": "profile"}, "terrain.file is missing"),
    ({"kind": "profile", "file": "no_such_course.csv"}, "terrain.file: profile file 'no_such_course.csv' "
                                                         "does not exist"),
])
def test_bad_rough_ground_fails_in_one_line(terrain, fragment):
    with pytest.raises(ScenarioError) as e:
        tb.Scenario.paper(terrain=terrain)
    assert fragment in str(e.value) and "\n" not in str(e.value)


def test_a_study_reads_its_profile_beside_the_study_file(tmp_path, monkeypatch):
    from trackbench.study.spec.study_file import load_study

    (tmp_path / "courses").mkdir()
    (tmp_path / "courses" / "course.csv").write_text("x,height\n0,0\n10,0\n11,0.05\n12,0\n")
    study = tmp_path / "courses" / "ride.toml"
    study.write_text('[scenario]\nterrain = { kind = "profile", file = "course.csv" }\n')
    monkeypatch.chdir(tmp_path)          # elsewhere: the path is the study file's, not the shell's
    s = load_study(study)
    assert s.runs[0].scenario["terrain"]["file"] == str(tmp_path / "courses" / "course.csv")


def test_a_long_course_holds_candidate_rows_by_its_length_not_its_square():
    """600 m of rough ground (16,385 segments): the candidate rows hold SEGMENT_CANDIDATES
    segments each (before, as many as the ground has: 2 GB an array), and the run goes."""
    from trackbench.model.core.indices import SEGMENT_CANDIDATES
    from trackbench.run.assemble import Model, equilibrium
    from trackbench.run.simulate import build_ground

    sc = tb.Scenario.paper(duration=0.05, terrain={**ROUGH, "length": 600.0})
    eq = equilibrium(sc)
    ground, _ = build_ground(sc, eq)
    arrays = Model(sc, eq, ground).arrays
    assert ground.segments.shape[0] > 16_000 and arrays.nbr.shape[1] == 1 + SEGMENT_CANDIDATES
    assert arrays.nbr.nbytes + arrays.v0.nbytes < 100e6
    assert tb.simulate(sc).attrs["status"] == "completed"


def test_a_ground_too_dense_for_the_candidate_rows_stops_the_run_saying_so(tmp_path):
    """1,000 segments of 0.2 mm under the track (wiggles of 1e-7 m: flat enough to stand on,
    no straight run to merge): more than a row holds near one pin."""
    x = np.concatenate([[-50.0], np.linspace(0.0, 0.2, 1001), [50.0]])
    h = np.concatenate([[0.0], 1e-7 * (np.arange(1001) % 2), [0.0]])
    p = tmp_path / "dense.csv"
    p.write_text("x,height\n" + "\n".join(f"{a!r},{b!r}" for a, b in zip(x.tolist(), h.tolist())))
    ds = tb.simulate(tb.Scenario.paper(duration=0.01, terrain={"kind": "profile", "file": str(p)}))
    assert ds.attrs["status"] == "failed" and "too dense" in ds.attrs["status_message"]


def test_restitution_laws_on_a_long_ground_are_refused_in_one_line():
    with pytest.raises(ScenarioError) as e:
        tb.simulate(tb.Scenario.paper(terrain=ROUGH, **{"contact.damping": "hunt_crossley",
                                                        "contact.restitution": 0.75}))
    assert "contact.damping = 'hunt_crossley' cannot run on this ground" in str(e.value)
    assert "\n" not in str(e.value)


def test_a_long_run_is_replayed_following_the_chassis(tmp_path, rough_run):
    """A run covering more than 20 m of ground is seen in a window about the chassis, the
    world moved under it frame by frame; a short run whole, as before."""
    from trackbench.outputs.geometry import follow_window
    from trackbench.outputs.recording.record import write_recording

    assert follow_window(rough_run) is None                      # 8 m covered
    ds = tb.simulate(tb.Scenario.paper(duration=2.5, terrain={"kind": "flat"}))   # 25 m
    lo, hi = follow_window(ds)
    assert -4.5 < lo < -3.0 and 3.0 < hi < 4.5                   # the track and a metre each side
    text = write_recording(ds, tmp_path / "long.rrd", every=20).read_bytes()
    short = write_recording(rough_run, tmp_path / "short.rrd", every=20).read_bytes()
    assert b"following the chassis" in text and b"Translation3D" in text     # the world moves
    assert b"following the chassis" not in short and b"Translation3D" not in short
