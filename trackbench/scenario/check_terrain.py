"""Terrain checks: the terrain table's shape by kind (flat, one obstacle, points, a
sequence of obstacles), each obstacle's placement, and terrain.soil."""

import numpy as np

from . import ScenarioError
from .check_values import check_value
from .parameters_table import (
    OBSTACLE_KEYS,
    OBSTACLE_KIND_RULE,
    PAPER_FIRST_CONTACT_TIME,
    RANDOM_DEFAULTS,
    TERRAIN_KEYS,
    TERRAIN_OPEN_LOW,
    TERRAIN_RULES,
)


def validate_terrain(t):
    """The terrain table: its shape (_terrain_shape) and, on any shape, terrain.soil."""
    soil = t.get("soil", "rigid")
    out = _terrain_shape({k: v for k, v in t.items() if k != "soil"})
    if soil != "rigid":
        from ..model.ground.soil import resolve_soil

        try:
            resolve_soil(soil)
        except ValueError as e:
            raise ScenarioError(str(e)) from None
        out["soil"] = soil
    return out


def _terrain_shape(t):
    kind = check_value("terrain.kind", t.get("kind"), TERRAIN_RULES["kind"])
    if kind == "flat":
        extra = set(t) - {"kind"}
        if extra:
            raise ScenarioError(f"terrain.{sorted(extra)[0]} does not apply to flat ground")
        return {"kind": "flat"}
    if kind == "points":
        return _points(t)
    if kind == "sequence":
        return _sequence(t)
    if kind in ("random", "profile"):
        return _rough(t, kind)
    return _validate_obstacle(t, "terrain", True)


def _rough(t, kind):
    """A random profile (its arguments checked, the profile made when the run starts) or a
    measured one (its file read now, so that a missing or malformed file stops before any
    work): model/ground/rough.py."""
    from ..model.ground import rough

    allowed = TERRAIN_KEYS[kind]
    out = {"kind": kind, **(RANDOM_DEFAULTS if kind == "random" else {})}
    out.update(_checked_keys(t, "terrain", f"kind '{kind}'", allowed))
    if "rms_in" in out and "wavelength_max" not in t:   # NRMM's RMS: its band ends at 60 ft
        out["wavelength_max"] = rough.NRMM_WAVELENGTH_MAX
    try:
        if kind == "profile":
            if "file" not in out:
                raise ValueError("terrain.file is missing: a profile needs its CSV file of x, height (m)")
            rough.read_profile_csv(out["file"])
        elif out["wavelength_min"] < 4 * rough.SPACING:
            raise ValueError(
                f"terrain.wavelength_min = {out['wavelength_min']!r} m is not allowed: expected at least "
                f"{4 * rough.SPACING:g} m (the profile is sampled every {rough.SPACING:g} m)"
            )
        else:
            rough.check_random(out["length"], out["seed"], out.get("roughness_class"), rough.rms_of(out),
                               out["wavelength_min"], out["wavelength_max"], rough.SPACING, out["run_in"],
                               rough.BLEND)
    except ValueError as e:
        text = str(e)
        if text.split(" ")[0] in allowed:
            text = "terrain." + text
        elif text.startswith("profile"):
            text = "terrain.file: " + text
        elif not text.startswith("terrain."):
            text = "terrain: " + text
        raise ScenarioError(text) from None
    return out


def _points(t):
    for k in t:
        if k not in ("kind", "points"):
            raise ScenarioError(
                f"terrain.{k} does not apply to kind 'points'; give terrain.points = [[x, y], ...]"
            )
    pts = t.get("points")
    try:
        arr = np.asarray(pts, dtype=float)
    except (TypeError, ValueError):
        arr = np.zeros((0, 3))  # fails the shape check below
    if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 2 or not np.all(np.isfinite(arr)):
        raise ScenarioError("terrain.points must be a list of at least two [x, y] pairs of finite numbers")
    if np.any(np.diff(arr[:, 0]) < 0):
        i = int(np.nonzero(np.diff(arr[:, 0]) < 0)[0][0]) + 1
        raise ScenarioError(
            f"terrain.points[{i}] has x = {arr[i, 0]} < the previous x: x must be non-decreasing"
        )
    if np.any(np.abs(arr) > 900):
        raise ScenarioError("terrain.points must lie within |x|, |y| <= 900 m")
    return {"kind": "points", "points": arr.tolist()}


