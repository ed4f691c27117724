"""A rerun recording (.rrd) of one run: the side view frame by frame, the time series,
the parameters and solver statistics, and a blueprint that lays them out.

    write_recording(ds, "results/my_study/run_0001/recording.rrd", every=1)
    maybe_write_recording(ds, run_folder)   # obeys the scenario's record.enabled / record.every

Everything is logged with rerun's columnar API (`send_columns`): one call per entity for
the whole run. No viewer and no network are involved; the file is written to a temporary
name in the target folder and renamed into place (atomic).

rerun's 2D views draw y downwards and ignore view coordinates (rerun issue #1387), so the
side view under /world is logged with y negated (y_logged = -height): the picture shows
the vehicle upright; hovering shows -y. The time series under /signals are plain SI values
equal to the Dataset's.
"""

import json
import os
import tempfile
import uuid
from pathlib import Path

import numpy as np
import pyarrow as pa
import rerun as rr
import rerun.blueprint as rrb
from rerun.components import LineStrip2DBatch

from . import geometry as G

TIMELINE = "sim_time"
RECORDING_NAME = "recording.rrd"
PLAYBACK_SPEED = 0.05  # the viewer replays at 1/20 of real time: 0.5 s simulated takes 10 s

E_GROUND = "/world/ground"
E_CHASSIS = "/world/chassis"
E_ARMS = "/world/arms"
E_WHEELS = "/world/wheels"
E_LINKS = "/world/track/links"
E_PINS = "/world/track/pins"
E_WHEEL_FORCE = "/world/forces/wheel_track"
E_GROUND_FORCE = "/world/forces/ground_track"
E_WHEEL_FY = "/signals/wheel_force_y"          # one scalar per wheel per row (series "wheel 1" ...)
E_AY = "/signals/chassis_ay"
E_VX = "/signals/chassis_vx"
E_ENERGY = "/signals/energy"                   # kinetic, elastic, gravity, balance per row
E_TENSION = "/signals/link_tension_max"
E_PARAMS = "/info/parameters"
E_SOLVER = "/info/solver"

WHEEL_RGB = [(230, 25, 75), (245, 130, 48), (60, 180, 75), (0, 130, 200), (145, 30, 180),
             (70, 240, 240), (240, 50, 230), (128, 128, 0)]
ENERGY_SERIES = (("kinetic", "energy_kinetic", (0, 114, 178)),
                 ("elastic", "energy_elastic", (0, 158, 115)),
                 ("gravity", "energy_gravity", (213, 94, 0)),
                 ("balance", "energy_balance", (0, 0, 0)))
CHASSIS_RGB = (60, 60, 60)
ARM_RGB = (110, 110, 110)
GROUND_RGB = (120, 85, 40)
WHEEL_FORCE_RGB = (200, 0, 0)
GROUND_FORCE_RGB = (150, 60, 200)


_STRIP_TYPE = LineStrip2DBatch._ARROW_DATATYPE


def wheel_rgb(i):
    return WHEEL_RGB[i % len(WHEEL_RGB)]


def record_settings(ds):
    """(enabled, every) from the run's scenario (attrs['scenario'], JSON)."""
    rec = G.scenario_of(ds).get("record", {})
    return bool(rec.get("enabled", True)), int(rec.get("every", 1))


def frame_indices(n, every):
    """Every `every`-th output frame, always including the last one."""
    if every < 1:
        raise ValueError(f"every must be >= 1, got {every}")
    idx = np.arange(0, n, every)
    if n and idx[-1] != n - 1:
        idx = np.append(idx, n - 1)
    return idx


def _flip(a):
    """Negate y (last axis) for rerun's y-down 2D views."""
    a = np.array(a, dtype=np.float32, copy=True)
    a[..., 1] *= -1.0
    return a


