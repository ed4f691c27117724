"""The rerun recording (read back with rerun's own reader), the plots, `trackbench view`."""

import json

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from rerun.chunk import RrdReader
from typer.testing import CliRunner

import trackbench as tb
from trackbench.cli import view as V
from trackbench.cli.app import app
from trackbench.figures.plots import plot_run, plot_study, study_axes
from trackbench.outputs import geometry as G
from trackbench.outputs.files.netcdf import write_netcdf
from trackbench.outputs.recording import entities as E
from trackbench.outputs.recording import record as R
from trackbench.outputs.recording import soil_view as S

GEOMETRY = (E.E_CHASSIS, E.E_ARMS, E.E_WHEELS, E.E_LINKS, E.E_PINS, E.E_WHEEL_FORCE, E.E_GROUND_FORCE)


@pytest.fixture(scope="session")
def step_run():
    """paper_step to 0.12 s: the step is hit at 0.0568 s, so the front of the track is on it."""
    return tb.simulate(tb.Scenario.paper(duration=0.12))


@pytest.fixture(scope="session")
def run_folder(step_run, tmp_path_factory):
    """A run folder like a study's: timeseries.nc and recording.rrd side by side."""
    d = tmp_path_factory.mktemp("study") / "runs" / "abcdef0123"
    write_netcdf(step_run, d / "timeseries.nc")
    R.write_recording(step_run, d / "recording.rrd")
    return d


def read_temporal(path):
    """entity path -> {column name -> list of per-row values}, rows sorted by sim_time."""
    by_entity = {}
    for c in RrdReader(path).stream().to_chunks():
        if E.TIMELINE not in c.timeline_names:
            continue
        rb = c.to_record_batch()
        cols = by_entity.setdefault(c.entity_path, {})
        for name in rb.schema.names:
            if "RowId" in name:
                continue
            cols.setdefault(name, []).extend(rb.column(name).to_pylist())
    for cols in by_entity.values():
        order = np.argsort(
            [t.total_seconds() if hasattr(t, "total_seconds") else t for t in cols[E.TIMELINE]], kind="stable"
        )
        for k in cols:
            cols[k] = [cols[k][i] for i in order]
    return by_entity


def static_entities(path):
    return {c.entity_path for c in RrdReader(path).stream().to_chunks() if not c.timeline_names}


def seconds(col):
    return np.array([t.total_seconds() for t in col])


def test_recording_has_every_entity_and_one_row_per_netcdf_frame(run_folder):
    nc = xr.load_dataset(run_folder / "timeseries.nc")
    n = nc.sizes["time"]
    data = read_temporal(run_folder / "recording.rrd")
    signals = [E.E_WHEEL_FY, E.E_AY, E.E_VX, E.E_TENSION, E.E_ENERGY]
    for e in GEOMETRY + tuple(signals):
        assert e in data, f"{e} missing from the recording"
        t = seconds(data[e][E.TIMELINE])
        assert len(t) == n, e
        np.testing.assert_allclose(t, nc["time"].values, atol=1e-9)
    static = static_entities(run_folder / "recording.rrd")
    for e in (E.E_GROUND, E.E_PARAMS, E.E_SOLVER):
        assert e in static
    # per-frame instance counts: 5 wheels, 30 links, 31 pins
    assert {len(v) for v in data[E.E_WHEELS]["Ellipses2D:centers"]} == {5}
    assert {len(v) for v in data[E.E_LINKS]["LineStrips2D:strips"]} == {30}
    assert {len(v) for v in data[E.E_PINS]["Points2D:positions"]} == {31}


def test_logged_values_equal_the_dataset(run_folder, step_run):
    data = read_temporal(run_folder / "recording.rrd")
    got = np.array(data[E.E_WHEEL_FY]["Scalars:scalars"])  # (n, 5): one scalar per wheel
    np.testing.assert_array_equal(got, step_run["wheel_force_y"].values)
    energy = np.array(data[E.E_ENERGY]["Scalars:scalars"])
    np.testing.assert_array_equal(energy[:, 0], step_run["energy_kinetic"].values)
    np.testing.assert_array_equal(energy[:, 3], step_run["energy_balance"].values)
    assert np.max(step_run["wheel_force_y"].values) > 1e5  # the step was hit: not a constant signal
    got_ay = np.array([v[0] for v in data[E.E_AY]["Scalars:scalars"]])
    np.testing.assert_array_equal(got_ay, step_run["chassis_ay"].values)
    # the side view is logged with y negated (rerun's 2D views draw y downwards), float32
    vec = np.array(data[E.E_WHEEL_FORCE]["Arrows2D:vectors"], dtype=float)  # (n, 5, 2)
    f = (
        np.stack([step_run["wheel_force_x"].values, -step_run["wheel_force_y"].values], axis=-1)
        * G.FORCE_SCALE
    )
    np.testing.assert_allclose(vec, f, rtol=1e-6, atol=1e-6)
    pins = np.array(data[E.E_PINS]["Points2D:positions"], dtype=float)
    np.testing.assert_allclose(pins[..., 0], step_run["pin_x"].values, atol=1e-5)
    np.testing.assert_allclose(pins[..., 1], -step_run["pin_y"].values, atol=1e-5)
    # link colours follow the tension
    colors = np.array(data[E.E_LINKS]["LineStrips2D:colors"], dtype=np.uint32)
    np.testing.assert_array_equal(colors, G.tension_rgba32(step_run["link_tension"].values))
    # chassis outline: closed, its first corner (rear, bottom) is the rotated body point
    hull = np.array(data[E.E_CHASSIS]["LineStrips2D:strips"], dtype=float)[:, 0]  # (n, 5, 2)
    np.testing.assert_allclose(hull[:, 0], hull[:, -1])
    body = np.array(json.loads(step_run.attrs["track_ends"]))
    c, s = np.cos(step_run["chassis_pitch"].values), np.sin(step_run["chassis_pitch"].values)
    bx, by = body[:, 0].min() - G.HULL_MARGIN, G.HULL_BOTTOM
    np.testing.assert_allclose(hull[:, 0, 0], step_run["chassis_x"].values + c * bx - s * by, atol=1e-5)
    np.testing.assert_allclose(-hull[:, 0, 1], step_run["chassis_y"].values + s * bx + c * by, atol=1e-5)


