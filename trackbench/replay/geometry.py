"""What the side view draws, computed from a run Dataset with numpy only (shared by the
rerun recording and the matplotlib configuration plots).

Drawing choices (documented in results_schema.md, section "recording"):

- Chassis outline: a rectangle fixed in the chassis frame, x from the rear track end
  - 0.1 m to the front track end + 0.1 m, y from -0.3 m to +0.6 m relative to the mass
  centre, rotated by the pitch. It is a drawing aid (the model's hull has no shape).
- Arms: straight lines from the pivot (chassis position + rotated pivot body point) to
  the road-wheel centre. Wheels: circles of the true radius.
- Wheel-track force on each wheel: an arrow starting at the wheel's contact region
  (wheel centre minus (r + h_w) along the force direction) pointing along the force.
- Ground force: the Dataset holds only the total ground force on the track. It is drawn
  as one arrow ending at an estimate of the centre of pressure: the mean of the nearest
  ground points of the free pins that touch the ground, weighted by their pad
  compression (h_g - distance to the ground). The arrow comes from below the ground.
- Scale of every force arrow: FORCE_SCALE metres per newton (1 m per 200 kN).
"""

import json

import numpy as np

HULL_MARGIN = 0.1      # m beyond each track end
HULL_BOTTOM = -0.3     # m below the mass centre (chassis frame)
HULL_TOP = 0.6         # m above the mass centre
FORCE_SCALE = 1.0 / 200e3  # m per N: 1 m per 200 kN
GROUND_MARGIN = 1.0    # m of ground drawn beyond the region the track covers

# link tension colour scale: (tension in N, RGB)
TENSION_STOPS = np.array([-100e3, 0.0, 80e3, 160e3, 300e3])
TENSION_RGB = np.array([
    [40, 90, 230],     # compression: blue
    [170, 170, 170],   # slack: grey
    [40, 160, 60],     # about the static pretension (80 kN): green
    [240, 190, 0],     # twice it: amber
    [220, 30, 30],     # 300 kN and more: red
], dtype=float)


def attr_json(ds, name):
    v = ds.attrs[name]
    return json.loads(v) if isinstance(v, (str, bytes)) else v


def scenario_of(ds):
    return attr_json(ds, "scenario")


def tension_rgb(tension):
    """Link tension (N), any shape -> float RGB in 0..255, shape (..., 3)."""
    t = np.clip(np.asarray(tension, dtype=float), TENSION_STOPS[0], TENSION_STOPS[-1])
    return np.stack([np.interp(t, TENSION_STOPS, TENSION_RGB[:, k]) for k in range(3)], axis=-1)


_LUT_STEP = 250.0  # N per entry of the colour lookup table


def _lut():
    t = np.arange(TENSION_STOPS[0], TENSION_STOPS[-1] + _LUT_STEP, _LUT_STEP)
    rgb = np.rint(tension_rgb(t)).astype(np.uint32)
    return (rgb[:, 0] << 24) | (rgb[:, 1] << 16) | (rgb[:, 2] << 8) | np.uint32(255)


_RGBA_LUT = _lut()


def tension_rgba32(tension):
    """Link tension (N) -> packed 0xRRGGBBAA uint32, as rerun stores colours (lookup table,
    250 N resolution)."""
    k = np.rint((np.asarray(tension, dtype=np.float64) - TENSION_STOPS[0]) * (1.0 / _LUT_STEP))
    np.clip(k, 0, len(_RGBA_LUT) - 1, out=k)
    return _RGBA_LUT[k.astype(np.intp)]


def _rotate(c, s, bx, by):
    """Body points (bx, by) rotated by the pitch (c = cos, s = sin, shape (n,))."""
    bx, by = np.asarray(bx, float), np.asarray(by, float)
    return (c[:, None] * bx - s[:, None] * by, s[:, None] * bx + c[:, None] * by)


def covered_x_range(ds):
    """x range the track covers during the run, with GROUND_MARGIN each side."""
    px = ds.variables["pin_x"].values
    wx = ds.variables["wheel_x"].values
    r = float(ds.attrs["wheel_radius"])
    lo = min(np.nanmin(px), np.nanmin(wx) - r) - GROUND_MARGIN
    hi = max(np.nanmax(px), np.nanmax(wx) + r) + GROUND_MARGIN
    return float(lo), float(hi)


def ground_polyline(ds, x_range=None):
    """The ground vertices (m, 2) clipped to x_range (default: the covered range)."""
    v = np.asarray(attr_json(ds, "ground_vertices"), dtype=float)
    x0, x1 = covered_x_range(ds) if x_range is None else x_range

    def at(x):
        for i in range(len(v) - 1):
            if v[i, 0] <= x <= v[i + 1, 0] and v[i + 1, 0] > v[i, 0]:
                u = (x - v[i, 0]) / (v[i + 1, 0] - v[i, 0])
                return [x, v[i, 1] + u * (v[i + 1, 1] - v[i, 1])]
        return [x, v[0, 1] if x < v[0, 0] else v[-1, 1]]

    inner = v[(v[:, 0] > x0) & (v[:, 0] < x1)]
    return np.vstack([[at(x0)], inner.reshape(-1, 2), [at(x1)]])


