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
- Closed track layout (attrs["track_layout"] == "closed"): the pins form a loop, the last
  joined to the first by link 0; every pin is free. The sprocket is its tooth profile
  (model.sprocket.profile) turned by its absolute angle, the idler a circle on a guide
  segment 2 x travel long, fixed in the chassis, the support rollers circles.
"""

import math

import numpy as np

from trackbench.outputs.variables import attr_json, scenario_of  # noqa: F401  (G.attr_json, G.scenario_of)

HULL_MARGIN = 0.1      # m beyond each track end
HULL_BOTTOM = -0.3     # m below the mass centre (chassis frame)
HULL_TOP = 0.6         # m above the mass centre
FORCE_SCALE = 1.0 / 200e3  # m per N: 1 m per 200 kN
GROUND_MARGIN = 1.0    # m of ground drawn beyond the region the track covers
FOLLOW_SPAN = 20.0     # m: a run covering more ground than this is viewed following the chassis
_BLOCK = 8192          # elements per block in the blocked helpers: temporaries stay small and cached

# link tension colour scale: (tension in N, RGB)
TENSION_STOPS = np.array([-100e3, 0.0, 80e3, 160e3, 300e3])
TENSION_RGB = np.array([
    [40, 90, 230],     # compression: blue
    [170, 170, 170],   # slack: grey
    [40, 160, 60],     # about the static pretension (80 kN): green
    [240, 190, 0],     # twice it: amber
    [220, 30, 30],     # 300 kN and more: red
], dtype=float)


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
    250 N resolution). Works in blocks (small temporaries, no page faults on big inputs)."""
    t = np.asarray(tension, dtype=np.float64)
    out = np.empty(t.shape, dtype=np.uint32)
    flat_t = t.reshape(-1)
    flat_o = out.reshape(-1)
    top = len(_RGBA_LUT) - 1
    inv = 1.0 / _LUT_STEP
    k = np.empty(min(flat_t.size, _BLOCK))
    for lo in range(0, flat_t.size, _BLOCK):
        hi = min(flat_t.size, lo + _BLOCK)
        kb = k[:hi - lo]
        np.subtract(flat_t[lo:hi], TENSION_STOPS[0], out=kb)
        kb *= inv
        np.rint(kb, out=kb)
        np.clip(kb, 0, top, out=kb)
        np.take(_RGBA_LUT, kb.astype(np.intp), out=flat_o[lo:hi])
    return out


def _rotate(c, s, bx, by):
    """Body points (bx, by) rotated by the pitch (c = cos, s = sin, shape (n,))."""
    bx, by = np.asarray(bx, float), np.asarray(by, float)
    return (c[:, None] * bx - s[:, None] * by, s[:, None] * bx + c[:, None] * by)


def is_closed(ds):
    """True for a closed-layout run (the paper layout's Datasets carry no track_layout)."""
    return ds.attrs.get("track_layout") == "closed"


def free_pins(pins, closed):
    """The pins (..., np, 2) that can touch the ground: the paper's first and last pins are
    fixed on the chassis, every pin of the closed loop is free."""
    return pins if closed else pins[..., 1:-1, :]


def link_ends(pins, closed):
    """Pins (..., np, 2) -> the two ends of every link (..., nl, 2, 2), in link order. The
    paper's link b joins pins b and b+1; the closed loop's link 0 joins the last pin back to
    the first (its link b the pins b-1 and b in array order), which closes the drawing."""
    start = np.roll(pins, 1, axis=-2) if closed else pins[..., :-1, :]
    end = pins if closed else pins[..., 1:, :]
    return np.stack([start, end], axis=-2)


def closed_layout(ds):
    """The closed layout's parts (attrs['closed_layout']: body points and sizes of the
    sprocket, the idler and its guide, the rollers)."""
    return attr_json(ds, "closed_layout")


