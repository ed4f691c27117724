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

import functools
import json
import uuid
from pathlib import Path

import numpy as np
import pyarrow as pa
import rerun as rr
import rerun.blueprint as rrb
from rerun.components import LineStrip2DBatch

from ..atomic import atomic_path
from . import geometry as G

TIMELINE = "sim_time"
RECORDING_NAME = "recording.rrd"
PLAYBACK_SPEED = 0.05  # the viewer replays at 1/20 of real time: 0.5 s simulated takes 10 s

E_GROUND = "/world/ground"
E_SOIL = "/world/ground/soil"                   # soft soil only: the surface lowered by the rut so far
E_CHASSIS = "/world/chassis"
E_ARMS = "/world/arms"
E_WHEELS = "/world/wheels"
E_LINKS = "/world/track/links"
E_PINS = "/world/track/pins"
E_WHEEL_FORCE = "/world/forces/wheel_track"
E_GROUND_FORCE = "/world/forces/ground_track"
E_SPROCKET = "/world/sprocket"                  # closed layout only: the tooth profile
E_IDLER = "/world/idler/wheel"
E_GUIDE = "/world/idler/guide"
E_ROLLERS = "/world/rollers"
E_WHEEL_FY = "/signals/wheel_force_y"          # one scalar per wheel per row (series "wheel 1" ...)
E_AY = "/signals/chassis_ay"
E_VX = "/signals/chassis_vx"
E_ENERGY = "/signals/energy"                   # kinetic, elastic, gravity, balance per row
E_TENSION = "/signals/link_tension_max"
E_SPROCKET_TORQUE = "/signals/sprocket_torque"  # closed layout only
E_IDLER_FORCE = "/signals/idler_force"
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
SOIL_RGB = (215, 170, 60)
WHEEL_FORCE_RGB = (200, 0, 0)
GROUND_FORCE_RGB = (150, 60, 200)
SPROCKET_RGB = (40, 60, 110)
IDLER_RGB = (90, 90, 90)
GUIDE_RGB = (180, 120, 60)
ROLLER_RGB = (120, 120, 120)


_STRIP_TYPE = LineStrip2DBatch._ARROW_DATATYPE
_VEC2_TYPE = rr.components.Position2DBatch._ARROW_DATATYPE   # fixed_size_list<float32 not null>[2]
_COLOR_TYPE = rr.components.ColorBatch._ARROW_DATATYPE       # uint32 0xRRGGBBAA
_SCALAR_TYPE = rr.components.ScalarBatch._ARROW_DATATYPE     # float64
_FRAME_BLOCK = 2048  # frames per block when working out the side view (keeps temporaries small)


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


def _xy32(x, y, out=None):
    """x, y (float64, same shape) -> float32 (..., 2) with y negated (as _flip of the stacked
    pair: both round to float32 first; negation is exact)."""
    if out is None:
        out = np.empty(np.shape(x) + (2,), dtype=np.float32)
    out[..., 0] = x
    np.negative(y, out=out[..., 1], casting="same_kind")
    return out


def _offsets(count, step):
    return np.arange(0, count * step + 1, step, dtype=np.int32)


def _list(values, rows, per_row):
    """Arrow list array: `rows` rows of `per_row` items each of the Arrow array `values`."""
    return pa.ListArray.from_arrays(pa.array(_offsets(rows, per_row)), values)


def _vec2(a32):
    """float32 (..., 2) -> Arrow fixed_size_list<float32>[2] values (zero copy)."""
    return pa.FixedSizeListArray.from_arrays(pa.array(a32.reshape(-1)), type=_VEC2_TYPE)


def _strip_values(a32):
    """float32 (n_strips, m, 2) -> Arrow LineStrip2D values (list of m points per strip)."""
    n, m = a32.shape[0], a32.shape[1]
    return pa.ListArray.from_arrays(pa.array(_offsets(n, m)), _vec2(a32), type=_STRIP_TYPE)