def blueprint_views(path):
    """The stored blueprint's views: space origin -> view class ("2D", "TimeSeries", ...)."""
    r = RrdReader(path)
    (bp,) = r.blueprints()
    views = {}
    for c in r.stream(store=bp).to_chunks():
        rb = c.to_record_batch()
        if "ViewBlueprint:space_origin" in rb.schema.names:
            views[rb.column("ViewBlueprint:space_origin").to_pylist()[0][0]] = rb.column(
                "ViewBlueprint:class_identifier"
            ).to_pylist()[0][0]
    return views


def test_blueprint_is_stored(run_folder):
    views = blueprint_views(run_folder / "recording.rrd")
    assert views.get("/world") == "2D"
    for e in (E.E_WHEEL_FY, E.E_AY, E.E_VX):
        assert views.get(e) == "TimeSeries"
    assert views.get(E.E_PARAMS) == "TextDocument"
    # the closed layout's plots and parts belong to closed runs only
    assert E.E_SPROCKET_TORQUE not in views and E.E_IDLER_FORCE not in views
    logged = set(read_temporal(run_folder / "recording.rrd")) | static_entities(run_folder / "recording.rrd")
    assert not logged & {
        E.E_SPROCKET,
        E.E_IDLER,
        E.E_GUIDE,
        E.E_ROLLERS,
        E.E_SPROCKET_TORQUE,
        E.E_IDLER_FORCE,
    }


def test_parameters_and_solver_text(step_run):
    assert "| speed | 10.0 |" in R.parameters_text(step_run)
    text = R.solver_text(step_run)
    assert f"| steps | {step_run.attrs['steps']} |" in text and "peak_wheel_force_y wheel 1" in text


def with_record(ds, **rec):
    ds = ds.copy()
    sc = json.loads(ds.attrs["scenario"])
    sc["record"].update(rec)
    ds.attrs = {**ds.attrs, "scenario": json.dumps(sc)}
    return ds


def test_record_switch_and_every(step_run, tmp_path):
    off = tmp_path / "off"
    off.mkdir()
    assert R.maybe_write_recording(with_record(step_run, enabled=False), off) is None
    assert list(off.iterdir()) == []
    on = tmp_path / "on"
    p = R.maybe_write_recording(with_record(step_run, enabled=True, every=7), on)
    assert p == on / "recording.rrd" and [x.name for x in on.iterdir()] == ["recording.rrd"]  # no temp left
    data = read_temporal(p)
    n = step_run.sizes["time"]
    idx = R.frame_indices(n, 7)
    assert idx[-1] == n - 1 and len(idx) == len(range(0, n, 7)) + (1 if (n - 1) % 7 else 0)
    t = seconds(data[E.E_CHASSIS][E.TIMELINE])
    np.testing.assert_allclose(t, step_run["time"].values[idx], atol=1e-9)
    assert len(data[E.E_WHEEL_FY][E.TIMELINE]) == n  # time series stay at full rate


def test_run_plots_are_real_images(step_run, tmp_path):
    import matplotlib.image as mpimg

    paths = plot_run(step_run, tmp_path, times=(0.05, 0.1))
    names = [p.name for p in paths]
    assert names == ["configuration.png", "wheel_force.png", "chassis_ay.png", "chassis_vx.png", "energy.png"]
    for p in paths:
        img = mpimg.imread(p)
        assert img.shape[0] > 400 and img.shape[1] > 600, p
        ink = np.mean(np.any(img[..., :3] < 0.9, axis=-1))
        assert ink > 0.03, f"{p.name} is nearly blank ({ink:.3f})"
    conf = mpimg.imread(paths[0])[..., :3]
    # the ground fill (tan) and tension colours (green around 80 kN) are drawn
    tan = np.all(np.abs(conf - np.array([0xD8, 0xC3, 0xA0]) / 255) < 0.03, axis=-1).mean()
    green = np.all(np.abs(conf - G.TENSION_RGB[2] / 255) < 0.06, axis=-1).mean()
    assert tan > 0.02 and green > 0.001
    # a time after the run's end: left out, times spread over the run instead (no error)
    late = plot_run(step_run, tmp_path / "x", times=(0.3,))
    assert late[0].name == "configuration.png" and mpimg.imread(late[0]).shape[0] > 1300  # three panels


def fake_times(t_end, status="completed", n=200):
    return xr.Dataset(coords={"time": np.linspace(0.0, t_end, n)}, attrs={"status": status})


