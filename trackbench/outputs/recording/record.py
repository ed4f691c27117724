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

import uuid
from pathlib import Path

import numpy as np
import pyarrow as pa
import rerun as rr
from rerun.components import LineStrip2DBatch

from trackbench.outputs import geometry as G
from trackbench.outputs.files.atomic import atomic_path
from trackbench.outputs.recording import soil_view as S
from trackbench.outputs.recording.entities import (
    E_ARMS,
    E_AY,
    E_CHASSIS,
    E_ENERGY,
    E_GROUND,
    E_GROUND_FORCE,
    E_GUIDE,
    E_IDLER,
    E_IDLER_FORCE,
    E_LINKS,
    E_PARAMS,
    E_PINS,
    E_ROLLERS,
    E_SEAT,
    E_SOIL,
    E_SOLVER,
    E_SPROCKET,
    E_SPROCKET_TORQUE,
    E_TENSION,
    E_VX,
    E_WHEEL_FORCE,
    E_WHEEL_FY,
    E_WHEELS,
    E_WORLD,
    ENERGY_SERIES,
    GROUND_RGB,
    SOIL_RGB,
    TIMELINE,
)
from trackbench.outputs.recording.panels import blueprint, parameters_text, solver_text
from trackbench.outputs.recording.styles import _closed_styles, _static_styles

RECORDING_NAME = "recording.rrd"


_STRIP_TYPE = LineStrip2DBatch._ARROW_DATATYPE
_VEC2_TYPE = rr.components.Position2DBatch._ARROW_DATATYPE   # fixed_size_list<float32 not null>[2]
_COLOR_TYPE = rr.components.ColorBatch._ARROW_DATATYPE       # uint32 0xRRGGBBAA
_SCALAR_TYPE = rr.components.ScalarBatch._ARROW_DATATYPE     # float64
_FRAME_BLOCK = 2048  # frames per block when working out the side view (keeps temporaries small)
# samples logged at a time: a long run's recording is worked out and streamed to its file
# block by block (from a file opened lazily, only a block is read), its memory that of a block
RECORD_BLOCK = 8192


def record_settings(ds):
    """(enabled, every: output samples per side-view frame) from the run's scenario
    (attrs['scenario'], JSON): record.every, or frames at record.fps."""
    from trackbench.outputs.files.storage import frame_step
    sc = G.scenario_of(ds)
    rec = sc.get("record", {})
    return bool(rec.get("enabled", True)), frame_step(rec, sc.get("output_interval", 1e-4))


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


def _log_closed_static(rec, ds):
    lay = G.closed_layout(ds)
    styles = _closed_styles(float(lay["idler_radius"]), float(lay["roller_radius"]), len(lay["rollers"]))
    for e, style in styles.items():
        rec.log(e, style, static=True)


def _log_static(rec, ds):
    styles = _static_styles(tuple(float(r) for r in G.wheel_radii(ds)))
    rec.log(E_GROUND, rr.LineStrips2D([_flip(G.ground_polyline(ds))], colors=[GROUND_RGB], radii=[0.015],
                                      labels=["ground"]), static=True)
    for e in (E_CHASSIS, E_ARMS, E_WHEELS, E_LINKS, E_PINS, E_WHEEL_FORCE, E_GROUND_FORCE,
              E_WHEEL_FY, E_AY, E_SEAT, E_VX, E_ENERGY, E_TENSION):
        rec.log(e, styles[e], static=True)
    rec.log(E_PARAMS, rr.TextDocument(parameters_text(ds), media_type=rr.MediaType.MARKDOWN), static=True)
    rec.log(E_SOLVER, rr.TextDocument(solver_text(ds), media_type=rr.MediaType.MARKDOWN), static=True)
    if G.is_closed(ds):
        _log_closed_static(rec, ds)
    if S.is_soil(ds):
        rec.log(E_SOIL, rr.LineStrips2D.from_fields(colors=[SOIL_RGB], radii=[0.01],
                                                    labels=["soil surface (rut so far)"]), static=True)