class _Column:
    """A ready-made component column for `send_columns`: its descriptor and its Arrow list
    array (one list per row). Built straight from numpy; rerun's archetype `.columns()` /
    `.partition()` would copy and re-validate the same data."""

    __slots__ = ("descriptor", "array")

    def __init__(self, descriptor, array):
        self.descriptor = descriptor
        self.array = array

    def component_descriptor(self):
        return self.descriptor

    def as_arrow_array(self):
        return self.array


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
    from ..quantities import TABLE
    for q in TABLE:   # every summary quantity, in SI units
        if q.variable not in ds:
            continue
        v, units = ds.variables[q.variable], ds.variables[q.variable].attrs.get("units", "")
        if q.per_wheel:
            t = ds.variables[q.variable + "_time"].values
            rows += [(f"{q.variable} wheel {int(w)} ({units})", f"{float(f):.6g} at t = {float(tw):.5f} s")
                     for w, f, tw in zip(ds.variables["wheel"].values, v.values, t)]
        else:
            rows.append((f"{q.variable} ({units})", f"{float(v.values):.6g}"))
    text = "# Solver statistics\n\n" + _md_table(rows)
    if "equilibrium" in a:
        text += "\n\n## Initial equilibrium\n\n```json\n" + json.dumps(G.attr_json(ds, "equilibrium"), indent=1) + "\n```"
    return text


def blueprint(ds):
    """Side view large on the left; wheel forces, chassis acceleration and velocity on the
    right; energies, link tension and the text documents in tabs below them. A closed-layout
    run adds the drive torque and the tensioner force under the side view, where the
    sprocket and the idler they act on are seen."""
    x0, x1 = G.covered_x_range(ds)
    ground = G.ground_polyline(ds, (x0, x1))
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
    if G.is_closed(ds):
        side = rrb.Vertical(side, rrb.Horizontal(
            rrb.TimeSeriesView(origin=E_SPROCKET_TORQUE, name="sprocket drive torque (N m)"),
            rrb.TimeSeriesView(origin=E_IDLER_FORCE, name="idler tensioner force (N)")), row_shares=[3, 1])
    return rrb.Blueprint(rrb.Horizontal(side, plots, column_shares=[3, 2]),
                         rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
                         rrb.TimePanel(state="expanded", timeline=TIMELINE, playback_speed=PLAYBACK_SPEED))


@functools.lru_cache(maxsize=16)
def _static_styles(nw, r):
    """The static archetypes that depend only on the wheel count and radius (built once per
    process: rerun's archetype constructors are slow next to logging them): entity -> archetype."""
    return {
        E_CHASSIS: rr.LineStrips2D.from_fields(colors=[CHASSIS_RGB], radii=[0.02]),
        E_ARMS: rr.LineStrips2D.from_fields(colors=[ARM_RGB], radii=[0.03]),
        E_WHEELS: rr.Ellipses2D.from_fields(half_sizes=[[r, r]] * nw, colors=[wheel_rgb(i) for i in range(nw)],
                                            line_radii=[0.012], labels=[f"wheel {i + 1}" for i in range(nw)]),
        E_LINKS: rr.LineStrips2D.from_fields(radii=[0.012]),
        E_PINS: rr.Points2D.from_fields(radii=[0.02], colors=[(30, 30, 30)]),
        E_WHEEL_FORCE: rr.Arrows2D.from_fields(colors=[WHEEL_FORCE_RGB], radii=[0.015]),
        E_GROUND_FORCE: rr.Arrows2D.from_fields(colors=[GROUND_FORCE_RGB], radii=[0.02],
                                                labels=["ground force (total)"]),
        E_WHEEL_FY: rr.SeriesLines(colors=[wheel_rgb(i) for i in range(nw)],
                                   names=[f"wheel {i + 1}" for i in range(nw)]),
        E_AY: rr.SeriesLines(colors=[(0, 0, 0)], names=["chassis a_y (m/s^2)"]),
        E_VX: rr.SeriesLines(colors=[(0, 0, 0)], names=["chassis v_x (m/s)"]),
        E_ENERGY: rr.SeriesLines(colors=[rgb for _, _, rgb in ENERGY_SERIES],
                                 names=[name for name, _, _ in ENERGY_SERIES]),
        E_TENSION: rr.SeriesLines(colors=[(200, 0, 0)], names=["max link tension (N)"]),
    }