def test_default_configuration_times_lie_in_the_run():
    from trackbench.figures.plots import PAPER_TIMES, choose_times, default_times

    assert default_times(fake_times(0.5)) == PAPER_TIMES  # the paper's run: its times
    assert default_times(fake_times(1.5)) == pytest.approx((0.5, 1.0, 1.5))  # spread over a long run
    short = default_times(fake_times(0.2))
    assert len(short) == 3 and max(short) == pytest.approx(0.2)
    failed = default_times(fake_times(0.05, "failed"))  # up to where it stopped
    assert len(failed) == 3 and failed[-1] == pytest.approx(0.05) and min(failed) > 0.0
    # a failed run of the paper's length still shows its last sample
    assert default_times(fake_times(0.48, "failed"))[-1] == pytest.approx(0.48)
    chosen, note = choose_times(fake_times(0.2), (0.1, 0.35, 0.45))
    assert chosen == [0.1] and "0.35, 0.45 s left out" in note
    chosen, note = choose_times(fake_times(0.05, "failed"), (0.1,))
    assert chosen[-1] == pytest.approx(0.05) and "spread" in note


def test_failed_short_run_still_gets_its_figures(step_run, tmp_path):
    import matplotlib.image as mpimg

    ds = step_run.isel(time=step_run["time"].values <= 0.04)
    ds.attrs = {**step_run.attrs, "status": "failed", "t_final": 0.04}
    paths = plot_run(ds, tmp_path)  # `trackbench plot` without --times
    assert [p.name for p in paths][:2] == ["configuration.png", "wheel_force.png"]
    assert mpimg.imread(paths[0]).shape[0] > 1300  # three panels up to 0.04 s


def test_configuration_frames_the_vehicle_and_scales_the_arrows(step_run):
    import matplotlib.pyplot as plt

    from trackbench.figures.plots import _arrow_scale, draw_configuration

    i = int(np.argmax(step_run["wheel_force_y"].values.max(axis=1)))  # the hardest hit on the step
    g = G.side_view(step_run, [i])
    top = float(g["chassis"][0][:, 1].max()) + 0.15
    assert (
        float((g["wheel_arrow_origin"][0] + g["wheel_arrow_vector"][0])[:, 1].max()) > top + 1.0
    )  # at 1 m/200 kN
    scale = _arrow_scale(step_run, [i], None)
    assert scale < G.FORCE_SCALE
    tips = g["wheel_arrow_origin"][0] + g["wheel_arrow_vector"][0] * (scale / G.FORCE_SCALE)
    assert float(tips[:, 1].max()) <= top
    fig, ax = plt.subplots()
    draw_configuration(ax, step_run, i, force_scale=scale)
    low, high = ax.get_ylim()
    ground = G.ground_polyline(step_run)
    assert low >= float(ground[:, 1].min()) - 0.45 and high == pytest.approx(
        top
    )  # not the ground arrow's tail
    plt.close(fig)
    assert _arrow_scale(step_run, [0], None) == G.FORCE_SCALE  # standing still: the paper's scale


def test_run_titles_name_the_run(step_run, tmp_path):
    from trackbench.figures.plots import run_label

    d = tmp_path / "speed_sweep" / "runs" / "abcdef0123456789"
    write_netcdf(step_run, d / "timeseries.nc")
    (d / "run.json").write_text(
        json.dumps(
            {
                "run_id": "abcdef0123456789",
                "study": "speed_sweep",
                "replicate": 0,
                "params": {
                    "speed": 12.5,
                    "terrain.height": 0.1,
                    "idler.preload": 150000.0,
                    "drawbar.slip": 0.05,
                },
            }
        )
    )
    assert run_label(step_run, d) == (
        "speed_sweep run abcdef01: speed 12.5 m/s, terrain.height 0.1 m, "
        "idler.preload 150 kN, drawbar.slip 5 %"
    )
    assert run_label(step_run, d / "timeseries.nc") == run_label(step_run, d)
    assert run_label(step_run) == "paper_step"  # no study around it: the scenario's name