def sprocket_outline(lay):
    """The sprocket's tooth profile at angle 0 about its axis (m, 2), closed. Every frame
    draws it turned by the sprocket's angle: the seats are laid out from that angle, so the
    turned outline is profile(angle) without building the polyline again frame by frame."""
    from trackbench.model.vehicle.teeth import profile

    return profile(
        lay["teeth"],
        lay["pitch_radius"],
        lay["seat_radius"],
        lay["tip_radius"],
        lay["pin_radius"],
        flank_angle=math.radians(lay["flank_angle"]),
    )


def _world(x, y, c, s, body):
    """Body points (k, 2) at the frames' chassis positions (x, y) and pitch (c, s): (n, k, 2)."""
    body = np.asarray(body, float).reshape(-1, 2)
    rx, ry = _rotate(c, s, body[:, 0], body[:, 1])
    return np.stack([x[:, None] + rx, y[:, None] + ry], axis=-1)


def closed_parts(lay, outline, x, y, pitch, sprocket_angle, idler_x, idler_y):
    """The closed layout's parts at some frames (every argument but lay and outline (n,)).

    sprocket (n, m, 2): the outline turned by the sprocket's absolute angle (pitch -
    sprocket_angle: sprocket_angle is relative to the chassis, clockwise positive) about
    its axis, sprocket_axis (n, 2); idler (n, 2) its centre; guide (n, 2, 2) the guide's
    two ends, travel either side of the idler's slide-0 point and fixed in the chassis;
    rollers (n, k, 2) their centres."""
    c, s = np.cos(pitch), np.sin(pitch)
    axis = _world(x, y, c, s, lay["sprocket"])                       # (n, 1, 2)
    turn = pitch - sprocket_angle
    tx, ty = _rotate(np.cos(turn), np.sin(turn), outline[:, 0], outline[:, 1])
    half = float(lay["travel"]) * np.asarray(lay["guide"], float)
    ends = np.asarray(lay["idler"], float) + np.stack([-half, half])
    return {
        "sprocket": axis + np.stack([tx, ty], axis=-1),
        "sprocket_axis": axis[:, 0],
        "idler": np.stack([idler_x, idler_y], axis=-1),
        "guide": _world(x, y, c, s, ends),
        "rollers": _world(x, y, c, s, lay["rollers"]),
    }


def wheel_radii(ds):
    """Each road wheel's radius (m), front to rear: the attribute wheel_radii where the wheels
    differ, else wheel_radius for every wheel."""
    if "wheel_radii" in ds.attrs:
        return np.asarray(attr_json(ds, "wheel_radii"), float)
    return np.full(ds.sizes["wheel"], float(ds.attrs["wheel_radius"]))


def covered_x_range(ds, block=8192):
    """x range the track covers during the run, with GROUND_MARGIN each side (read block by
    block of samples: a long run's file opened lazily is never read whole)."""
    r = float(wheel_radii(ds).max())
    n = ds.sizes["time"]
    lo, hi = np.inf, -np.inf
    for a in range(0, max(n, 1), block):
        part = ds if n <= block else ds.isel(time=slice(a, a + block))
        px = part.variables["pin_x"].values
        wx = part.variables["wheel_x"].values
        lo = min(lo, np.nanmin(px), np.nanmin(wx) - r)
        hi = max(hi, np.nanmax(px), np.nanmax(wx) + r)
    return float(lo - GROUND_MARGIN), float(hi + GROUND_MARGIN)


def follow_window(ds):
    """For a run covering more than FOLLOW_SPAN of ground (a ride, a long run), the side view's
    x range about the chassis' mass centre, the track at t = 0 with GROUND_MARGIN each side
    (the recording then moves the world under the chassis); None for a shorter run, seen whole."""
    lo, hi = covered_x_range(ds)
    if hi - lo <= FOLLOW_SPAN:
        return None
    x0 = float(ds.variables["chassis_x"].values[0])
    first = ds.isel(time=0)
    r = float(wheel_radii(ds).max())
    px, wx = first.variables["pin_x"].values, first.variables["wheel_x"].values
    left = min(float(np.nanmin(px)), float(np.nanmin(wx)) - r)
    right = max(float(np.nanmax(px)), float(np.nanmax(wx)) + r)
    return left - x0 - GROUND_MARGIN, right - x0 + GROUND_MARGIN