def _log_signals(rec, ds, idx=None):
    """Time series at every output frame (idx None: keeps the peaks), or at the frames idx
    (compact storage: every k-th and the last). Multi-series entities (wheel forces,
    energies) hold one scalar per series per row."""
    t = [
        rr.TimeColumn(
            TIMELINE, duration=np.asarray(_rows(ds.variables["time"].values, idx), dtype=np.float64)
        )
    ]
    d = rr.Scalars.descriptor_scalars()

    def scalars(a):
        a = np.ascontiguousarray(_rows(a, idx), dtype=np.float64)
        n, k = a.shape[0], (a.shape[1] if a.ndim == 2 else 1)
        return [_Column(d, _list(pa.array(a.reshape(-1), type=_SCALAR_TYPE), n, k))]

    rec.send_columns(E_WHEEL_FY, indexes=t, columns=scalars(ds.variables["wheel_force_y"].values))
    rec.send_columns(E_AY, indexes=t, columns=scalars(ds.variables["chassis_ay"].values))
    rec.send_columns(E_SEAT, indexes=t, columns=scalars(ds.variables["seat_acceleration_y"].values))
    rec.send_columns(E_VX, indexes=t, columns=scalars(ds.variables["chassis_vx"].values))
    e = np.stack([ds.variables[var].values for _, var, _ in ENERGY_SERIES], axis=1)
    rec.send_columns(E_ENERGY, indexes=t, columns=scalars(e))
    rec.send_columns(
        E_TENSION, indexes=t, columns=scalars(np.nanmax(ds.variables["link_tension"].values, axis=1))
    )
    if G.is_closed(ds):
        rec.send_columns(
            E_SPROCKET_TORQUE, indexes=t, columns=scalars(ds.variables["sprocket_torque"].values)
        )
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
    send(
        E_PINS, indexes=t, columns=[_Column(rr.Points2D.descriptor_positions(), _list(_vec2(pins), n, npin))]
    )
    p64 = pins.view(np.uint64)[..., 0]                           # one (x, y) float32 pair as 8 bytes
    links64 = np.empty((n, nl, 2), dtype=np.uint64)
    links64[:, shift:, 0] = p64[:, :-1]
    links64[:, :, 1] = p64[:, 1 - shift:]
    if closed:
        links64[:, 0, 0] = p64[:, -1]
    links = links64.view(np.float32)                              # (n, nl, 4): the link's two ends
    colors = G.tension_rgba32(take("link_tension"))
    send(
        E_LINKS,
        indexes=t,
        columns=[
            _Column(
                rr.LineStrips2D.descriptor_strips(), _list(_strip_values(links.reshape(n * nl, 2, 2)), n, nl)
            ),
            _Column(
                rr.LineStrips2D.descriptor_colors(),
                _list(pa.array(colors.reshape(-1), type=_COLOR_TYPE), n, nl),
            ),
        ],
    )
    return pin_x, pin_y


def _log_frames(rec, ds, idx, follow=False):
    """The side view at the frames `idx`: the same geometry as geometry.side_view, computed
    straight into float32 (y negated) buffers and Arrow arrays, one send_columns per entity.
    The track (the bulk of the data) goes first: rerun encodes it on its own thread while
    the rest is prepared. follow (geometry.follow_window): the world moved under the chassis
    frame by frame, so that a long run's vehicle stays in the side view."""
    idx = np.asarray(idx)
    n = len(idx)
    full = n == ds.sizes["time"] and (n == 0 or (idx[0] == 0 and idx[-1] == n - 1))

    def take(name):
        v = np.asarray(ds.variables[name].values)
        return v if full else v[idx]

    t = [rr.TimeColumn(TIMELINE, duration=take("time"))]
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
    if follow:
        shift = np.zeros((n, 3), dtype=np.float32)
        shift[:, 0] = -x        # the chassis' mass centre at x = 0 of the view
        rec.send_columns(E_WORLD, indexes=t, columns=rr.Transform3D.columns(translation=shift))
    cos, sin = np.cos(th), np.sin(th)
    bx, by = G.hull_body(ds)
    piv = np.asarray(G.attr_json(ds, "arm_pivots"), float)
    wx, wy = take("wheel_x"), take("wheel_y")
    fx, fy = take("wheel_force_x"), take("wheel_force_y")
    gfx, gfy = take("ground_force_x"), take("ground_force_y")
    nw = wx.shape[1]
    reach = G.wheel_radii(ds) + float(ds.attrs["pad_wheel"])   # per wheel: broadcasts over samples
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
    _send_side_view(rec, ds, idx, t, (chassis, arms, origin, vector, g_origin, g_vector))