def test_plot_run_from_a_run_folder(run_folder, tmp_path):
    res = CliRunner().invoke(app, ["plot", str(run_folder), "--out", str(tmp_path), "--times", "0.06,0.11"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "configuration.png").stat().st_size > 20_000


def fake_summary(folder):
    rows = []
    rng = np.random.default_rng(1)
    for speed in (5.0, 10.0, 15.0):
        for h in (0.05, 0.1):
            row = {
                "run_id": f"r{speed:g}_{h:g}",
                "status": "completed",
                "status_message": "",
                "variant": 0,
                "replicate": 0,
                "speed": speed,
                "terrain.height": h,
                "solver": "reduced",
            }
            for w in range(1, 6):
                row[f"peak_wheel{w}_force_y"] = 1e5 * (1 + speed * h * w) + rng.uniform(0, 1e3)
                row[f"peak_wheel{w}_force_y_time"] = 0.1
            row.update(
                peak_ground_force_y=3e5 * speed * h,
                peak_link_tension=2e5,
                min_chassis_vx=speed - 1,
                first_contact_time=0.0568,
                steps=100,
                wall_time=0.4,
                solve_time=0.3,
            )
            rows.append(row)
    rows[-1]["status"] = "failed"
    folder.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(rows).to_csv(folder / "summary.csv", index=False)


def test_study_figure_tells_failed_runs_from_runs_not_run_yet(tmp_path, monkeypatch):
    """A study stopped halfway: its pending runs are not called failed."""
    fake_summary(tmp_path / "st")
    df = pd.read_csv(tmp_path / "st" / "summary.csv")
    df.loc[df.index[:2], "status"] = "pending"
    df.to_csv(tmp_path / "st" / "summary.csv", index=False)
    import matplotlib.axes

    labels = []
    plot = matplotlib.axes.Axes.plot

    def spy(self, *args, **kw):
        labels.append(kw.get("label"))
        return plot(self, *args, **kw)

    monkeypatch.setattr(matplotlib.axes.Axes, "plot", spy)
    plot_study(tmp_path / "st", tmp_path / "out")
    assert "failed run (1)" in labels and "not run yet (2)" in labels


def test_plot_study_one_figure_per_axis(tmp_path):
    fake_summary(tmp_path / "st")
    df = pd.read_csv(tmp_path / "st" / "summary.csv")
    assert study_axes(df) == ["speed", "terrain.height"]  # constant solver, peaks and book-keeping left out
    paths = plot_study(tmp_path / "st", tmp_path / "out")
    assert [p.name for p in paths] == ["study_speed.png", "study_terrain_height.png"]
    for p in paths:
        assert p.stat().st_size > 20_000
    res = CliRunner().invoke(app, ["plot", str(tmp_path / "st")])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "st" / "plots" / "study_speed.png").exists()
    # the study edited: height is no longer an axis; its old figure goes, the user's files stay
    df[df["terrain.height"] == 0.1].to_csv(tmp_path / "st" / "summary.csv", index=False)
    (tmp_path / "st" / "plots" / "notes.png").write_bytes(b"mine")
    res = CliRunner().invoke(app, ["plot", str(tmp_path / "st")])
    assert res.exit_code == 0 and "removed: " in res.output and "study_terrain_height.png" in res.output
    assert sorted(p.name for p in (tmp_path / "st" / "plots").iterdir()) == ["notes.png", "study_speed.png"]


def test_study_axes_have_units_and_readable_values():
    from trackbench.figures.plots import axis_label, parameter_unit, value_label

    assert [
        parameter_unit(k)
        for k in (
            "speed",
            "idler.preload",
            "drive.torque",
            "terrain.height",
            "vehicle.torsion_stiffness",
            "contact.friction_stiffness",
        )
    ] == ["m/s", "N", "N m", "m", "N m/rad", "N/m"]
    assert parameter_unit("contact.friction") == "" and parameter_unit("preset") == ""
    assert axis_label("idler.preload", [1.2e5, 1.8e5]) == "idler.preload (kN)"
    assert axis_label("drawbar.slip", [0.05, 0.5]) == "drawbar.slip (%, at the sprocket)"
    bump = json.dumps({"height": 0.1, "kind": "bump", "length": 0.6, "position": 3.5})
    assert value_label("terrain", bump) == "bump 0.1 m x 0.6 m"
    assert value_label("terrain", {"kind": "flat", "soil": "lete_sand"}) == "flat, lete_sand"


def test_study_draws_a_line_per_value_of_the_other_axis(tmp_path):
    from trackbench.figures.plots import _groups

    fake_summary(tmp_path / "st")
    df = pd.read_csv(tmp_path / "st" / "summary.csv")
    groups, too_many = _groups(df, ["terrain.height"], df["speed"].to_numpy(float))
    assert [g[0] for g in groups] == ["terrain.height 0.05 m", "terrain.height 0.1 m"] and not too_many
    assert [int(g[1].sum()) for g in groups] == [3, 3]
    # more combinations than MAX_LINES: one median line over them
    many = pd.DataFrame({"speed": np.repeat([5.0, 10.0], 8), "h": np.tile(np.arange(8.0), 2)})
    groups, too_many = _groups(many, ["h"], many["speed"].to_numpy())
    assert len(groups) == 1 and groups[0][0] is None and too_many


def test_study_terrain_axis_gets_short_labels(tmp_path):
    rows = []
    for k, t in enumerate(
        [
            None,
            None,
            {"kind": "bump", "height": 0.1, "length": 0.6, "position": 3.5},
            {"kind": "bump", "height": 0.2, "length": 0.6, "position": 3.5},
        ]
    ):
        rows.append(
            {
                "run_id": f"r{k}",
                "status": "completed",
                "terrain.height": 0.05 * (k + 1) if t is None else np.nan,
                "terrain": json.dumps(t, sort_keys=True) if t else np.nan,
                "peak_wheel1_force_y": 1e5 * (k + 1),
            }
        )
    (tmp_path / "st").mkdir()
    pd.DataFrame(rows).to_csv(tmp_path / "st" / "summary.csv", index=False)
    (tmp_path / "st" / "runs.json").write_text(
        json.dumps(
            {
                "runs": [
                    {"run_id": f"r{k}", "scenario": {"terrain": {"kind": "step", "height": 0.05 * (k + 1)}}}
                    for k in range(2)
                ]
            }
        )
    )
    import matplotlib.pyplot as plt

    made = []
    monkey = plt.Figure.savefig

    def keep(fig, path, **kw):
        made.append([t.get_text() for t in fig.axes[-1].get_xticklabels()])
        return monkey(fig, path, **kw)

    plt.Figure.savefig = keep
    try:
        paths = plot_study(tmp_path / "st", tmp_path / "out")
    finally:
        plt.Figure.savefig = monkey
    assert [p.name for p in paths] == ["study_terrain_height.png", "study_terrain.png"]
    assert made[1] == ["bump 0.1 m x 0.6 m", "bump 0.2 m x 0.6 m", "step 0.05 m", "step 0.1 m"]