def ground_vertices(ds):
    """The ground polyline's vertices (n, 2), m: the terrain the run had, rough ground included."""
    return np.column_stack([ds["ground_x"].values, ds["ground_y"].values])


def ground_polyline(ds, x_range=None):
    """The ground vertices (m, 2) clipped to x_range (default: the covered range)."""
    v = ground_vertices(ds)
    x0, x1 = covered_x_range(ds) if x_range is None else x_range

    def at(x):
        for i in range(len(v) - 1):
            if v[i, 0] <= x <= v[i + 1, 0] and v[i + 1, 0] > v[i, 0]:
                u = (x - v[i, 0]) / (v[i + 1, 0] - v[i, 0])
                return [x, v[i, 1] + u * (v[i + 1, 1] - v[i, 1])]
        return [x, v[0, 1] if x < v[0, 0] else v[-1, 1]]

    inner = v[(v[:, 0] > x0) & (v[:, 0] < x1)]
    return np.vstack([[at(x0)], inner.reshape(-1, 2), [at(x1)]])


def _nearest_xy(px, py, poly):
    """Points (px, py) (1-D) -> (distance, nearest x, nearest y) on the polyline, each (k,).
    Works through the points in blocks with reused buffers (same arithmetic per point)."""
    k = px.shape[0]
    dist, nx, ny = np.empty(k), np.zeros(k), np.zeros(k)
    segs = [(ax, ay, bx - ax, by - ay) for (ax, ay), (bx, by) in zip(poly[:-1].tolist(), poly[1:].tolist())]
    segs = [(ax, ay, dx, dy, dx * dx + dy * dy) for ax, ay, dx, dy in segs]
    m = min(k, _BLOCK)
    best, u, fx, fy, d2, tmp = (np.empty(m) for _ in range(6))
    closer = np.empty(m, dtype=bool)
    for lo in range(0, k, _BLOCK):
        hi = min(k, lo + _BLOCK)
        j = hi - lo
        bx_, by_ = px[lo:hi], py[lo:hi]
        b, U, FX, FY, D2, TMP, C = best[:j], u[:j], fx[:j], fy[:j], d2[:j], tmp[:j], closer[:j]
        NX, NY = nx[lo:hi], ny[lo:hi]
        b.fill(np.inf)
        for ax, ay, dx, dy, l2 in segs:   # a handful of segments
            if l2 == 0.0:
                continue
            # u = clip(((px - ax) * dx + (py - ay) * dy) / l2, 0, 1)
            np.subtract(bx_, ax, out=U)
            U *= dx
            np.subtract(by_, ay, out=TMP)
            TMP *= dy
            U += TMP
            U /= l2
            np.clip(U, 0.0, 1.0, out=U)
            np.multiply(U, dx, out=FX)
            FX += ax
            np.multiply(U, dy, out=FY)
            FY += ay
            # d2 = (px - fx) ** 2 + (py - fy) ** 2
            np.subtract(bx_, FX, out=D2)
            np.square(D2, out=D2)
            np.subtract(by_, FY, out=TMP)
            np.square(TMP, out=TMP)
            D2 += TMP
            np.less(D2, b, out=C)
            np.copyto(b, D2, where=C)
            np.copyto(NX, FX, where=C)
            np.copyto(NY, FY, where=C)
        np.sqrt(b, out=dist[lo:hi])
    return dist, nx, ny


def _nearest_on_polyline(p, poly):
    """p (..., 2) -> (distance (...), nearest point (..., 2)) to the polyline."""
    p = np.asarray(p, dtype=float)
    shape = p.shape[:-1]
    dist, nx, ny = _nearest_xy(p[..., 0].reshape(-1), p[..., 1].reshape(-1), poly)
    return dist.reshape(shape), np.stack([nx, ny], axis=-1).reshape(shape + (2,))


