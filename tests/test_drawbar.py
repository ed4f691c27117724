"""The drawbar on the closed track's chassis (model/drive.py): its input, its force and work,
and the drawbar test on LETE sand against Wong's closed form (trackbench/traction.py)."""

import functools
import math

import numpy as np
import pytest

import trackbench as tb
from trackbench.model.core import indices as L
from trackbench.model.vehicle.drive import drawbar_on_chassis, held_speed
from trackbench.outputs.metrics.traction import pressure_effect, run_soil, steady, wong
from trackbench.scenario import ScenarioError

CLOSED = {"track.layout": "closed"}


@pytest.mark.parametrize(
    "over, words",
    [
        ({"drawbar.load": 1e3, "track.layout": "paper"}, "closed track only"),
        ({**CLOSED, "drawbar.slip": 0.2}, "needs drive.kind = 'speed'"),
        ({**CLOSED, "drive.kind": "speed", "drawbar.slip": 0.99}, "[0, 0.95]"),
        ({**CLOSED, "drawbar.hitch": [1.0]}, "pair [x, y]"),
        ({**CLOSED, "drawbar.hitch": [1.0, math.inf]}, "pair [x, y]"),
        ({**CLOSED, "drawbar.rig_damping": 0.0}, "> 0"),
        ({**CLOSED, "drawbar.lod": 1.0}, "did you mean drawbar.load"),
    ],
)
def test_bad_drawbar(over, words):
    with pytest.raises(ScenarioError) as e:
        tb.Scenario.from_dict(over)
    assert words in str(e.value) and "\n" not in str(e.value)


def test_drawbar_force_torque_and_power():
    """The load and the rig's dashpot at a hitch below the mass centre: force, its moment
    about the mass centre and its power at the hitch's speed."""
    lp = np.zeros(L.N_LOOP)
    lp[L.LP_DRAWBAR_LOAD] = 1e4
    lp[L.LP_HITCH_X], lp[L.LP_HITCH_Y] = -2.0, -0.5
    lp[L.LP_RIG_SLIP], lp[L.LP_RIG_DAMPING], lp[L.LP_TARGET], lp[L.LP_PITCH_RADIUS] = 0.2, 1e6, 4.0, 0.3
    vx, om = 4.01, 0.1  # level chassis: the hitch moves at vx - om * (-0.5)
    f, torque, power = drawbar_on_chassis(lp, vx, om, 1.0, 0.0)
    v_hitch = vx + 0.5 * om
    assert f == pytest.approx(-1e4 - 1e6 * (v_hitch - 4.0))
    assert torque == pytest.approx(0.5 * f)  # a rearward pull below the centre pitches the nose up
    assert power == pytest.approx(f * v_hitch)
    assert held_speed(lp, vx, 20.0) == pytest.approx(20.0 * 0.3 * 0.8)  # the rig: the sprocket's speed
    lp[L.LP_RIG_SLIP] = 0.0
    assert held_speed(lp, vx, 20.0) == vx


def test_constant_load_is_taken_by_the_drive_and_its_work_is_booked():
    """A constant 20 kN drawbar at a low rear hitch on the speed-driven closed track on LETE
    sand: the chassis' momentum balance (ground's horizontal force - load = mass x
    acceleration, on average), and the work-based energy residual stays below 1e-6 of E0
    with the drawbar's work in it."""
    sc = tb.Scenario.from_dict(
        {
            **CLOSED,
            "terrain": {"kind": "flat", "soil": "lete_sand"},
            "preset": "damped",
            "drive.kind": "speed",
            "speed": 4.0,
            "drawbar.load": 2e4,
            "drawbar.hitch": [-3.0, -0.4],
            "duration": 0.3,
            "output_interval": 1e-3,
        }
    )
    ds = tb.simulate(sc)
    assert ds.attrs["status"] == "completed"
    assert np.allclose(ds.drawbar_load.values, 2e4)
    mass = float(ds.attrs["weight"]) / sc["gravity"]
    dv = ds.chassis_vx.values[-1] - ds.chassis_vx.values[0]
    impulse = np.trapezoid(ds.drawbar_pull.values - ds.drawbar_load.values, ds.time.values)
    assert dv == pytest.approx(impulse / mass, abs=0.02)  # the track's own momentum swings a little
    assert float(abs(ds.energy_residual).max()) < 1e-6


