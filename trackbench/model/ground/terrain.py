"""Rigid ground: a polyline with x non-decreasing, its first and last segments
extended far, outward normals pointing up/out of the ground, convex corners found
where the polyline turns clockwise (docs/model.md, "Contacts")."""

from dataclasses import dataclass

import numpy as np

FAR = 1000.0  # m: the first and last segments reach x = -FAR and +FAR


@dataclass(frozen=True)
class Ground:
    vertices: np.ndarray   # (n, 2), x non-decreasing, first x = -FAR, last x = +FAR
    segments: np.ndarray   # (n-1, 7): x0, y0, tx, ty, length, nx, ny
    corners: np.ndarray    # (m, 2) convex corners


def _straight_through(verts):
    """Vertices without those the polyline runs straight through: a user's polyline that
    starts its flat ground at x = 0 would otherwise put the resting track on two segments,
    and the second counts as an obstacle (its first contact reported at t = 0)."""
    d = np.diff(verts, axis=0)
    cross = d[:-1, 0] * d[1:, 1] - d[:-1, 1] * d[1:, 0]
    dot = d[:-1, 0] * d[1:, 0] + d[:-1, 1] * d[1:, 1]
    keep = np.ones(len(verts), bool)
    keep[1:-1] = ~((cross == 0.0) & (dot > 0.0))
    return verts[keep]