def _strips(a):
    """(n_strips, m, 2) array -> the Arrow list array rerun's LineStrip2D component stores
    (built directly: rerun's own converter loops over the strips in Python). y is negated."""
    a = _flip(a)
    n, m = a.shape[0], a.shape[1]
    vals = pa.FixedSizeListArray.from_arrays(pa.array(a.reshape(-1)), type=_STRIP_TYPE.value_type)
    offsets = pa.array(np.arange(0, n * m + 1, m, dtype=np.int32))
    return pa.ListArray.from_arrays(offsets, vals, type=_STRIP_TYPE)


def _md_table(rows):
    out = ["| name | value |", "| --- | --- |"]
    out += [f"| {k} | {v} |" for k, v in rows]
    return "\n".join(out)


def _flat(d, prefix=""):
    out = []
    for k, v in d.items():
        if isinstance(v, dict):
            out += _flat(v, prefix + k + ".")
        else:
            out.append((prefix + k, json.dumps(v) if isinstance(v, (list, dict)) else v))
    return out


def parameters_text(ds):
    sc = G.scenario_of(ds)
    extra = G.attr_json(ds, "terrain_resolved") if "terrain_resolved" in ds.attrs else {}
    text = f"# Run parameters: {sc.get('name', '')}\n\n" + _md_table(sorted(_flat(sc)))
    if extra:
        text += "\n\n## Resolved terrain\n\n" + _md_table(sorted(extra.items()))
    return text


def solver_text(ds):
    a = ds.attrs
    keys = ("status", "status_message", "t_final", "solver", "method", "tolerance", "steps", "rejected_steps",
            "rhs_evaluations", "min_step", "max_step", "neighbour_rebuilds", "wall_time", "solve_time",
            "initial_total_energy", "weight", "trackbench_version", "model_version")
    rows = [(k, a[k]) for k in keys if k in a]
    for name in ("peak_wheel_force_y",):
        if name in ds:
            rows += [(f"{name} wheel {int(w)} (N)", f"{float(f):.6g} at t = {float(t):.5f} s")
                     for w, f, t in zip(ds.variables["wheel"].values, ds.variables[name].values, ds.variables[name + "_time"].values)]
    for name in ("peak_ground_force_y", "peak_link_tension", "min_link_tension", "peak_chassis_ay",
                 "min_chassis_ay", "min_chassis_vx", "max_energy_balance_error", "max_energy_residual",
                 "first_contact_time", "first_compression_time"):
        if name in ds:
            units = ds.variables[name].attrs.get("units", "")
            rows.append((f"{name} ({units})", f"{float(ds.variables[name].values):.6g}"))
    text = "# Solver statistics\n\n" + _md_table(rows)
    if "equilibrium" in a:
        text += "\n\n## Initial equilibrium\n\n```json\n" + json.dumps(G.attr_json(ds, "equilibrium"), indent=1) + "\n```"
    return text


def blueprint(ds):
    """Side view large on the left; wheel forces, chassis acceleration and velocity on the
    right; energies, link tension and the text documents in tabs below them."""
    x0, x1 = G.covered_x_range(ds)
    ground = G.ground_polyline(ds)
    top = float(np.nanmax(ds.variables["chassis_y"].values)) + G.HULL_TOP + 0.5
    bottom = float(np.min(ground[:, 1])) - 0.5
    side = rrb.Spatial2DView(origin="/world", name="side view (x forward; up is up)",
                             visual_bounds=rrb.VisualBounds2D(x_range=[x0, x1], y_range=[-top, -bottom]))
    plots = rrb.Vertical(
        rrb.TimeSeriesView(origin=E_WHEEL_FY, name="vertical wheel-track force (N)"),
        rrb.TimeSeriesView(origin=E_AY, name="chassis vertical acceleration (m/s^2)"),
        rrb.TimeSeriesView(origin=E_VX, name="chassis horizontal velocity (m/s)"),
        rrb.Tabs(
            rrb.TimeSeriesView(origin=E_ENERGY, name="energies (J)"),
            rrb.TimeSeriesView(origin=E_TENSION, name="max link tension (N)"),
            rrb.TextDocumentView(origin=E_PARAMS, name="parameters"),
            rrb.TextDocumentView(origin=E_SOLVER, name="solver"),
        ),
    )
    return rrb.Blueprint(rrb.Horizontal(side, plots, column_shares=[3, 2]),
                         rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
                         rrb.TimePanel(state="expanded", timeline=TIMELINE, playback_speed=PLAYBACK_SPEED))