def _send_side_view(rec, ds, idx, t, parts):
    """One send_columns per entity of the side view worked out by _log_frames: the soil
    surface, chassis, arms, wheels and the force arrows."""
    chassis, arms, origin, vector, g_origin, g_vector = parts
    strips = rr.LineStrips2D.descriptor_strips()
    send = rec.send_columns
    n, nw = arms.shape[0], arms.shape[1]
    if S.is_soil(ds):   # the deformed soil surface: the ground lowered by the rut so far
        base, drop = S.soil_surface(ds, idx)
        surface = _xy32(np.broadcast_to(base[:, 0], drop.shape), base[:, 1] - drop)
        send(E_SOIL, indexes=t, columns=[_Column(strips, _list(_strip_values(surface), n, 1))])
    send(E_CHASSIS, indexes=t, columns=[_Column(strips, _list(_strip_values(chassis), n, 1))])
    send(
        E_ARMS, indexes=t, columns=[_Column(strips, _list(_strip_values(arms.reshape(n * nw, 2, 2)), n, nw))]
    )
    wheels = np.ascontiguousarray(arms[:, :, 1])
    send(
        E_WHEELS,
        indexes=t,
        columns=[_Column(rr.Ellipses2D.descriptor_centers(), _list(_vec2(wheels), n, nw))],
    )
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
    send(
        E_IDLER,
        indexes=t,
        columns=[_Column(rr.Ellipses2D.descriptor_centers(), _list(_vec2(bufs["idler"]), n, 1))],
    )
    if nr:   # a layout without rollers logs no roller entity
        send(E_ROLLERS, indexes=t,
             columns=[_Column(rr.Ellipses2D.descriptor_centers(), _list(_vec2(bufs["rollers"]), n, nr))])


def write_recording(ds, path, every=1, signal_every=1):
    """Write the run's rerun recording to `path` (atomically); returns the Path.

    every: log the side-view geometry at every `every`-th output frame (and the last);
    signal_every: the same for the time series (1, every frame, keeps their peaks)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    n = ds.sizes["time"]
    idx = frame_indices(n, int(every))
    signals = None if int(signal_every) == 1 else frame_indices(n, int(signal_every))
    block = n if S.is_soil(ds) else RECORD_BLOCK   # the soil's surface is rebuilt from the whole run
    sc = G.scenario_of(ds)
    follow = G.follow_window(ds) is not None
    rec = rr.RecordingStream("trackbench", recording_id=str(uuid.uuid4()), send_properties=True)
    with atomic_path(path) as tmp:
        try:
            rec.save(tmp, default_blueprint=blueprint(ds, follow))
            rec.send_recording_name(f"trackbench {sc.get('name', 'run')}")
            # rerun encodes what was sent on its own thread while the next entity is prepared:
            # the time series first (nothing to prepare), then the geometry
            for a in range(0, n, max(block, 1)):
                part = ds if block >= n else ds.isel(time=slice(a, a + block))
                _log_signals(rec, part, _within(signals, a, block))
                frames = _within(idx, a, block)
                if len(frames):
                    _log_frames(rec, part, frames, follow)
            _log_static(rec, ds)
            rec.flush()
        finally:
            rec.disconnect()
    return path


def _within(idx, a, block):
    """The indices idx in [a, a + block), counted from a (None stays None: every sample)."""
    if idx is None:
        return None
    return idx[(idx >= a) & (idx < a + block)] - a


def maybe_write_recording(ds, folder, name=RECORDING_NAME, storage="full"):
    """Write folder/name when the scenario's record.enabled is true (with its record.every,
    thinned for compact storage); returns the Path, or None when recording is switched off."""
    enabled, every = record_settings(ds)
    if not enabled:
        return None
    from trackbench.outputs.files.storage import recording_steps
    frames, signals = recording_steps(every, storage)
    return write_recording(ds, Path(folder) / name, every=frames, signal_every=signals)