@functools.lru_cache(maxsize=16)
def _closed_styles(idler_radius, roller_radius, n_rollers):
    """The closed layout's static archetypes (as _static_styles): entity -> archetype."""
    ri, rr_ = idler_radius, roller_radius
    styles = {
        E_SPROCKET: rr.LineStrips2D.from_fields(colors=[SPROCKET_RGB], radii=[0.008], labels=["sprocket"]),
        E_IDLER: rr.Ellipses2D.from_fields(half_sizes=[[ri, ri]], colors=[IDLER_RGB], line_radii=[0.012],
                                           labels=["idler"]),
        E_GUIDE: rr.LineStrips2D.from_fields(colors=[GUIDE_RGB], radii=[0.03], labels=["idler guide"]),
        E_SPROCKET_TORQUE: rr.SeriesLines(colors=[SPROCKET_RGB], names=["sprocket drive torque (N m)"]),
        E_IDLER_FORCE: rr.SeriesLines(colors=[(0, 0, 0)], names=["idler tensioner force (N)"]),
    }
    if n_rollers:   # a layout without rollers has no roller entity at all
        styles[E_ROLLERS] = rr.Ellipses2D.from_fields(half_sizes=[[rr_, rr_]] * n_rollers, colors=[ROLLER_RGB],
                                                      line_radii=[0.01],
                                                      labels=[f"roller {i + 1}" for i in range(n_rollers)])
    return styles


def _log_closed_static(rec, ds):
    lay = G.closed_layout(ds)
    styles = _closed_styles(float(lay["idler_radius"]), float(lay["roller_radius"]), len(lay["rollers"]))
    for e, style in styles.items():
        rec.log(e, style, static=True)


def _log_static(rec, ds):
    styles = _static_styles(int(ds.sizes["wheel"]), float(ds.attrs["wheel_radius"]))
    rec.log(E_GROUND, rr.LineStrips2D([_flip(G.ground_polyline(ds))], colors=[GROUND_RGB], radii=[0.015],
                                      labels=["ground"]), static=True)
    for e in (E_CHASSIS, E_ARMS, E_WHEELS, E_LINKS, E_PINS, E_WHEEL_FORCE, E_GROUND_FORCE,
              E_WHEEL_FY, E_AY, E_VX, E_ENERGY, E_TENSION):
        rec.log(e, styles[e], static=True)
    rec.log(E_PARAMS, rr.TextDocument(parameters_text(ds), media_type=rr.MediaType.MARKDOWN), static=True)
    rec.log(E_SOLVER, rr.TextDocument(solver_text(ds), media_type=rr.MediaType.MARKDOWN), static=True)
    if G.is_closed(ds):
        _log_closed_static(rec, ds)
    if G.is_soil(ds):
        rec.log(E_SOIL, rr.LineStrips2D.from_fields(colors=[SOIL_RGB], radii=[0.01],
                                                    labels=["soil surface (rut so far)"]), static=True)