def test_view_resolves_paths_and_explains_missing_display(run_folder, monkeypatch):
    rrd = run_folder / "recording.rrd"
    study = run_folder.parent.parent
    assert V.resolve_recording(rrd) == rrd
    assert V.resolve_recording(run_folder) == rrd
    assert V.resolve_recording(study, "abcdef0123") == rrd
    assert V.resolve_recording(study, "abc") == rrd  # unique prefix
    with pytest.raises(V.ViewError, match="no run 'zzz'"):
        V.resolve_recording(study, "zzz")
    with pytest.raises(V.ViewError, match="give a run id"):
        V.resolve_recording(study)
    assert not V.display_available({}) and V.display_available({"WAYLAND_DISPLAY": "wayland-0"})
    with pytest.raises(V.ViewError) as e:
        V.open_viewer(run_folder, env={})
    msg = str(e.value)
    assert "no display" in msg and "rerun recording.rrd" in msg and "app.rerun.io" in msg
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    res = CliRunner().invoke(app, ["view", str(study), "abc"])
    assert res.exit_code == 3 and "no display" in res.output


def test_view_of_a_netcdf_writes_the_recording_beside_it(step_run, tmp_path):
    nc = write_netcdf(step_run, tmp_path / "paper_step.nc")
    rrd = V.resolve_recording(nc)
    assert rrd == tmp_path / "paper_step.rrd" and rrd.stat().st_size > 100_000


# ------------------------------------------------------------------ closed track layout ----

CLOSED_PARTS = (E.E_SPROCKET, E.E_IDLER, E.E_GUIDE, E.E_ROLLERS)


@pytest.fixture(scope="module")
def closed_run():
    """A short closed-layout run on flat ground with two support rollers on the return run."""
    return tb.simulate(
        tb.Scenario.from_dict(
            {
                "track.layout": "closed",
                "terrain": {"kind": "flat"},
                "duration": 0.02,
                "speed": 2.0,
                "rollers.positions": [[1.0, 0.2], [-1.0, 0.2]],
            }
        )
    )


@pytest.fixture(scope="module")
def closed_recording(closed_run, tmp_path_factory):
    return R.write_recording(closed_run, tmp_path_factory.mktemp("closed") / "recording.rrd")


def test_link_ends_close_the_loop_and_free_pins():
    pins = np.arange(8.0).reshape(4, 2)
    paper = G.link_ends(pins, closed=False)
    assert paper.shape == (3, 2, 2)
    np.testing.assert_array_equal(paper[0], pins[[0, 1]])
    loop = G.link_ends(pins, closed=True)
    assert loop.shape == (4, 2, 2)
    np.testing.assert_array_equal(loop[0], pins[[3, 0]])  # link 0: the last pin back to the first
    np.testing.assert_array_equal(loop[2], pins[[1, 2]])
    np.testing.assert_array_equal(G.free_pins(pins, False), pins[1:-1])
    np.testing.assert_array_equal(G.free_pins(pins, True), pins)


def test_closed_recording_draws_sprocket_idler_rollers_and_loop(closed_run, closed_recording):
    from trackbench.model.vehicle.teeth import profile

    ds, lay = closed_run, G.closed_layout(closed_run)
    n, npin = ds.sizes["time"], ds.sizes["pin"]
    data = read_temporal(closed_recording)
    for e in CLOSED_PARTS + (E.E_SPROCKET_TORQUE, E.E_IDLER_FORCE, E.E_LINKS, E.E_PINS):
        assert len(data[e][E.TIMELINE]) == n, e
    assert set(CLOSED_PARTS) <= static_entities(closed_recording)
    # the sprocket: its whole tooth profile at every frame, turned by its absolute angle
    teeth = np.array(data[E.E_SPROCKET]["LineStrips2D:strips"], dtype=float)[:, 0]  # (n, m, 2)
    angle = ds["chassis_pitch"].values - ds["sprocket_angle"].values
    c, s = np.cos(ds["chassis_pitch"].values), np.sin(ds["chassis_pitch"].values)
    (bx, by), x, y = lay["sprocket"], ds["chassis_x"].values, ds["chassis_y"].values
    for i in (0, n - 1):
        want = profile(
            lay["teeth"],
            lay["pitch_radius"],
            lay["seat_radius"],
            lay["tip_radius"],
            lay["pin_radius"],
            angle[i],
        ) + [x[i] + c[i] * bx - s[i] * by, y[i] + s[i] * bx + c[i] * by]
        assert teeth.shape[1] == len(want)
        np.testing.assert_allclose(teeth[i], want * [1, -1], atol=1e-5)
    # idler at its centre, on a guide 2 x travel long through its slide-0 point
    idler = np.array(data[E.E_IDLER]["Ellipses2D:centers"], dtype=float)[:, 0]
    np.testing.assert_allclose(
        idler, np.stack([ds["idler_x"].values, -ds["idler_y"].values], axis=-1), atol=1e-5
    )
    guide = np.array(data[E.E_GUIDE]["LineStrips2D:strips"], dtype=float)[:, 0]  # (n, 2, 2)
    np.testing.assert_allclose(
        np.linalg.norm(guide[:, 1] - guide[:, 0], axis=-1), 2 * lay["travel"], rtol=1e-5
    )
    middle = guide.mean(axis=1) * [1, -1]
    slide = np.sum(
        (np.stack([ds["idler_x"].values, ds["idler_y"].values], axis=-1) - middle)
        * (guide[:, 1] - guide[:, 0])
        * [1, -1],
        axis=-1,
    ) / (2 * lay["travel"])
    np.testing.assert_allclose(slide, ds["idler_position"].values, atol=1e-5)
    assert {len(v) for v in data[E.E_ROLLERS]["Ellipses2D:centers"]} == {2}
    # the loop: every pin free, one link per pin, link 0 from the last pin back to the first
    assert {len(v) for v in data[E.E_PINS]["Points2D:positions"]} == {npin}
    links = np.array(data[E.E_LINKS]["LineStrips2D:strips"], dtype=float)  # (n, nl, 2, 2)
    pins = np.array(data[E.E_PINS]["Points2D:positions"], dtype=float)
    assert links.shape[1] == npin == ds.sizes["link"]
    np.testing.assert_array_equal(links[:, 0, 0], pins[:, -1])
    np.testing.assert_array_equal(links[:, 0, 1], pins[:, 0])
    np.testing.assert_array_equal(links[:, 1:, 0], pins[:, :-1])
    colors = np.array(data[E.E_LINKS]["LineStrips2D:colors"], dtype=np.uint32)
    np.testing.assert_array_equal(colors, G.tension_rgba32(ds["link_tension"].values))
    # the recording draws what the matplotlib side view draws
    g = G.side_view(ds)
    np.testing.assert_allclose(teeth, g["sprocket"] * [1, -1], atol=1e-5)
    np.testing.assert_allclose(links, g["links"] * [1, -1], atol=1e-5)
    np.testing.assert_allclose(
        np.array(data[E.E_ROLLERS]["Ellipses2D:centers"], dtype=float), g["rollers"] * [1, -1], atol=1e-5
    )