def ground_from_points(points, merge_straight=False):
    """Build a Ground from interior points; extends the ends horizontally to +-FAR;
    merge_straight: one segment where consecutive ones run on in the same direction."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    left = [-FAR, pts[0, 1]] if pts[0, 0] > -FAR else None
    right = [FAR, pts[-1, 1]] if pts[-1, 0] < FAR else None
    verts = np.array(([left] if left else []) + pts.tolist() + ([right] if right else []))
    # drop repeated points so every segment has a direction
    keep = np.ones(len(verts), bool)
    keep[1:] = np.any(np.diff(verts, axis=0) != 0.0, axis=1)
    verts = verts[keep]
    if merge_straight:
        verts = _straight_through(verts)
    d = np.diff(verts, axis=0)
    length = fm.vhypot(d[:, 0], d[:, 1])
    t = d / length[:, None]
    n = np.column_stack([-t[:, 1], t[:, 0]])
    seg = np.column_stack([verts[:-1], t, length, n])
    cross = t[:-1, 0] * t[1:, 1] - t[:-1, 1] * t[1:, 0]
    corners = verts[1:-1][cross < 0.0]
    return Ground(verts, np.ascontiguousarray(seg), np.ascontiguousarray(corners.reshape(-1, 2)))


HALFROUND_CHORDS = 36   # a half-round as a polygon of chords of 5 deg, its vertices on the circle


def halfround_points(x, radius):
    """A half-round of ``radius`` (a half-cylinder lying across the path, NG-NRMM's obstacle)
    whose front foot is at x: HALFROUND_CHORDS chords, the feet exactly on the base line."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    angle = np.pi - np.arange(HALFROUND_CHORDS + 1) * (np.pi / HALFROUND_CHORDS)
    px = x + radius + radius * fm.vcos(angle)
    py = radius * fm.vsin(angle)
    px[0], py[0], px[-1], py[-1] = x, 0.0, x + 2.0 * radius, 0.0
    return np.column_stack([px, py]).tolist()


def obstacle_points(kind, x, height, length=0.0):
    """Interior vertices of one obstacle starting at x on the base line y = 0 (a half-round:
    height is its radius)."""
    if kind == "step":
        return [[x, 0.0], [x, height]]
    if kind == "ramp":
        return [[x, 0.0], [x + length, height]]
    if kind == "block":
        return [[x, 0.0], [x, height], [x + length, height], [x + length, 0.0]]
    if kind == "bump":  # a trapezoid with 45 deg flanks and a flat top of `length`
        return [[x, 0.0], [x + height, height], [x + height + length, height],
                [x + 2 * height + length, 0.0]]
    if kind == "halfround":
        return halfround_points(x, height)
    raise ValueError(kind)


def flat_ground():
    return ground_from_points([[-FAR, 0.0], [FAR, 0.0]])


def contact_x(eq, height, pad_ground):
    """x* of docs/model.md ("Terrain and obstacle placement"): the largest x at which the
    resting track's ground-side surface (links offset by h_g along the outer normal, circles
    of radius h_g at pins bent convex towards the ground) is at the given height."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    a = eq.info["pins"]
    best = -np.inf
    t = np.diff(a, axis=0)
    t /= fm.vhypot(t[:, 0], t[:, 1])[:, None]
    n_out = np.column_stack([-t[:, 1], t[:, 0]])  # -n_inner
    for b in range(len(t)):
        p0 = a[b] + pad_ground * n_out[b]
        p1 = a[b + 1] + pad_ground * n_out[b]
        lo, hi = sorted((p0[1], p1[1]))
        if lo <= height <= hi and p1[1] != p0[1]:
            u = (height - p0[1]) / (p1[1] - p0[1])
            best = max(best, p0[0] + u * (p1[0] - p0[0]))
    for b in range(1, len(a) - 1):
        if t[b - 1, 0] * t[b, 1] - t[b - 1, 1] * t[b, 0] < 0.0:  # convex towards the ground
            dy = height - a[b, 1]
            if abs(dy) <= pad_ground:
                best = max(best, a[b, 0] + np.sqrt(pad_ground * pad_ground - dy * dy))
    if not np.isfinite(best):
        raise ValueError(
            f"the resting track never reaches height {height} m: the obstacle cannot be placed by "
            "first_contact_time; give terrain.position instead"
        )
    return float(best)


def _check_ahead(x, ob, eq, pad_ground):
    """The first obstacle must start ahead of the resting track: where its first corner's
    height (a step's or a block's top, a ramp's or a bump's foot) meets the track's ground-side
    surface. Behind that, it stands in the track at t = 0."""
    h = ob["height"] if ob["kind"] in ("step", "block") else 0.0
    try:
        front = contact_x(eq, h, pad_ground)
    except ValueError:       # taller than the track's front: its foremost point
        front = float(eq.info["pins"][:, 0].max()) + pad_ground
    if x < front:
        raise ValueError(
            f"terrain.position = {x:.4g} m puts the {ob['kind']} under the resting track (its ground "
            f"side reaches x = {front:.4g} m at height {h:g} m): place it further ahead"
            + (", or by first_contact_time" if ob["kind"] in ("step", "block") else "")
        )


STANDING_FLATNESS = 1e-6  # m: how flat a rough ground must be where the vehicle stands at the start


def rough_points(t):
    """(x, height) of a random or measured profile (model/ground/rough.py), x as given."""
    from . import rough

    if t["kind"] == "profile":
        return rough.read_profile_csv(t["file"])
    return rough.random_profile(
        t["length"], t["seed"], t.get("roughness_class"), rough.rms_of(t), wavelength_min=t["wavelength_min"],
        wavelength_max=t["wavelength_max"], dx=rough.SPACING, run_in=t["run_in"], blend=rough.BLEND,
    )


def _standing(x, h, eq, pad_ground):
    """The profile's heights relative to the ground under the resting track (which the
    equilibrium puts at y = 0), once it is flat there: from the track's rearmost to its
    foremost pin, pad included (the profile's first and last heights run on beyond its ends)."""
    pins = eq.info["pins"]
    lo, hi = float(pins[:, 0].min()) - pad_ground, float(pins[:, 0].max()) + pad_ground
    inside = (x > lo) & (x < hi)
    under = np.concatenate([np.interp([lo, hi], x, h), h[inside]])
    spread = float(under.max() - under.min())
    if spread > STANDING_FLATNESS:
        raise ValueError(
            f"terrain: the vehicle cannot stand on the ground at the start: it is not flat under the "
            f"resting track (x = {lo:.3g} .. {hi:.3g} m, heights vary by {spread:.3g} m); allowed: flat "
            f"within {STANDING_FLATNESS:g} m there (a flat run-in)"
        )
    return h - under[0]


def _check_reached(scenario, eq):
    """A random ground's rough section must come under the track before the run ends: a run
    that never leaves the run-in measures flat ground (its ride metrics near zero)."""
    front = float(eq.info["pins"][:, 0].max()) + scenario["track.pad_ground"]
    travel = scenario["speed"] * scenario["duration"]
    run_in = scenario["terrain"]["run_in"]
    if front + travel <= run_in:
        raise ValueError(
            f"terrain.run_in = {run_in:g} m: the run ends before the track reaches the rough ground "
            f"(its front at x = {front:.3g} m travels speed x duration = {travel:.3g} m); allowed: "
            f"run_in below {front + travel:.3g} m, or a longer duration or a higher speed"
        )


def _check_memory_laws(scenario, ground):
    """The laws that need the approach speed (the laws by restitution) remember a pin's per
    ground segment, which a candidate row holds for at most SEGMENT_CANDIDATES segments
    (model/core/indices.py)."""
    from ..contact.laws import DAMPING_LAWS
    from ..core.indices import SEGMENT_CANDIDATES

    damping = scenario["contact.damping"]
    n = ground.segments.shape[0]
    if DAMPING_LAWS[damping].needs_approach_speed and n > SEGMENT_CANDIDATES:
        allowed = ", ".join(repr(name) for name in DAMPING_LAWS.names(needs_approach_speed=False))
        raise ValueError(
            f"contact.damping = {damping!r} cannot run on this ground of {n} segments: it remembers "
            f"a contact's approach speed per ground segment, up to {SEGMENT_CANDIDATES}; allowed on "
            f"rough ground: contact.damping = {allowed} (the damped preset's is 'viscous')"
        )


def build_ground(scenario, eq):
    """Terrain polyline of the scenario, with obstacles placed by time resolved."""
    t = scenario["terrain"]
    if t["kind"] == "flat":
        return ground_from_points([[-FAR, 0.0], [FAR, 0.0]]), {}
    if t["kind"] == "points":
        return ground_from_points(t["points"], merge_straight=True), {}
    if t["kind"] in ("random", "profile"):
        if t["kind"] == "random":
            _check_reached(scenario, eq)
        x, h = rough_points(t)
        h = _standing(x, h, eq, scenario["track.pad_ground"])
        ground = ground_from_points(np.column_stack([x, h]), merge_straight=True)
        _check_memory_laws(scenario, ground)
        return ground, {}
    obstacles = t["obstacles"] if t["kind"] == "sequence" else [t]
    pts = [[-FAR, 0.0]]
    level = 0.0
    x_end = -FAR
    resolved = {}
    for i, ob in enumerate(obstacles):
        if "first_contact_time" in ob:
            x = (
                contact_x(eq, ob["height"], scenario["track.pad_ground"])
                + scenario["speed"] * ob["first_contact_time"]
            )
            resolved[f"obstacle_{i}_position"] = x
        elif "gap" in ob:
            x = x_end + ob["gap"]
        else:
            x = ob["position"]
        if i == 0 and "first_contact_time" not in ob:
            _check_ahead(x, ob, eq, scenario["track.pad_ground"])
        if x < x_end:
            raise ValueError(f"terrain obstacle {i} starts at x = {x:.4g} m, before the previous one ends "
                             f"({x_end:.4g} m)")
        new = [
            [px, py + level]
            for px, py in obstacle_points(ob["kind"], x, ob.get("height", ob.get("radius")),
                                          ob.get("length", 0.0))
        ]
        pts += new
        x_end = new[-1][0]
        if ob["kind"] in ("step", "ramp"):
            level += ob["height"]
    pts.append([FAR, level])
    return ground_from_points(pts), resolved