def _log_signals(rec, ds, every=1):
    """Time series at every output frame (keeps the peaks), or at every ``every``-th (and the
    last: compact storage). Multi-series entities (wheel forces, energies) hold one scalar per
    series per row."""
    idx = None if every == 1 else frame_indices(ds.sizes["time"], every)
    t = [rr.TimeColumn(TIMELINE, duration=np.asarray(_rows(ds.variables["time"].values, idx), dtype=np.float64))]
    d = rr.Scalars.descriptor_scalars()

    def scalars(a):
        a = np.ascontiguousarray(_rows(a, idx), dtype=np.float64)
        n, k = a.shape[0], (a.shape[1] if a.ndim == 2 else 1)
        return [_Column(d, _list(pa.array(a.reshape(-1), type=_SCALAR_TYPE), n, k))]

    rec.send_columns(E_WHEEL_FY, indexes=t, columns=scalars(ds.variables["wheel_force_y"].values))
    rec.send_columns(E_AY, indexes=t, columns=scalars(ds.variables["chassis_ay"].values))
    rec.send_columns(E_VX, indexes=t, columns=scalars(ds.variables["chassis_vx"].values))
    e = np.stack([ds.variables[var].values for _, var, _ in ENERGY_SERIES], axis=1)
    rec.send_columns(E_ENERGY, indexes=t, columns=scalars(e))
    rec.send_columns(E_TENSION, indexes=t, columns=scalars(np.nanmax(ds.variables["link_tension"].values, axis=1)))
    if G.is_closed(ds):
        rec.send_columns(E_SPROCKET_TORQUE, indexes=t, columns=scalars(ds.variables["sprocket_torque"].values))
        rec.send_columns(E_IDLER_FORCE, indexes=t, columns=scalars(ds.variables["idler_force"].values))


def _rows(a, idx):
    return a if idx is None else np.asarray(a)[idx]


def _log_track(rec, t, take, n, closed=False):
    """Pins and links (coloured by tension) at the frames; returns the pins' x and y.
    The links' ends as geometry.link_ends: the closed loop has a link more than the
    paper's track, link 0, from the last pin back to the first."""
    send = rec.send_columns
    pin_x, pin_y = take("pin_x"), take("pin_y")
    pins = _xy32(pin_x, pin_y)                                    # (n, np, 2)
    npin = pins.shape[1]
    shift = int(closed)          # the loop's link 0 comes first: the others move up one place
    nl = npin - 1 + shift
    send(E_PINS, indexes=t, columns=[_Column(rr.Points2D.descriptor_positions(), _list(_vec2(pins), n, npin))])
    p64 = pins.view(np.uint64)[..., 0]                           # one (x, y) float32 pair as 8 bytes
    links64 = np.empty((n, nl, 2), dtype=np.uint64)
    links64[:, shift:, 0] = p64[:, :-1]
    links64[:, :, 1] = p64[:, 1 - shift:]
    if closed:
        links64[:, 0, 0] = p64[:, -1]
    links = links64.view(np.float32)                              # (n, nl, 4): the link's two ends
    colors = G.tension_rgba32(take("link_tension"))
    send(E_LINKS, indexes=t,
         columns=[_Column(rr.LineStrips2D.descriptor_strips(), _list(_strip_values(links.reshape(n * nl, 2, 2)), n, nl)),
                  _Column(rr.LineStrips2D.descriptor_colors(), _list(pa.array(colors.reshape(-1), type=_COLOR_TYPE), n, nl))])
    return pin_x, pin_y