def test_closed_recording_signals_and_blueprint(closed_run, closed_recording):
    data = read_temporal(closed_recording)
    for e, var in ((E.E_SPROCKET_TORQUE, "sprocket_torque"), (E.E_IDLER_FORCE, "idler_force")):
        got = np.array([v[0] for v in data[e]["Scalars:scalars"]])
        np.testing.assert_array_equal(got, closed_run[var].values)
    assert np.all(closed_run["idler_force"].values > 0)  # the tensioner holds the loop taut: a real signal
    views = blueprint_views(closed_recording)
    assert views.get(E.E_SPROCKET_TORQUE) == "TimeSeries" and views.get(E.E_IDLER_FORCE) == "TimeSeries"
    assert views.get("/world") == "2D" and views.get(E.E_WHEEL_FY) == "TimeSeries"


def test_closed_recording_thinned_and_without_rollers(closed_run, tmp_path):
    ds = closed_run.copy()
    lay = G.closed_layout(ds)
    ds.attrs = {**ds.attrs, "closed_layout": json.dumps({**lay, "rollers": []})}
    p = R.write_recording(ds, tmp_path / "r.rrd", every=7)
    data = read_temporal(p)
    idx = R.frame_indices(ds.sizes["time"], 7)
    np.testing.assert_allclose(seconds(data[E.E_SPROCKET][E.TIMELINE]), ds["time"].values[idx], atol=1e-9)
    assert E.E_ROLLERS not in data and E.E_ROLLERS not in static_entities(p)
    assert len(data[E.E_IDLER_FORCE][E.TIMELINE]) == ds.sizes["time"]


def test_closed_run_draws_the_drive(closed_run, tmp_path):
    import matplotlib.image as mpimg

    paths = plot_run(closed_run, tmp_path)
    names = [p.name for p in paths]
    assert "drive.png" in names and "traction.png" not in names  # rigid ground, no drawbar
    img = mpimg.imread(tmp_path / "drive.png")
    assert img.shape[0] > 800 and np.mean(np.any(img[..., :3] < 0.9, axis=-1)) > 0.03


def test_closed_configuration_png(closed_run, tmp_path):
    import matplotlib.image as mpimg

    from trackbench.figures.plots import plot_configuration

    path = plot_configuration(closed_run, (0.0, 0.02), tmp_path / "configuration.png")
    assert path.exists() and path.stat().st_size > 20_000
    img = mpimg.imread(path)[..., :3]
    assert img.shape[0] > 400 and img.shape[1] > 600
    assert np.mean(np.any(img < 0.9, axis=-1)) > 0.03

    def share(hex_rgb, tol=0.03):
        rgb = np.array([int(hex_rgb[k : k + 2], 16) for k in (1, 3, 5)]) / 255
        return np.all(np.abs(img - rgb) < tol, axis=-1).mean()

    # sprocket face (pale blue), idler guide (bronze bar), track tension colours (green)
    assert share("#c9d3e6") > 0.001 and share("#b4783c") > 0.0001
    assert share("#%02x%02x%02x" % tuple(G.TENSION_RGB[2].astype(int)), 0.06) > 0.001


# ---------------------------------------------------------------------------- soft soil ----


@pytest.fixture(scope="module")
def soil_run():
    """A short paper-layout run on dry sand: the track sinks and leaves a rut."""
    return tb.simulate(tb.Scenario.from_dict({"terrain.soil": "dry_sand", "duration": 0.05}))