def _log_static(rec, ds):
    nw = ds.sizes["wheel"]
    r = float(ds.attrs["wheel_radius"])
    rec.log(E_GROUND, rr.LineStrips2D([_flip(G.ground_polyline(ds))], colors=[GROUND_RGB], radii=[0.015],
                                      labels=["ground"]), static=True)
    rec.log(E_CHASSIS, rr.LineStrips2D.from_fields(colors=[CHASSIS_RGB], radii=[0.02]), static=True)
    rec.log(E_ARMS, rr.LineStrips2D.from_fields(colors=[ARM_RGB], radii=[0.03]), static=True)
    rec.log(E_WHEELS, rr.Ellipses2D.from_fields(half_sizes=[[r, r]] * nw, colors=[wheel_rgb(i) for i in range(nw)],
                                                line_radii=[0.012], labels=[f"wheel {i + 1}" for i in range(nw)]),
            static=True)
    rec.log(E_LINKS, rr.LineStrips2D.from_fields(radii=[0.012]), static=True)
    rec.log(E_PINS, rr.Points2D.from_fields(radii=[0.02], colors=[(30, 30, 30)]), static=True)
    rec.log(E_WHEEL_FORCE, rr.Arrows2D.from_fields(colors=[WHEEL_FORCE_RGB], radii=[0.015]), static=True)
    rec.log(E_GROUND_FORCE, rr.Arrows2D.from_fields(colors=[GROUND_FORCE_RGB], radii=[0.02],
                                                    labels=["ground force (total)"]), static=True)
    rec.log(E_WHEEL_FY, rr.SeriesLines(colors=[wheel_rgb(i) for i in range(nw)],
                                       names=[f"wheel {i + 1}" for i in range(nw)]), static=True)
    rec.log(E_AY, rr.SeriesLines(colors=[(0, 0, 0)], names=["chassis a_y (m/s^2)"]), static=True)
    rec.log(E_VX, rr.SeriesLines(colors=[(0, 0, 0)], names=["chassis v_x (m/s)"]), static=True)
    rec.log(E_ENERGY, rr.SeriesLines(colors=[rgb for _, _, rgb in ENERGY_SERIES],
                                     names=[name for name, _, _ in ENERGY_SERIES]), static=True)
    rec.log(E_TENSION, rr.SeriesLines(colors=[(200, 0, 0)], names=["max link tension (N)"]), static=True)
    rec.log(E_PARAMS, rr.TextDocument(parameters_text(ds), media_type=rr.MediaType.MARKDOWN), static=True)
    rec.log(E_SOLVER, rr.TextDocument(solver_text(ds), media_type=rr.MediaType.MARKDOWN), static=True)


def _log_signals(rec, ds):
    """Time series at every output frame (cheap; keeps the peaks). Multi-series entities
    (wheel forces, energies) hold one scalar per series per row."""
    t = rr.TimeColumn(TIMELINE, duration=np.asarray(ds.variables["time"].values, dtype=np.float64))
    fy = np.ascontiguousarray(ds.variables["wheel_force_y"].values, dtype=np.float64)
    n = fy.shape[0]
    rec.send_columns(E_WHEEL_FY, indexes=[t],
                     columns=rr.Scalars.columns(scalars=fy.reshape(-1)).partition(np.full(n, fy.shape[1], np.int32)))
    rec.send_columns(E_AY, indexes=[t], columns=rr.Scalars.columns(scalars=ds.variables["chassis_ay"].values))
    rec.send_columns(E_VX, indexes=[t], columns=rr.Scalars.columns(scalars=ds.variables["chassis_vx"].values))
    e = np.stack([ds.variables[var].values for _, var, _ in ENERGY_SERIES], axis=1)
    rec.send_columns(E_ENERGY, indexes=[t],
                     columns=rr.Scalars.columns(scalars=e.reshape(-1)).partition(np.full(n, e.shape[1], np.int32)))
    rec.send_columns(E_TENSION, indexes=[t],
                     columns=rr.Scalars.columns(scalars=np.nanmax(ds.variables["link_tension"].values, axis=1)))