def _log_frames(rec, ds, idx):
    """The side view at the frames `idx`: the same geometry as geometry.side_view, computed
    straight into float32 (y negated) buffers and Arrow arrays, one send_columns per entity.
    The track (the bulk of the data) goes first: rerun encodes it on its own thread while
    the rest is prepared."""
    idx = np.asarray(idx)
    n = len(idx)
    full = n == ds.sizes["time"] and (n == 0 or (idx[0] == 0 and idx[-1] == n - 1))

    def take(name):
        v = np.asarray(ds.variables[name].values)
        return v if full else v[idx]

    t = [rr.TimeColumn(TIMELINE, duration=take("time"))]
    send = rec.send_columns
    closed = G.is_closed(ds)
    pin_x, pin_y = _log_track(rec, t, take, n, closed)
    if closed:
        _log_closed_parts(rec, ds, t, take, n)
    free = slice(None) if closed else slice(1, -1)   # the pins that can touch the ground

    # chassis outline, arms (pivot to wheel centre), wheel-track force arrows (from the
    # contact region along the force), ground force (total) at the pad-compression-weighted
    # centre of the pins' ground contacts: worked out in blocks of frames, straight into the
    # float32 output buffers (small temporaries: no page faults on megabytes of them)
    x, y, th = take("chassis_x"), take("chassis_y"), take("chassis_pitch")
    cos, sin = np.cos(th), np.sin(th)
    bx, by = G.hull_body(ds)
    piv = np.asarray(G.attr_json(ds, "arm_pivots"), float)
    wx, wy = take("wheel_x"), take("wheel_y")
    fx, fy = take("wheel_force_x"), take("wheel_force_y")
    gfx, gfy = take("ground_force_x"), take("ground_force_y")
    nw = wx.shape[1]
    reach = float(ds.attrs["wheel_radius"]) + float(ds.attrs["pad_wheel"])
    poly, hg = G.ground_polyline(ds), float(ds.attrs["pad_ground"])
    chassis = np.empty((n, len(bx), 2), dtype=np.float32)
    arms = np.empty((n, nw, 2, 2), dtype=np.float32)
    origin = np.empty((n, nw, 2), dtype=np.float32)
    vector = np.empty((n, nw, 2), dtype=np.float32)
    g_origin = np.empty((n, 2), dtype=np.float32)
    g_vector = np.empty((n, 2), dtype=np.float32)
    for lo in range(0, n, _FRAME_BLOCK):
        b = slice(lo, min(n, lo + _FRAME_BLOCK))
        c, s, xb, yb = cos[b], sin[b], x[b, None], y[b, None]
        hx, hy = G._rotate(c, s, bx, by)
        _xy32(xb + hx, yb + hy, out=chassis[b])
        px, py = G._rotate(c, s, piv[:, 0], piv[:, 1])
        _xy32(xb + px, yb + py, out=arms[b, :, 0])
        _xy32(wx[b], wy[b], out=arms[b, :, 1])
        fxb, fyb = fx[b], fy[b]
        mag = np.hypot(fxb, fyb)
        pos = mag > 0.0
        safe = np.where(pos, mag, 1.0)
        ux = np.where(pos, fxb / safe, 0.0)
        uy = np.where(pos, fyb / safe, 1.0)
        _xy32(wx[b] - reach * ux, wy[b] - reach * uy, out=origin[b])
        _xy32(G.FORCE_SCALE * fxb, G.FORCE_SCALE * fyb, out=vector[b])
        centre = G.ground_arrow_centre(pin_x[b, free], pin_y[b, free], poly, hg)
        gx, gy = gfx[b] * G.FORCE_SCALE, gfy[b] * G.FORCE_SCALE
        _xy32(centre[:, 0] - gx, centre[:, 1] - gy, out=g_origin[b])
        _xy32(gx, gy, out=g_vector[b])
    strips = rr.LineStrips2D.descriptor_strips()
    if G.is_soil(ds):   # the deformed soil surface: the ground lowered by the rut so far
        base, drop = G.soil_surface(ds, idx)
        surface = _xy32(np.broadcast_to(base[:, 0], drop.shape), base[:, 1] - drop)
        send(E_SOIL, indexes=t, columns=[_Column(strips, _list(_strip_values(surface), n, 1))])
    send(E_CHASSIS, indexes=t, columns=[_Column(strips, _list(_strip_values(chassis), n, 1))])
    send(E_ARMS, indexes=t, columns=[_Column(strips, _list(_strip_values(arms.reshape(n * nw, 2, 2)), n, nw))])
    wheels = np.ascontiguousarray(arms[:, :, 1])
    send(E_WHEELS, indexes=t, columns=[_Column(rr.Ellipses2D.descriptor_centers(), _list(_vec2(wheels), n, nw))])
    send(E_WHEEL_FORCE, indexes=t,
         columns=[_Column(rr.Arrows2D.descriptor_origins(), _list(_vec2(origin), n, nw)),
                  _Column(rr.Arrows2D.descriptor_vectors(), _list(_vec2(vector), n, nw))])
    send(E_GROUND_FORCE, indexes=t,
         columns=[_Column(rr.Arrows2D.descriptor_origins(), _list(_vec2(g_origin), n, 1)),
                  _Column(rr.Arrows2D.descriptor_vectors(), _list(_vec2(g_vector), n, 1))])


