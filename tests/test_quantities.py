"""The summary quantities are one table (trackbench/quantities.py): every place that shows
or stores a run's summary reads it, and it matches the Dataset."""

import json

import pandas as pd
import pytest

from trackbench.figures.plots import study_axes
from trackbench.outputs import dataset as output
from trackbench.outputs import quantities
from trackbench.outputs.quantities import run_summary

SI_OF = {"kN": "N", "kN m": "N m", "m/s^2": "m s-2", "m/s": "m s-1", "s": "s", "1": "1", "cm": "m", "%": "1",
         "g": "1", "W": "W", "m/s^1.75": "m s-1.75"}


def test_the_table_matches_the_dataset(paper_run_short):
    """Every quantity is a Dataset variable whose SI unit its display unit converts from;
    each peak has its _time."""
    _check_table(paper_run_short, [q for q in quantities.TABLE if not q.needs])
    assert not any(q.variable in paper_run_short for q in quantities.TABLE if q.needs)


def _check_table(ds, table):
    for q in table:
        var = ds[q.variable]
        assert var.attrs["units"] == SI_OF[q.unit], q.variable
        assert var.dims == (("wheel",) if q.per_wheel else ()), q.variable
        assert q.kind in ("peak", "mean", "event", "check")
        if q.kind == "peak":
            assert ds[q.variable + "_time"].attrs["units"] == "s"


def test_the_closed_track_quantities_match_its_dataset():
    import trackbench as tb

    ds = tb.simulate(
        tb.Scenario.from_dict(
            {"track.layout": "closed", "duration": 2e-3, "speed": 0.0, "terrain": {"kind": "flat"}}
        )
    )
    _check_table(ds, [q for q in quantities.TABLE if q.needs != "soil"])
    cols = [c for q, c, _, _ in quantities.entries(ds)]
    assert "peak_sprocket_torque" in cols and "peak_idler_force" in cols
    assert "peak_sprocket_torque" in quantities.summary_columns(5, features={"closed"})
    assert "peak_sprocket_torque" not in quantities.summary_columns(5)


def test_the_soil_quantities_match_their_dataset():
    """Deepest sinkage (the soil's memory: every accepted step), drawbar pull and slip means
    over the run's second half, in the summary of a driven closed track on soil."""
    import trackbench as tb

    ds = tb.simulate(
        tb.Scenario.from_dict(
            {
                "track.layout": "closed",
                "terrain": {"kind": "flat", "soil": "lete_sand"},
                "drive.kind": "speed",
                "speed": 4.0,
                "duration": 0.05,
            }
        )
    )
    _check_table(ds, quantities.TABLE)
    v = quantities.values(ds)
    assert v["peak_sinkage"] >= float(ds.sinkage.max()) > 0.0
    late = ds.time.values >= 0.025
    assert v["mean_drawbar_pull"] == float(ds.drawbar_pull[late].mean())
    rp = json.loads(ds.attrs["closed_layout"])["pitch_radius"]
    travelled, laid = ds.chassis_vx.values[late].mean(), (ds.sprocket_speed.values[late] * rp).mean()
    assert v["mean_slip"] == pytest.approx(1.0 - travelled / laid, rel=1e-12)
    assert "mean_slip" in quantities.peak_columns(5, features={"soil"})
    assert "peak_sinkage" not in quantities.summary_columns(5, features={"closed"})


def test_summary_columns_in_the_documented_order():
    wheels = [c for w in (1, 2) for c in (f"peak_wheel{w}_force_y", f"peak_wheel{w}_force_y_time")]
    assert quantities.summary_columns(2) == wheels + [
        "peak_ground_force_y",
        "peak_ground_force_y_time",
        "peak_link_tension",
        "peak_link_tension_time",
        "peak_chassis_ay",
        "peak_chassis_ay_time",
        "min_chassis_ay",
        "min_chassis_ay_time",
        "min_chassis_vx",
        "min_chassis_vx_time",
        "peak_seat_acceleration_g",
        "peak_seat_acceleration_g_time",
        "absorbed_power",
        "weighted_rms_acceleration",
        "vdv",
        "first_contact_time",
        "first_compression_time",
        "max_energy_balance_error",
        "max_energy_residual",
    ]
    assert quantities.peak_columns(2) == wheels[0::2] + [
        "peak_ground_force_y",
        "peak_link_tension",
        "peak_chassis_ay",
        "min_chassis_ay",
        "min_chassis_vx",
        "peak_seat_acceleration_g",
        "absorbed_power",
        "weighted_rms_acceleration",
        "vdv",
    ]


def test_run_json_screen_summary_and_table_agree(paper_run_short):
    v = quantities.values(paper_run_short)
    assert list(v) == quantities.summary_columns(paper_run_short.sizes["wheel"])
    assert list(run_summary(paper_run_short)) == list(v)
    assert v["peak_wheel3_force_y"] == float(paper_run_short.peak_wheel_force_y.sel(wheel=3))
    assert v["min_chassis_vx_time"] == float(paper_run_short.min_chassis_vx_time)
    s = output.summary_numbers(paper_run_short)
    assert (
        s["peak_link_tension_kN"] == v["peak_link_tension"] / 1e3
        and s["peak_chassis_ay"] == v["peak_chassis_ay"]
    )
    assert "min_link_tension" not in v and "min_link_tension_kN" not in s  # in the Dataset, not the summary
    for c in v:
        q, wheel = quantities.quantity_of(c)
        assert (wheel is not None) == q.per_wheel


def test_a_placement_parameter_ending_in_time_is_a_study_axis():
    df = pd.DataFrame(
        {
            "terrain.first_contact_time": [0.05, 0.06],
            "peak_wheel12_force_y": [1.0, 2.0],
            "max_energy_residual": [1e-9, 2e-9],
            "peak_link_tension_time": [0.1, 0.2],
        }
    )
    assert study_axes(df) == ["terrain.first_contact_time"]