STIFF_LINKS = 8e7  # N/m: ten times the paper's links; Wong's track is inextensible (docs/validation.md)


@functools.lru_cache(maxsize=None)
def _drawbar_run(slip, duration, since):
    """benchmarks/bench_soil.py's drawbar test with stiff links, `duration` s: the figures
    over t >= since, Wong's thrust under uniform pressure, the same with the pins' own
    pressures (traction.pressure_effect), and thrust / W over each half of that window.
    Cached: two tests read each run."""
    sc = tb.Scenario.from_dict(
        {
            "terrain": {"kind": "flat", "soil": "lete_sand"},
            **CLOSED,
            "preset": "damped",
            "drive.kind": "speed",
            "speed": 4.0,
            "drive.gain_p": 2e5,
            "drive.gain_i": 2e6,
            "drive.torque_limit": 1e5,
            "drawbar.slip": slip,
            "track.link_stiffness": STIFF_LINKS,
            "duration": duration,
            "output_interval": 2e-3,
        }
    )
    ds = tb.simulate(sc)
    assert ds.attrs["status"] == "completed"
    assert float(abs(ds.energy_residual).max()) < 1e-6
    fig = steady(ds, since)
    middle = 0.5 * (since + duration)
    halves = [
        steady(part, start) for part, start in ((ds.sel(time=slice(since, middle)), since), (ds, middle))
    ]
    soil = run_soil(ds)
    f_wong = wong(fig, soil)[0]
    own, equal = pressure_effect(ds, since, fig["track_slip"], soil)
    return fig, f_wong, f_wong * own / equal, [h["thrust"] / h["weight"] for h in halves]


RUNS = [(0.05, 4.0, 2.0), (0.3, 1.2, 0.6)]


@pytest.mark.parametrize("slip, duration, since", RUNS)
def test_thrust_against_slip_matches_wong_within_5_percent(slip, duration, since):
    """Gross thrust (the soil shear's x, = drawbar_pull on flat soil) of the vehicle held at a
    slip by the towing rig, against Wong's closed form at the slip the soil sees
    (traction.track_slip), over the pins' own pressures (each pin's Bekker share of the
    weight, traction.pressure_effect; the road wheels load the pins under them most): within
    3 % (measured: 2 % at most over runs nudged by 1e-9 m). That holds the model's shear to
    Wong's theory for the pressures the model itself finds, not those to an outside figure
    (the uniform form below does that), and steady: thrust / W alike (5 %) over the two
    halves of the window (W swings with the vehicle's bounce at high slip, the thrust with
    it; a thrust still settling, as with the paper's links, rises 10-60 % from one half to
    the next). The rig holds the sprocket's slip to 0.02 of the set one, and the drawbar
    takes the thrust (steady: the mean horizontal momentum does not change). Stiff links, as
    Wong's inextensible track: the paper's (8e6 N/m) stretch with the ground run's tension,
    so that the front of the contact slips less than the rear, and the thrust settles 11 %
    below Wong's at 5 % set (benchmarks/bench_soil.py, docs/validation.md). At low slip the
    thrust takes ~2 s to settle: its rise stretches the links more."""
    fig, _, f_own, halves = _drawbar_run(slip, duration, since)
    assert fig["slip"] == pytest.approx(slip, abs=0.02)
    assert fig["drawbar_load"] == pytest.approx(fig["thrust"], rel=0.03)
    assert halves[1] == pytest.approx(halves[0], rel=0.05)
    assert fig["thrust"] == pytest.approx(f_own, rel=0.03)