def _log_closed_parts(rec, ds, t, take, n):
    """The closed layout's sprocket (its tooth profile, turned frame by frame), idler,
    idler guide and rollers at the frames, as geometry.closed_parts (worked out in blocks
    of frames straight into float32 buffers, y negated)."""
    lay = G.closed_layout(ds)
    outline = G.sprocket_outline(lay)
    x, y, th = take("chassis_x"), take("chassis_y"), take("chassis_pitch")
    angle, ix, iy = take("sprocket_angle"), take("idler_x"), take("idler_y")
    nr = len(lay["rollers"])
    bufs = {"sprocket": np.empty((n, len(outline), 2), dtype=np.float32),
            "idler": np.empty((n, 2), dtype=np.float32),
            "guide": np.empty((n, 2, 2), dtype=np.float32),
            "rollers": np.empty((n, nr, 2), dtype=np.float32)}
    for lo in range(0, n, _FRAME_BLOCK):
        b = slice(lo, min(n, lo + _FRAME_BLOCK))
        parts = G.closed_parts(lay, outline, x[b], y[b], th[b], angle[b], ix[b], iy[b])
        for name, out in bufs.items():
            _xy32(parts[name][..., 0], parts[name][..., 1], out=out[b])
    strips = rr.LineStrips2D.descriptor_strips()
    send = rec.send_columns
    send(E_SPROCKET, indexes=t, columns=[_Column(strips, _list(_strip_values(bufs["sprocket"]), n, 1))])
    send(E_GUIDE, indexes=t, columns=[_Column(strips, _list(_strip_values(bufs["guide"]), n, 1))])
    send(E_IDLER, indexes=t, columns=[_Column(rr.Ellipses2D.descriptor_centers(), _list(_vec2(bufs["idler"]), n, 1))])
    if nr:   # a layout without rollers logs no roller entity
        send(E_ROLLERS, indexes=t,
             columns=[_Column(rr.Ellipses2D.descriptor_centers(), _list(_vec2(bufs["rollers"]), n, nr))])


def write_recording(ds, path, every=1, signal_every=1):
    """Write the run's rerun recording to `path` (atomically); returns the Path.

    every: log the side-view geometry at every `every`-th output frame (and the last);
    signal_every: the same for the time series (1, every frame, keeps their peaks)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    idx = frame_indices(ds.sizes["time"], int(every))
    sc = G.scenario_of(ds)
    rec = rr.RecordingStream("trackbench", recording_id=str(uuid.uuid4()), send_properties=True)
    with atomic_path(path) as tmp:
        try:
            rec.save(tmp, default_blueprint=blueprint(ds))
            rec.send_recording_name(f"trackbench {sc.get('name', 'run')}")
            # rerun encodes what was sent on its own thread while the next entity is prepared:
            # the time series first (nothing to prepare), then the geometry
            _log_signals(rec, ds, int(signal_every))
            _log_frames(rec, ds, idx)
            _log_static(rec, ds)
            rec.flush()
        finally:
            rec.disconnect()
    return path


def maybe_write_recording(ds, folder, name=RECORDING_NAME, storage="full"):
    """Write folder/name when the scenario's record.enabled is true (with its record.every,
    thinned for compact storage); returns the Path, or None when recording is switched off."""
    enabled, every = record_settings(ds)
    if not enabled:
        return None
    from ..storage import recording_steps
    frames, signals = recording_steps(every, storage)
    return write_recording(ds, Path(folder) / name, every=frames, signal_every=signals)