def ground_arrow_centre(free_x, free_y, poly, hg):
    """Centre of the ground-force arrow per frame (n, 2): the pad-compression-weighted mean
    of the nearest ground points of the free pins (free_x, free_y, each (n, k)) that touch
    the ground (`poly` the ground polyline, `hg` the pad thickness); frames with no pin
    touching use the ground point under the lowest pin."""
    n, k = free_y.shape
    # only pins below the highest ground point + h_g can touch: compute those alone
    low = free_y < float(poly[:, 1].max()) + hg
    flat = np.flatnonzero(low)
    fi = flat // k if k else flat
    pi = flat - fi * k
    sel_x, sel_y = free_x[fi, pi], free_y[fi, pi]
    dist, near_x, near_y = _nearest_xy(sel_x, sel_y, poly)
    w = np.maximum(hg - dist, 0.0)
    wsum = np.bincount(fi, weights=w, minlength=n)
    cx = np.bincount(fi, weights=w * near_x, minlength=n)
    cy = np.bincount(fi, weights=w * near_y, minlength=n)
    touching = wsum > 0.0
    safe = np.where(touching, wsum, 1.0)
    centre = np.stack([cx / safe, cy / safe], axis=-1)
    # no pin touching (the track airborne, or only on a corner): the arrow (then about zero)
    # sits below the track's lowest pin, on the ground (computed for those frames only)
    rows = np.flatnonzero(~touching)
    if len(rows):
        lowest = np.argmin(free_y[rows], axis=1)
        _, ux, uy = _nearest_xy(free_x[rows, lowest], free_y[rows, lowest], poly)
        centre[rows, 0] = ux
        centre[rows, 1] = uy
    return centre


def hull_body(ds):
    """The chassis outline in the chassis frame: (bx, by), 5 corners each (closed)."""
    ends = np.asarray(attr_json(ds, "track_ends"), float)
    front, rear = float(np.max(ends[:, 0])), float(np.min(ends[:, 0]))
    bx = np.array(
        [rear - HULL_MARGIN, front + HULL_MARGIN, front + HULL_MARGIN, rear - HULL_MARGIN, rear - HULL_MARGIN]
    )
    by = np.array([HULL_BOTTOM, HULL_BOTTOM, HULL_TOP, HULL_TOP, HULL_BOTTOM])
    return bx, by


def side_view(ds, idx=None):
    """Geometry of the frames `idx` (default: all) as numpy arrays (n = len(idx)).

    Returns a dict: time (n,), chassis (n, 5, 2) closed outline, pivots and wheels
    (n, nw, 2), pins (n, np, 2), links (n, nl, 2, 2) the two ends of each link, tension
    (n, nl), wheel_force (n, nw, 2), wheel_arrow_origin / wheel_arrow_vector (n, nw, 2),
    ground_arrow_origin / ground_arrow_vector (n, 2); arrow vectors in m (FORCE_SCALE
    applied). A closed-layout run adds sprocket, idler, guide and rollers (closed_parts)."""
    if idx is None:
        idx = np.arange(ds.sizes["time"])
    idx = np.asarray(idx)

    full = len(idx) == ds.sizes["time"] and np.array_equal(idx, np.arange(len(idx)))

    def take(name):
        v = np.asarray(ds.variables[name].values)
        return v if full else v[idx]

    x, y, th = take("chassis_x"), take("chassis_y"), take("chassis_pitch")
    c, s = np.cos(th), np.sin(th)
    bx, by = hull_body(ds)
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
    reach = (wheel_radii(ds) + float(ds.attrs["pad_wheel"]))[:, None]
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
    closed = is_closed(ds)
    out["links"] = link_ends(pins, closed)
    if closed:
        lay = closed_layout(ds)
        out.update(closed_parts(lay, sprocket_outline(lay), x, y, th, take("sprocket_angle"),
                                take("idler_x"), take("idler_y")))
    # ground force at the pad-compression-weighted centre of the free pins' ground contacts
    free = free_pins(pins, closed)
    centre = ground_arrow_centre(
        free[..., 0], free[..., 1], ground_polyline(ds), float(ds.attrs["pad_ground"])
    )
    g = np.stack([take("ground_force_x"), take("ground_force_y")], axis=-1) * FORCE_SCALE
    out["ground_arrow_origin"] = centre - g
    out["ground_arrow_vector"] = g
    return out


# ------------------------------------------------------------------------- soft soil ----