@pytest.fixture(scope="module")
def soil_recording(soil_run, tmp_path_factory):
    return R.write_recording(soil_run, tmp_path_factory.mktemp("soil") / "recording.rrd", every=4)


def test_soil_recording_logs_the_deformed_surface(soil_run, soil_recording):
    ds = soil_run
    data = read_temporal(soil_recording)
    assert E.E_SOIL in data and E.E_SOIL in static_entities(soil_recording)
    idx = R.frame_indices(ds.sizes["time"], 4)
    np.testing.assert_allclose(seconds(data[E.E_SOIL][E.TIMELINE]), ds["time"].values[idx], atol=1e-9)
    strips = np.array(data[E.E_SOIL]["LineStrips2D:strips"], dtype=float)[:, 0]  # (n, m, 2), y negated
    assert strips.shape[0] == len(idx)
    x, height = strips[-1, :, 0], -strips[:, :, 1]
    assert np.all(np.diff(x) >= 0)
    # the last frame: the original ground lowered by rut_depth at each cell centre (flat soil at y = 0)
    rx, depth = ds["rut_x"].values, ds["rut_depth"].values
    assert depth.max() > 0.01
    at = np.searchsorted(x, rx[depth > 0] - 1e-6)
    np.testing.assert_allclose(x[at], rx[depth > 0], atol=1e-5)
    np.testing.assert_allclose(height[-1, at], -depth[depth > 0], atol=1e-5)
    # the surface only ever sinks; it ends the run deeper than it started
    assert np.all(np.diff(height, axis=0) <= 1e-6)
    assert height[-1].min() < height[0].min() - 1e-3 or np.sum(height[-1] < -1e-3) > np.sum(height[0] < -1e-3)
    # away from the rut it is the ground
    ground = G.ground_polyline(ds)
    np.testing.assert_allclose(strips[-1, [0, -1]] * [1, -1], ground[[0, -1]], atol=1e-5)


def _raise_nodes(rut, x, z, x0, dx, half):
    """The soil memory's rule written out again: nodes at cell centres, quintic weights,
    the shallower node raised just enough (both when z is deeper than both), every other
    node under the pin's shoe (within half a link of x) to z where it is shallower."""
    u = (x - x0) / dx - 0.5
    c = int(np.floor(u))
    around = 0 <= c and c + 1 < rut.size  # else x has no two nodes around it: all under the shoe
    centres = x0 + (np.arange(rut.size) + 0.5) * dx
    shoe = np.abs(centres - x) <= half
    if around:
        shoe[c : c + 2] = False
    rut[shoe] = np.maximum(rut[shoe], z)
    if not around:
        return
    u -= c
    w = u * u * u * (10.0 + u * (6.0 * u - 15.0))
    if z <= (1 - w) * rut[c] + w * rut[c + 1]:
        return
    if z >= max(rut[c], rut[c + 1]):
        rut[c] = rut[c + 1] = z
        return
    lo, hi = (c, c + 1) if rut[c] <= rut[c + 1] else (c + 1, c)
    w_lo = 1 - w if lo == c else w
    rut[lo] = min(max((z - (1 - w_lo) * rut[hi]) / w_lo, rut[lo]), rut[hi])


def test_soil_memory_under_a_shoe_at_both_ends_of_the_cells():
    """The kernel's rule (model.soil_force.raise_memory, through replay_memory) against the
    rebuild above, pins near and beyond both ends of a small row of cells: every node under
    the shoe is raised, at either end alike."""
    from trackbench.model.ground.soil_jit import replay_memory

    x0, dx, n, half = 0.0, 0.01, 30, 0.095
    for x in (
        -0.071,
        -0.004,
        0.002,
        0.013,
        0.151,
        0.287,
        0.296,
        0.305,
        0.331,
    ):  # none half a shoe from a centre
        px, sink = np.array([[x]]), np.array([[0.05]])
        got = replay_memory(px, sink, x0, dx, 2 * half, np.array([0]), np.zeros((1, n)))
        want = np.zeros(n)
        _raise_nodes(want, x, 0.05, x0, dx, half)
        np.testing.assert_array_equal(got, want)
        under = np.abs(x0 + (np.arange(n) + 0.5) * dx - x) <= half
        assert (got[under] == 0.05).all() and (got[~under] == 0.0).all()


def test_soil_dent_matches_an_independent_rebuild(soil_run):
    """The dent: the soil's memory replayed on the output samples, scaled per cell to end at
    rut_depth; without the scaling it ends within the sampling's reach of rut_max_sinkage."""
    ds = soil_run
    rx, depth = ds["rut_x"].values, ds["rut_depth"].values
    dx = rx[1] - rx[0]
    n = ds.sizes["time"]
    edges = np.append(rx - dx / 2, rx[-1] + dx / 2)
    half = 0.5 * json.loads(ds.attrs["scenario"])["track"]["link_length"]
    hist, last = S.running_sinkage(ds, np.arange(n), edges)
    want = np.zeros((n, rx.size))
    rut = np.zeros(rx.size)
    for i in range(n):
        for x, s in zip(ds["pin_x"].values[i], ds["sinkage"].values[i]):
            if s > 0:
                _raise_nodes(rut, x, s, edges[0], edges[1] - edges[0], half)
        want[i] = rut
    np.testing.assert_array_equal(hist, want)
    np.testing.assert_array_equal(last, want[-1])
    assert np.abs(last - ds["rut_max_sinkage"].values).max() < 0.01
    base, drop = S.soil_surface(ds, [0, n - 1])
    at = np.searchsorted(base[:, 0], rx[depth > 0] - 1e-9)
    np.testing.assert_allclose(drop[-1, at], depth[depth > 0], atol=1e-12)
    assert np.all(drop[0] <= drop[-1] + 1e-12)