def _nearest_on_polyline(p, poly):
    """p (..., 2) -> (distance (...), nearest point (..., 2)) to the polyline."""
    px, py = p[..., 0], p[..., 1]
    best = np.full(px.shape, np.inf)
    nx = np.zeros(px.shape)
    ny = np.zeros(px.shape)
    for (ax, ay), (bx, by) in zip(poly[:-1], poly[1:]):   # a handful of segments
        dx, dy = bx - ax, by - ay
        l2 = dx * dx + dy * dy
        if l2 == 0.0:
            continue
        u = np.clip(((px - ax) * dx + (py - ay) * dy) / l2, 0.0, 1.0)
        fx, fy = ax + u * dx, ay + u * dy
        d2 = (px - fx) ** 2 + (py - fy) ** 2
        closer = d2 < best
        best = np.where(closer, d2, best)
        nx = np.where(closer, fx, nx)
        ny = np.where(closer, fy, ny)
    return np.sqrt(best), np.stack([nx, ny], axis=-1)


def side_view(ds, idx=None):
    """Geometry of the frames `idx` (default: all) as numpy arrays (n = len(idx)).

    Returns a dict: time (n,), chassis (n, 5, 2) closed outline, pivots and wheels
    (n, nw, 2), pins (n, np, 2), tension (n, nl), wheel_force (n, nw, 2),
    wheel_arrow_origin / wheel_arrow_vector (n, nw, 2), ground_arrow_origin /
    ground_arrow_vector (n, 2); arrow vectors in m (FORCE_SCALE applied)."""
    if idx is None:
        idx = np.arange(ds.sizes["time"])
    idx = np.asarray(idx)

    full = len(idx) == ds.sizes["time"] and np.array_equal(idx, np.arange(len(idx)))

    def take(name):
        v = np.asarray(ds.variables[name].values)
        return v if full else v[idx]

    x, y, th = take("chassis_x"), take("chassis_y"), take("chassis_pitch")
    c, s = np.cos(th), np.sin(th)
    ends = np.asarray(attr_json(ds, "track_ends"), float)
    front, rear = float(np.max(ends[:, 0])), float(np.min(ends[:, 0]))
    bx = np.array([rear - HULL_MARGIN, front + HULL_MARGIN, front + HULL_MARGIN, rear - HULL_MARGIN, rear - HULL_MARGIN])
    by = np.array([HULL_BOTTOM, HULL_BOTTOM, HULL_TOP, HULL_TOP, HULL_BOTTOM])
    hx, hy = _rotate(c, s, bx, by)
    chassis = np.stack([x[:, None] + hx, y[:, None] + hy], axis=-1)
    piv = np.asarray(attr_json(ds, "arm_pivots"), float)
    px, py = _rotate(c, s, piv[:, 0], piv[:, 1])
    pivots = np.stack([x[:, None] + px, y[:, None] + py], axis=-1)
    wheels = np.stack([take("wheel_x"), take("wheel_y")], axis=-1)
    pins = np.stack([take("pin_x"), take("pin_y")], axis=-1)
    f = np.stack([take("wheel_force_x"), take("wheel_force_y")], axis=-1)
    mag = np.hypot(f[..., 0], f[..., 1])
    unit = np.where(mag[..., None] > 0.0, f / np.where(mag > 0.0, mag, 1.0)[..., None], np.array([0.0, 1.0]))
    reach = float(ds.attrs["wheel_radius"]) + float(ds.attrs["pad_wheel"])
    out = {
        "time": take("time"),
        "chassis": chassis,
        "pivots": pivots,
        "wheels": wheels,
        "pins": pins,
        "tension": take("link_tension"),
        "wheel_force": f,
        "wheel_arrow_origin": wheels - reach * unit,
        "wheel_arrow_vector": FORCE_SCALE * f,
    }
    # ground force at the pad-compression-weighted centre of the free pins' ground contacts
    hg = float(ds.attrs["pad_ground"])
    free = pins[:, 1:-1]
    poly = ground_polyline(ds)
    # only pins below the highest ground point + h_g can touch: compute those alone
    low = free[..., 1] < float(poly[:, 1].max()) + hg
    fi, pi = np.nonzero(low)
    dist, near = _nearest_on_polyline(free[fi, pi], poly)
    w = np.maximum(hg - dist, 0.0)
    n = len(idx)
    wsum = np.bincount(fi, weights=w, minlength=n)
    cx = np.bincount(fi, weights=w * near[:, 0], minlength=n)
    cy = np.bincount(fi, weights=w * near[:, 1], minlength=n)
    touching = wsum > 0.0
    safe = np.where(touching, wsum, 1.0)
    centre = np.stack([cx / safe, cy / safe], axis=-1)
    # no pin touching (the track airborne, or only on a corner): the arrow (then about zero)
    # sits below the track's lowest pin, on the ground
    lowest = np.argmin(free[..., 1], axis=1)
    _, under = _nearest_on_polyline(free[np.arange(n), lowest], poly)
    centre = np.where(touching[:, None], centre, under)
    g = np.stack([take("ground_force_x"), take("ground_force_y")], axis=-1) * FORCE_SCALE
    out["ground_arrow_origin"] = centre - g
    out["ground_arrow_vector"] = g
    return out