@pytest.mark.parametrize(
    "slip, duration, since",
    [
        pytest.param(
            *RUNS[0],
            marks=pytest.mark.xfail(
                strict=True,
                raises=AssertionError,
                reason=(
                    "at 5 % slip set (2 % at the soil) the thrust is 6.4 % above Wong's form for a uniformly "
                    "loaded track (five runs nudged by 1e-9 m: +5.6 to +6.5 %): the road wheels load the "
                    "pins under them most, and Wong's integral over the pins' own pressures is 8.1 % above "
                    "the uniform one; the thrust is within 1.6 % of that (the test above; docs/validation.md)"
                ),
            ),
        ),
        RUNS[1],
    ],
)
def test_thrust_matches_wong_for_a_uniformly_loaded_track(slip, duration, since):
    """The textbook form: Wong's closed form for a track of the same contact length, area and
    weight under uniform pressure, within 5 %."""
    fig, f_wong, _, _ = _drawbar_run(slip, duration, since)
    assert fig["thrust"] == pytest.approx(f_wong, rel=0.05)


def _fake_soil_run(path, slip, pull):
    """A timeseries.nc with what the drawbar-pull plot reads: a closed run on LETE sand."""
    import json

    import xarray as xr

    t = np.linspace(0.0, 1.0, 11)
    sink = np.zeros((t.size, 4))
    sink[:, :3] = 0.01
    pin_x = np.array([0.4, 0.2, 0.0, -0.2]) - 4.0 * slip / (1.0 - slip) * t[:, None]  # track slip = slip
    sc = {"terrain": {"kind": "flat", "soil": "lete_sand"}, "track": {"link_length": 0.19, "width": 0.5}}
    ds = xr.Dataset(
        {
            "slip": ("time", np.full(t.size, slip)),
            "chassis_vx": ("time", np.full(t.size, 4.0)),
            "sprocket_speed": ("time", np.full(t.size, 4.0 / (1.0 - slip) / 0.3)),  # pitch radius 0.3
            "drawbar_pull": ("time", np.full(t.size, pull)),
            "drawbar_load": ("time", np.full(t.size, pull)),
            "sprocket_torque": ("time", np.full(t.size, 1e4)),
            "ground_force_y": ("time", np.full(t.size, 2e5)),
            "sinkage": (("time", "pin"), sink),
            "pin_x": (("time", "pin"), pin_x),
        },
        coords={"time": t},
        attrs={"scenario": json.dumps(sc), "closed_layout": json.dumps({"pitch_radius": 0.3})},
    )
    path.parent.mkdir(parents=True)
    ds.to_netcdf(path)


def test_study_plot_draws_drawbar_pull_against_slip(tmp_path):
    pytest.importorskip("matplotlib")
    import pandas as pd

    from trackbench.figures.plots import plot_study

    rows = []
    for k, (slip, pull) in enumerate(((0.1, 1.2e5), (0.3, 1.3e5))):
        _fake_soil_run(tmp_path / "runs" / f"r{k}" / "timeseries.nc", slip, pull)
        rows.append(
            {"run_id": f"r{k}", "status": "completed", "drawbar.slip": slip, "peak_wheel1_force_y": 1e5}
        )
    pd.DataFrame(rows).to_csv(tmp_path / "summary.csv", index=False)
    paths = plot_study(tmp_path, tmp_path / "plots")
    assert tmp_path / "plots" / "study_drawbar_pull.png" in paths
    assert (tmp_path / "plots" / "study_drawbar_pull.png").stat().st_size > 10_000


def test_study_plot_leaves_out_drawbar_pull_without_a_drawbar(tmp_path):
    """A soft-soil study of free-running speeds (no drawbar axis, none set): no pull-against-slip figure."""
    pytest.importorskip("matplotlib")
    import pandas as pd

    from trackbench.figures.plots import plot_study

    rows = []
    for k, (speed, slip, pull) in enumerate(((3.0, 0.02, -100.0), (6.0, 0.04, 2.6e3))):
        _fake_soil_run(tmp_path / "runs" / f"r{k}" / "timeseries.nc", slip, pull)
        rows.append({"run_id": f"r{k}", "status": "completed", "speed": speed, "peak_wheel1_force_y": 1e5})
    pd.DataFrame(rows).to_csv(tmp_path / "summary.csv", index=False)
    paths = plot_study(tmp_path, tmp_path / "plots")
    assert [p.name for p in paths] == ["study_speed.png"]