def _sequence(t):
    obs = t.get("obstacles")
    extra = set(t) - {"kind", "obstacles"}
    if extra:
        raise ScenarioError(
            f"terrain.{sorted(extra)[0]} does not apply to a sequence; put it into terrain.obstacles"
        )
    if not isinstance(obs, list) or not obs:
        raise ScenarioError("terrain.obstacles must be a non-empty list of obstacle tables")
    return {
        "kind": "sequence",
        "obstacles": [_validate_obstacle(o, f"terrain.obstacles[{i}]", i == 0) for i, o in enumerate(obs)],
    }


def _checked_keys(table, where, what, allowed):
    """A terrain or obstacle table's keys but its kind, each allowed for it (what: "a step",
    "kind 'random'") and its value checked against TERRAIN_RULES."""
    out = {}
    for k, v in table.items():
        if k == "kind":
            continue
        if k not in allowed:
            raise ScenarioError(
                f"{where}.{k} does not apply to {what}; allowed: {', '.join(sorted(allowed))}"
            )
        out[k] = check_value(f"{where}.{k}", v, TERRAIN_RULES[k], open_low=k in TERRAIN_OPEN_LOW)
    return out


def _validate_obstacle(ob, where, first):
    """One obstacle: the whole terrain (where == 'terrain') or one of a sequence."""
    if not isinstance(ob, dict):
        raise ScenarioError(f'{where} must be a table like {{kind = "step", height = 0.1, position = 5.0}}')
    kind = check_value(where + ".kind", ob.get("kind"), OBSTACLE_KIND_RULE)
    allowed = OBSTACLE_KEYS[kind] if where != "terrain" else TERRAIN_KEYS[kind]
    out = {"kind": kind, **_checked_keys(ob, where, f"a {kind}", allowed)}
    needs = ("radius",) if kind == "halfround" else ("height",) + (("length",) if kind != "step" else ())
    for need in needs:
        if need not in out:
            raise ScenarioError(f"{where}.{need} is missing: a {kind} needs {need}")
    _check_placement(out, where, first, allowed)
    return out


def _check_placement(out, where, first, allowed):
    """Exactly one of position, gap, first_contact_time; the first obstacle placed absolutely
    (by the paper's time if it can be and nothing is given), the others by position or gap."""
    kind = out["kind"]
    placed = [k for k in ("position", "gap", "first_contact_time") if k in out]
    if len(placed) > 1:
        raise ScenarioError(f"{where}: give only one of {', '.join(placed)}")
    if not placed:
        if first and "first_contact_time" in allowed:
            out["first_contact_time"] = PAPER_FIRST_CONTACT_TIME
        elif first:
            raise ScenarioError(f"{where}.position is missing: a {kind} needs the x of its start")
        else:
            raise ScenarioError(f"{where}: give position or gap")
    if not first and "first_contact_time" in out:
        raise ScenarioError(f"{where}.first_contact_time: only the first obstacle can be placed by time")
    if first and "gap" in out:
        raise ScenarioError(f"{where}.gap: the first obstacle needs position or first_contact_time")


def check_placed_by_time(out):
    """An obstacle placed by first_contact_time stands speed x time ahead of the resting track:
    at speed 0 it would stand against the track at t = 0, whatever time was asked."""
    t = out["terrain"]
    first = t["obstacles"][0] if t["kind"] == "sequence" else t
    if out["speed"] == 0.0 and first.get("first_contact_time", 0.0) > 0.0:
        raise ScenarioError(
            f"terrain.first_contact_time = {first['first_contact_time']} s needs speed > 0 (the "
            "obstacle is placed speed x time ahead of the track); at speed 0 give terrain.position "
            "(m) or a flat terrain"
        )