def test_rigid_runs_log_no_soil(run_folder, step_run):
    assert not S.is_soil(step_run)
    rrd = run_folder / "recording.rrd"
    assert E.E_SOIL not in read_temporal(rrd) and E.E_SOIL not in static_entities(rrd)


def test_soil_run_draws_sinkage_and_pull(soil_run, tmp_path):
    import matplotlib.image as mpimg

    names = [p.name for p in plot_run(soil_run, tmp_path)]
    assert "traction.png" in names and "drive.png" not in names  # the paper's layout has no sprocket
    img = mpimg.imread(tmp_path / "traction.png")
    assert img.shape[0] > 600 and np.mean(np.any(img[..., :3] < 0.9, axis=-1)) > 0.03
    assert np.max(soil_run["sinkage"].values) > 0.0


def test_soil_configuration_png_shows_the_rut(soil_run, step_run, tmp_path):
    import matplotlib.image as mpimg

    from trackbench.figures.plots import SOIL_DENT, plot_configuration

    def share(path):
        img = mpimg.imread(path)[..., :3]
        rgb = np.array([int(SOIL_DENT[k : k + 2], 16) for k in (1, 3, 5)]) / 255
        return np.all(np.abs(img - rgb) < 0.03, axis=-1).mean()

    soil = plot_configuration(soil_run, (0.0, 0.05), tmp_path / "soil.png")
    rigid = plot_configuration(step_run, (0.0, 0.1), tmp_path / "rigid.png")
    assert share(soil) > 0.0005 and share(rigid) == 0.0


def test_plotting_a_file_that_is_not_a_run_says_so_in_one_line(tmp_path):
    from trackbench.figures.plots import plot_run

    junk = tmp_path / "junk.nc"
    junk.write_text("not netCDF")
    with pytest.raises(ValueError, match=r"junk.nc is not a netCDF file trackbench can read"):
        plot_run(junk, tmp_path / "p")
    import xarray as xr

    xr.Dataset({"a": ("x", [1.0, 2.0])}).to_netcdf(tmp_path / "other.nc")
    with pytest.raises(ValueError, match=r"other.nc is a netCDF file but not a trackbench run"):
        plot_run(tmp_path / "other.nc", tmp_path / "p")


def test_a_soil_study_figure_has_panels_for_sinkage_pull_and_slip():
    """Each in its own unit (the soft_soil study's question: drawbar pull and sinkage); a
    rigid-ground study keeps the two force panels."""
    import pandas as pd

    from trackbench.figures.study_figures import _panels, _what

    df = pd.DataFrame(
        {
            "peak_wheel1_force_y": [1e5],
            "peak_ground_force_y": [3e5],
            "peak_sinkage": [0.06],
            "mean_drawbar_pull": [1.8e3],
            "mean_slip": [0.013],
        }
    )
    panels = {label: (cols, scale) for label, cols, scale in _panels(df)}
    assert panels["deepest sinkage into the soil (cm)"] == (["peak_sinkage"], 1e-2)
    assert panels["mean drawbar pull, 2nd half (kN)"] == (["mean_drawbar_pull"], 1e3)
    assert panels["mean slip (sprocket), 2nd half (%)"] == (["mean_slip"], 1e-2)
    assert panels["peak force (kN)"][0] == ["peak_ground_force_y"]  # the mean pull not among peaks
    assert len(_panels(df.drop(columns=["peak_sinkage", "mean_drawbar_pull", "mean_slip"]))) == 2
    assert _what(_panels(df)) == "peak forces, sinkage, drawbar pull and slip"
    assert _what(_panels(df[["peak_wheel1_force_y"]])) == "peak forces"


def test_a_closed_track_study_figure_has_a_sprocket_torque_panel():
    """The drive study's question: sprocket torque (kN m) beside the forces; its idler force
    among the peak forces (kN)."""
    import pandas as pd

    from trackbench.figures.study_figures import _panels, _what

    df = pd.DataFrame(
        {"peak_wheel1_force_y": [1e5], "peak_idler_force": [1.5e5], "peak_sprocket_torque": [1.4e4]}
    )
    panels = {label: (cols, scale) for label, cols, scale in _panels(df)}
    assert panels["peak sprocket torque (kN m)"] == (["peak_sprocket_torque"], 1e3)
    assert panels["peak force (kN)"][0] == ["peak_idler_force"]
    assert _what(_panels(df)) == "peak forces and sprocket torque"


def test_study_figures_are_titled_by_the_study_name_not_its_folder(tmp_path):
    """`study run --output elsewhere` names the folder; the figures keep the study's name."""
    import json

    from trackbench.figures.study_figures import _study_name

    (tmp_path / "elsewhere").mkdir()
    src = tmp_path / "elsewhere" / "summary.csv"
    assert _study_name(src) == "elsewhere"  # no runs.json: the folder
    (tmp_path / "elsewhere" / "runs.json").write_text(json.dumps({"name": "soft_soil", "runs": []}))
    assert _study_name(src) == "soft_soil"