def _log_frames(rec, ds, idx):
    g = G.side_view(ds, idx)
    n = len(idx)
    t = [rr.TimeColumn(TIMELINE, duration=g["time"])]

    def ones(k):
        return np.full(n, k, dtype=np.int32)

    rec.send_columns(E_CHASSIS, indexes=t, columns=rr.LineStrips2D.columns(strips=_strips(g["chassis"])).partition(ones(1)))
    arms = np.stack([g["pivots"], g["wheels"]], axis=2)            # (n, nw, 2, 2)
    nw = arms.shape[1]
    rec.send_columns(E_ARMS, indexes=t,
                     columns=rr.LineStrips2D.columns(strips=_strips(arms.reshape(n * nw, 2, 2))).partition(ones(nw)))
    rec.send_columns(E_WHEELS, indexes=t,
                     columns=rr.Ellipses2D.columns(centers=_flip(g["wheels"].reshape(-1, 2))).partition(ones(nw)))
    pins = g["pins"]
    nl = pins.shape[1] - 1
    links = np.stack([pins[:, :-1], pins[:, 1:]], axis=2)          # (n, nl, 2, 2)
    rec.send_columns(E_LINKS, indexes=t,
                     columns=rr.LineStrips2D.columns(strips=_strips(links.reshape(n * nl, 2, 2)),
                                                     colors=G.tension_rgba32(g["tension"]).reshape(-1))
                     .partition(ones(nl)))
    rec.send_columns(E_PINS, indexes=t,
                     columns=rr.Points2D.columns(positions=_flip(pins.reshape(-1, 2))).partition(ones(nl + 1)))
    rec.send_columns(E_WHEEL_FORCE, indexes=t,
                     columns=rr.Arrows2D.columns(origins=_flip(g["wheel_arrow_origin"].reshape(-1, 2)),
                                                 vectors=_flip(g["wheel_arrow_vector"].reshape(-1, 2)))
                     .partition(ones(nw)))
    rec.send_columns(E_GROUND_FORCE, indexes=t,
                     columns=rr.Arrows2D.columns(origins=_flip(g["ground_arrow_origin"]),
                                                 vectors=_flip(g["ground_arrow_vector"])).partition(ones(1)))


def write_recording(ds, path, every=1):
    """Write the run's rerun recording to `path` (atomically); returns the Path.

    every: log the side-view geometry at every `every`-th output frame (and the last);
    the time series are always logged at every output frame."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    idx = frame_indices(ds.sizes["time"], int(every))
    sc = G.scenario_of(ds)
    rec = rr.RecordingStream("trackbench", recording_id=str(uuid.uuid4()), send_properties=True)
    fd, tmp = tempfile.mkstemp(prefix="." + path.name + ".", suffix=".tmp", dir=path.parent)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    try:
        rec.save(tmp, default_blueprint=blueprint(ds))
        rec.send_recording_name(f"trackbench {sc.get('name', 'run')}")
        # the bulky per-frame geometry first: rerun encodes it on its own thread meanwhile
        _log_frames(rec, ds, idx)
        _log_signals(rec, ds)
        _log_static(rec, ds)
        rec.flush()
        rec.disconnect()
        os.replace(tmp, path)
    except BaseException:
        try:
            rec.disconnect()
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
        raise
    return path


def maybe_write_recording(ds, folder, name=RECORDING_NAME):
    """Write folder/name when the scenario's record.enabled is true (with its record.every);
    returns the Path, or None when recording is switched off."""
    enabled, every = record_settings(ds)
    if not enabled:
        return None
    return write_recording(ds, Path(folder) / name, every=every)
