"""What one run is: vehicle + track + terrain + run settings, validated before anything runs.

A scenario is a nested dict with dotted names (``speed``, ``vehicle.chassis_mass``,
``terrain.height``); ``Scenario.from_dict`` fills every missing value from the
paper's run and raises ``ScenarioError`` (one line, naming the parameter and what is
allowed) on anything wrong.
"""

import copy
import difflib
import math
from dataclasses import dataclass

import numpy as np

from .model.contact_laws import DAMPINGS, FRICTION_LAWS, GEOMETRIES, LAWS

from .model.layout import DRIVES
from .model.parameters import GRAVITY, closed_defaults, paper_contact, paper_track, paper_vehicle, wheel_centres_body
from .presets import PRESETS, preset_values

SOLVERS = ("reduced", "lee")
METHODS = ("dop853", "dopri5")
TERRAIN_KINDS = ("flat", "step", "ramp", "block", "bump", "points", "sequence")
OBSTACLE_KINDS = ("step", "ramp", "block", "bump")
PLACEMENT_KEYS = ("position", "first_contact_time", "gap")   # where an obstacle stands: one of them


class ScenarioError(ValueError):
    """Bad scenario input; the message is one line naming the culprit."""


def paper_step():
    """The paper's run: 10 m/s over a 0.1 m step first touched at t = 0.0568 s."""
    return {
        "name": "paper_step",
        "preset": "paper",
        "speed": 10.0,
        "duration": 0.5,
        "gravity": GRAVITY,
        "solver": "reduced",
        "method": "dopri5",
        "tolerance": 1e-9,
        "output_interval": 1e-4,
        "max_steps": 2_000_000,
        "perturbation": 0.0,     # m: seeded nudge of the free pins (study replicates)
        "seed": 0,
        "vehicle": paper_vehicle(),
        "track": paper_track(),
        "contact": paper_contact(),
        "terrain": {"kind": "step", "height": 0.1, "first_contact_time": 0.0568},
        **closed_defaults(),
        "lee": {"accel_order": 10, "eps_iterations": 10, "position_tol": 1e-9,
                "max_iterations": 500, "matrix_update_angle": 1e-3},
        "record": {"enabled": True, "every": 5},   # side-view frames: every 5th output sample
    }


# name -> (type, low, high, what is allowed). Bounds are exclusive where marked by the text.
_POS = (float, 0.0, math.inf, "a number > 0")
_NONNEG = (float, 0.0, math.inf, "a number >= 0")
RULES = {
    "name": (str, None, None, "a text"),
    "preset": (str, tuple(PRESETS), None, "one of " + ", ".join(PRESETS)),
    "speed": (float, 0.0, 100.0, "a number in [0, 100] m/s"),
    "duration": (float, 0.0, 1000.0, "a number in (0, 1000] s"),
    "gravity": (float, 0.0, 100.0, "a number in [0, 100] m/s^2"),
    "solver": (str, SOLVERS, None, "one of " + ", ".join(SOLVERS)),
    "method": (str, METHODS, None, "one of " + ", ".join(METHODS)),
    "tolerance": (float, 1e-14, 1e-3, "a number in [1e-14, 1e-3]"),
    "output_interval": _POS,
    "max_steps": (int, 1, 10**9, "an integer >= 1"),
    "perturbation": (float, 0.0, 1e-3, "a number in [0, 1e-3] m"),
    "seed": (int, 0, 2**63 - 1, "an integer >= 0"),
    "vehicle.chassis_mass": _POS,
    "vehicle.chassis_inertia": _POS,
    "vehicle.arm_mass": _POS,
    "vehicle.arm_inertia": _POS,
    "vehicle.arm_length": _POS,
    "vehicle.arm_angle": (float, 0.0, 90.0, "a number in (0, 90) deg"),
    "vehicle.torsion_stiffness": _POS,
    "vehicle.wheel_radius": _POS,
    "vehicle.n_wheels": (int, 2, 20, "an integer in [2, 20]"),
    "vehicle.first_pivot_x": (float, -math.inf, math.inf, "a finite number (m)"),
    "vehicle.pivot_y": (float, -math.inf, math.inf, "a finite number (m)"),
    "vehicle.pivot_spacing": _POS,
    "vehicle.front_track_end": (list, None, None, "a pair [x, y] of finite numbers (m)"),
    "vehicle.rear_track_end": (list, None, None, "a pair [x, y] of finite numbers (m)"),
    "track.n_links": (int, 4, 400, "an integer in [4, 400]"),
    "track.link_length": _POS,
    "track.pin_mass": _POS,
    "track.link_stiffness": _POS,
    "track.pad_wheel": _POS,
    "track.pad_ground": _POS,
    "track.wheel_stiffness": _POS,
    "track.ground_stiffness": _POS,
    "track.link_damping": (float, 0.0, math.inf, "a number >= 0 (N s/m)"),
    "vehicle.arm_damping": (list, None, None, "a list of one number >= 0 (N m s/rad) per road wheel, or []"),
    "contact.law": (str, tuple(LAWS), None, "one of " + ", ".join(LAWS)),
    "contact.exponent": (float, 0.0, 3.0, "a number in (0, 3]"),
    "contact.damping": (str, tuple(DAMPINGS), None, "one of " + ", ".join(DAMPINGS)),
    "contact.damping_ratio": (float, 0.0, 10.0, "a number in [0, 10]"),
    "contact.restitution": (float, 0.0, 1.0, "a number in (0, 1]"),
    "contact.damping_ramp": (float, 0.0, 0.1, "a number in (0, 0.1] m"),
    "contact.min_approach_speed": (float, 0.0, 100.0, "a number in (0, 100] m/s"),
    "contact.geometry": (str, tuple(GEOMETRIES), None, "one of " + ", ".join(GEOMETRIES)),
    "contact.friction": (float, 0.0, 10.0, "a number in [0, 10] (Coulomb mu; 0 = frictionless)"),
    "contact.friction_velocity": (float, 0.0, 10.0, "a number in (0, 10] m/s"),
    "contact.friction_law": (str, tuple(FRICTION_LAWS), None, "one of " + ", ".join(FRICTION_LAWS)),
    "contact.friction_stiffness": (float, 0.0, 1e12, "a number in (0, 1e12] (N/m: the bristle's tangential stiffness)"),
    "track.layout": (str, ("paper", "closed"), None, "one of paper, closed"),
    "track.tension": (float, 0.0, 1e7, "a number > 0 (N)"),
    "track.width": (float, 0.0, 10.0, "a number in (0, 10] m"),
    "sprocket.position": (str, ("rear", "front"), None, "one of rear, front"),
    "sprocket.teeth": (int, 3, 60, "an integer in [3, 60]"),
    "sprocket.pitch_radius": (float, 0.0, 10.0, "a number >= 0 (m; 0: derived from the link pitch)"),
    "sprocket.seat_radius": _POS,
    "sprocket.pin_radius": _POS,
    "sprocket.tip_radius": (float, 0.0, 10.0, "a number >= 0 (m; 0: derived)"),
    "sprocket.flank_angle": (float, 0.0, 45.0, "a number in [0, 45] deg"),
    "sprocket.stiffness": _POS,
    "sprocket.inertia": _POS,
    "idler.radius": _POS,
    "idler.mass": _POS,
    "idler.preload": (float, 0.0, 1e8, "a number >= 0 (N; 0: derived from track.tension)"),
    "idler.stiffness": _NONNEG,
    "idler.damping": _NONNEG,
    "idler.travel": _POS,
    "idler.guide_angle": (float, -60.0, 60.0, "a number in [-60, 60] deg"),
    "rollers.positions": (list, None, None, "a list of [x, y] body points (m), or []"),
    "rollers.radius": _POS,
    "drive.kind": (str, tuple(DRIVES), None, "one of " + ", ".join(DRIVES)),
    "drive.torque": (float, -1e7, 1e7, "a number in [-1e7, 1e7] N m"),
    "drive.curve": (list, None, None, "a list of [sprocket speed rad/s, torque N m] pairs, speeds increasing, or []"),
    "drive.target": (float, -100.0, 100.0, "a number in [-100, 100] m/s (default: the start speed)"),
    "drive.gain_p": _NONNEG,
    "drive.gain_i": _NONNEG,
    "drive.torque_limit": _POS,
    "drawbar.load": (float, -1e7, 1e7, "a number in [-1e7, 1e7] N (rearward positive; 0: none)"),
    "drawbar.hitch": (list, None, None, "a pair [x, y] of finite numbers (m, body point)"),
    "drawbar.slip": (float, 0.0, 0.95, "a number in [0, 0.95] (0: no towing rig)"),
    "drawbar.rig_damping": (float, 0.0, math.inf, "a number > 0 (N s/m)"),
    "lee.accel_order": (int, 1, 50, "an integer in [1, 50]"),
    "lee.eps_iterations": (int, 1, 1000, "an integer in [1, 1000]"),
    "lee.position_tol": (float, 1e-15, 1e-3, "a number in [1e-15, 1e-3] m"),
    "lee.max_iterations": (int, 1, 100000, "an integer >= 1"),
    "lee.matrix_update_angle": (float, 0.0, 1.0, "a number in [0, 1] rad (0: rebuild A_n after every step)"),
    "record.enabled": (bool, None, None, "true or false"),
    "record.every": (int, 1, 10**6, "an integer >= 1"),
}
# The unit of every parameter that has one (axis labels and titles of the figures).
UNITS = {"speed": "m/s", "duration": "s", "gravity": "m/s^2", "output_interval": "s", "perturbation": "m",
         "vehicle.chassis_mass": "kg", "vehicle.chassis_inertia": "kg m^2", "vehicle.arm_mass": "kg",
         "vehicle.arm_inertia": "kg m^2", "vehicle.arm_length": "m", "vehicle.arm_angle": "deg",
         "vehicle.torsion_stiffness": "N m/rad", "vehicle.wheel_radius": "m", "vehicle.first_pivot_x": "m",
         "vehicle.pivot_y": "m", "vehicle.pivot_spacing": "m", "vehicle.front_track_end": "m",
         "vehicle.rear_track_end": "m", "track.link_length": "m", "track.pin_mass": "kg",
         "track.link_stiffness": "N/m", "track.pad_wheel": "m", "track.pad_ground": "m",
         "track.wheel_stiffness": "N/m", "track.ground_stiffness": "N/m", "track.link_damping": "N s/m",
         "vehicle.arm_damping": "N m s/rad", "contact.damping_ramp": "m", "contact.min_approach_speed": "m/s",
         "contact.friction_velocity": "m/s", "contact.friction_stiffness": "N/m", "track.tension": "N",
         "track.width": "m", "sprocket.pitch_radius": "m", "sprocket.seat_radius": "m",
         "sprocket.pin_radius": "m", "sprocket.tip_radius": "m", "sprocket.flank_angle": "deg",
         "sprocket.stiffness": "N/m", "sprocket.inertia": "kg m^2", "idler.radius": "m",
         "idler.mass": "kg", "idler.preload": "N", "idler.stiffness": "N/m", "idler.damping": "N s/m",
         "idler.travel": "m", "idler.guide_angle": "deg", "rollers.positions": "m", "rollers.radius": "m",
         "drive.torque": "N m", "drive.target": "m/s", "drive.gain_p": "N m s/m", "drive.gain_i": "N m/m",
         "drive.torque_limit": "N m", "drawbar.load": "N", "drawbar.hitch": "m",
         "drawbar.rig_damping": "N s/m", "lee.position_tol": "m", "lee.matrix_update_angle": "rad",
         "terrain.height": "m", "terrain.length": "m", "terrain.position": "m",
         "terrain.first_contact_time": "s", "terrain.gap": "m"}

_OPEN_LOW = {"duration", "drawbar.rig_damping", "tolerance", "output_interval", "vehicle.arm_angle", "contact.exponent", "track.width",
             "contact.restitution", "contact.damping_ramp", "contact.min_approach_speed",
             "contact.friction_velocity", "contact.friction_stiffness"} | {
    k for k, r in RULES.items() if r is _POS}

TERRAIN_RULES = {
    "kind": (str, TERRAIN_KINDS, None, "one of " + ", ".join(TERRAIN_KINDS)),
    "height": (float, 0.0, 10.0, "a number in (0, 10] m"),
    "length": (float, 0.0, 1000.0, "a number in (0, 1000] m"),
    "position": (float, -900.0, 900.0, "a number in [-900, 900] m (x of the obstacle's start)"),
    "first_contact_time": (float, 0.0, 1000.0, "a number in (0, 1000] s"),
    "gap": (float, 0.0, 1000.0, "a number in [0, 1000] m"),
    "points": (list, None, None, "a list of [x, y] pairs with x non-decreasing"),
    "obstacles": (list, None, None, "a list of obstacle tables"),
    "soil": (str, None, None, "rigid, a soil name (trackbench params) or a table of soil values"),
}
_TERRAIN_KEYS = {
    "flat": set(),
    "step": {"height", "position", "first_contact_time"},
    "ramp": {"height", "length", "position"},
    "block": {"height", "length", "position", "first_contact_time"},
    "bump": {"height", "length", "position"},
    "points": {"points"},
    "sequence": {"obstacles"},
}
_OBSTACLE_KEYS = {"step": {"height", "position", "gap", "first_contact_time"},
                  "ramp": {"height", "length", "position", "gap"},
                  "block": {"height", "length", "position", "gap", "first_contact_time"},
                  "bump": {"height", "length", "position", "gap"}}


def parameter_names():
    """Every dotted name a scenario accepts (terrain keys included)."""
    return sorted(RULES) + sorted("terrain." + k for k in TERRAIN_RULES)


def _unknown(name, valid):
    close = difflib.get_close_matches(name, valid, n=3, cutoff=0.5)
    hint = f"; did you mean {', '.join(close)}?" if close else "; see `trackbench params` for the list"
    return ScenarioError(f"unknown parameter '{name}'{hint}")


def _check_value(name, value, rule, open_low=False):
    typ, lo, hi, allowed = rule
    bad = ScenarioError(f"{name} = {value!r} is not allowed: expected {allowed}")
    if typ is bool:
        if not isinstance(value, bool):
            raise bad
        return value
    if typ is str:
        if not isinstance(value, str) or (lo is not None and value not in lo):
            raise bad
        return value
    if typ is list:
        if not isinstance(value, (list, tuple)):
            raise bad
        return [list(v) if isinstance(v, (list, tuple)) else v for v in value]
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise bad
    if typ is int:
        if float(value) != int(value):
            raise bad
        value = int(value)
    else:
        value = float(value)
    if not math.isfinite(value) and not (math.isinf(value) and math.isinf(hi)):
        raise bad
    if not (lo <= value <= hi) or (open_low and value <= lo):
        raise bad
    return value


def set_dotted(d, name, value):
    """Set d['a']['b'] for name 'a.b', creating tables on the way."""
    parts = name.split(".")
    for p in parts[:-1]:
        d = d.setdefault(p, {})
    d[parts[-1]] = value


def flatten(d, prefix=""):
    out = {}
    for k, v in d.items():
        if isinstance(v, dict) and not (prefix + k).startswith("terrain"):
            out.update(flatten(v, prefix + k + "."))
        else:
            out[prefix + k] = v
    return out


def _merge(base, over, prefix=""):
    for k, v in over.items():
        name = prefix + k
        if k not in base and not name.startswith("terrain"):
            raise _unknown(name, parameter_names())
        if name == "terrain":
            if not isinstance(v, dict):
                raise ScenarioError("terrain must be a table, e.g. {kind = \"step\", height = 0.1}")
            if "kind" in v and v["kind"] != base["terrain"].get("kind"):
                base["terrain"] = {}  # a new kind starts from nothing
            if any(p in v for p in PLACEMENT_KEYS):
                for p in PLACEMENT_KEYS:  # the user's placement replaces the default's
                    base["terrain"].pop(p, None)
            base["terrain"].update(copy.deepcopy(v))
        elif isinstance(base.get(k), dict):
            if not isinstance(v, dict):
                raise ScenarioError(f"{name} is a group of parameters, not a value; set e.g. {name}.{next(iter(base[k]))}")
            _merge(base[k], v, name + ".")
        else:
            base[k] = copy.deepcopy(v)


def _validate_obstacle(ob, where, first):
    if not isinstance(ob, dict):
        raise ScenarioError(f"{where} must be a table like {{kind = \"step\", height = 0.1, position = 5.0}}")
    kind = _check_value(where + ".kind", ob.get("kind"), (str, OBSTACLE_KINDS, None,
                        "one of " + ", ".join(OBSTACLE_KINDS)))
    allowed = _OBSTACLE_KEYS[kind] if where != "terrain" else _TERRAIN_KEYS[kind]
    out = {"kind": kind}
    for k, v in ob.items():
        if k == "kind":
            continue
        if k not in allowed:
            raise ScenarioError(f"{where}.{k} does not apply to a {kind}; allowed: {', '.join(sorted(allowed))}")
        out[k] = _check_value(f"{where}.{k}", v, TERRAIN_RULES[k],
                              open_low=k in ("height", "length", "first_contact_time"))
    for need in ("height",) + (("length",) if kind != "step" else ()):
        if need not in out:
            raise ScenarioError(f"{where}.{need} is missing: a {kind} needs {need}")
    placed = [k for k in ("position", "gap", "first_contact_time") if k in out]
    if len(placed) > 1:
        raise ScenarioError(f"{where}: give only one of {', '.join(placed)}")
    if not placed:
        if first and "first_contact_time" in allowed:
            out["first_contact_time"] = 0.0568
        elif first:
            raise ScenarioError(f"{where}.position is missing: a {kind} needs the x of its start")
        else:
            raise ScenarioError(f"{where}: give position or gap")
    if not first and "first_contact_time" in out:
        raise ScenarioError(f"{where}.first_contact_time: only the first obstacle can be placed by time")
    if first and "gap" in out:
        raise ScenarioError(f"{where}.gap: the first obstacle needs position or first_contact_time")
    return out


def validate_terrain(t):
    """The terrain table: its shape (_terrain_shape) and, on any shape, terrain.soil."""
    soil = t.get("soil", "rigid")
    out = _terrain_shape({k: v for k, v in t.items() if k != "soil"})
    if soil != "rigid":
        from .model.soil import resolve_soil
        try:
            resolve_soil(soil)
        except ValueError as e:
            raise ScenarioError(str(e)) from None
        out["soil"] = soil
    return out


def _terrain_shape(t):
    kind = _check_value("terrain.kind", t.get("kind"), TERRAIN_RULES["kind"])
    if kind == "flat":
        extra = set(t) - {"kind"}
        if extra:
            raise ScenarioError(f"terrain.{sorted(extra)[0]} does not apply to flat ground")
        return {"kind": "flat"}
    if kind == "points":
        for k in t:
            if k not in ("kind", "points"):
                raise ScenarioError(f"terrain.{k} does not apply to kind 'points'; give terrain.points = [[x, y], ...]")
        pts = t.get("points")
        try:
            arr = np.asarray(pts, dtype=float)
        except (TypeError, ValueError):
            arr = np.zeros((0, 3))
        if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) < 2 or not np.all(np.isfinite(arr)):
            raise ScenarioError("terrain.points must be a list of at least two [x, y] pairs of finite numbers")
        if np.any(np.diff(arr[:, 0]) < 0):
            i = int(np.nonzero(np.diff(arr[:, 0]) < 0)[0][0]) + 1
            raise ScenarioError(f"terrain.points[{i}] has x = {arr[i, 0]} < the previous x: x must be non-decreasing")
        if np.any(np.abs(arr) > 900):
            raise ScenarioError("terrain.points must lie within |x|, |y| <= 900 m")
        return {"kind": "points", "points": arr.tolist()}
    if kind == "sequence":
        obs = t.get("obstacles")
        extra = set(t) - {"kind", "obstacles"}
        if extra:
            raise ScenarioError(f"terrain.{sorted(extra)[0]} does not apply to a sequence; put it into terrain.obstacles")
        if not isinstance(obs, list) or not obs:
            raise ScenarioError("terrain.obstacles must be a non-empty list of obstacle tables")
        return {"kind": "sequence", "obstacles": [
            _validate_obstacle(o, f"terrain.obstacles[{i}]", i == 0) for i, o in enumerate(obs)]}
    return _validate_obstacle(t, "terrain", True)


def _check_geometry(v, tr):
    """Does the track fit the wheels? Cheap checks on the equilibrium configuration (the
    closed layout's own: _check_closed)."""
    from .model.track_path import initial_track
    wc = wheel_centres_body(v)
    r = v["wheel_radius"]
    rho = r + tr["pad_wheel"]
    if v["n_wheels"] > 1 and v["pivot_spacing"] <= 2 * r:
        raise ScenarioError(f"vehicle.pivot_spacing = {v['pivot_spacing']} m makes neighbouring road wheels overlap: "
                            f"it must exceed 2 * wheel_radius = {2 * r} m")
    for key in ("front_track_end", "rear_track_end"):
        e = v[key]
        if len(e) != 2 or not all(isinstance(x, (int, float)) and math.isfinite(x) for x in e):
            raise ScenarioError(f"vehicle.{key} must be a pair [x, y] of finite numbers (m)")
    ends = np.array([v["front_track_end"], v["rear_track_end"]], float)
    if not (ends[0, 0] > wc[:, 0].max() + rho and ends[1, 0] < wc[:, 0].min() - rho):
        raise ScenarioError("vehicle.front_track_end / rear_track_end must lie ahead of the first and behind the "
                            "last road wheel (wheel radius and pad included)")
    if np.any(ends[:, 1] <= wc[:, 1].min() - rho + tr["pad_ground"]):
        raise ScenarioError("vehicle.front_track_end / rear_track_end must lie above the bottom of the road wheels")
    if tr["link_length"] <= 2 * tr["pad_ground"]:
        raise ScenarioError("track.link_length must exceed 2 * track.pad_ground")
    if tr["layout"] == "closed":
        return
    _, path, _ = initial_track(ends, wc, rho, tr["n_links"])
    free = tr["n_links"] * tr["link_length"]
    strain = path / free - 1.0
    if strain <= 0.0:
        raise ScenarioError(f"the track is too long for the wheels: n_links * link_length = {free:.4g} m but the path "
                            f"around the wheels is {path:.4g} m; allowed: a total link length below {path:.4g} m")
    if strain > 0.1:
        raise ScenarioError(f"the track is too short for the wheels: the links would stretch {100 * strain:.3g} % "
                            f"(n_links * link_length = {free:.4g} m, path {path:.4g} m); allowed: at most 10 %")


_CLOSED_GROUPS = ("sprocket", "idler", "rollers", "drive", "drawbar")


def _pairs(name, value, increasing=False, limit=None):
    arr = np.asarray(value, dtype=float) if value else np.zeros((0, 2))
    if arr.ndim != 2 or arr.shape[1] != 2 or not np.all(np.isfinite(arr)):
        raise ScenarioError(f"{name} must be a list of [a, b] pairs of finite numbers, or []")
    if increasing and np.any(np.diff(arr[:, 0]) <= 0):
        raise ScenarioError(f"{name}: the speeds must increase from pair to pair")
    if limit is not None and len(arr) > limit:
        raise ScenarioError(f"{name} has {len(arr)} pairs; allowed: at most {limit}")
    return arr.tolist()


def _check_drawbar(out):
    hitch = out["drawbar"]["hitch"]
    if len(hitch) != 2 or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
                                  for x in hitch):
        raise ScenarioError(f"drawbar.hitch = {hitch!r} is not allowed: expected a pair [x, y] of finite numbers "
                            "(m, body point)")
    out["drawbar"]["hitch"] = [float(x) for x in hitch]
    if out["drawbar"]["slip"] > 0.0 and out["drive"]["kind"] != "speed":
        raise ScenarioError(f"drawbar.slip = {out['drawbar']['slip']} needs drive.kind = 'speed' (the drive holds "
                            f"the sprocket at the rig's slip), not '{out['drive']['kind']}'")


def _check_closed(out, explicit):
    """The closed layout: what it supports, its geometry (model/closed.py), and the values
    it derives written into the scenario unless given."""
    if out["track"]["layout"] != "closed":
        # a closed-track value set to anything but its default on the paper's layout (a
        # resolved scenario counts every value as given)
        defaults = flatten({**closed_defaults(), "track": {"tension": paper_track()["tension"]}})
        flat = flatten({k: out[k] for k in (*_CLOSED_GROUPS, "track")})
        given = sorted(k for k in explicit if k in defaults and flat[k] != defaults[k])
        if given:
            raise ScenarioError(f"{given[0]} applies to the closed track only; set track.layout = 'closed'")
        return
    from .model.closed import ClosedLayoutError, closed_geometry
    from .model.layout import LP_CURVE_POINTS
    if out["solver"] == "lee":
        raise ScenarioError("solver = 'lee' runs the paper's track layout only; use solver = 'reduced' with "
                            "track.layout = 'closed'")
    if out["contact"]["damping"] not in ("none", "viscous"):
        raise ScenarioError(f"contact.damping = '{out['contact']['damping']}' does not apply to the closed track's "
                            "sprocket teeth; allowed with track.layout = 'closed': none, viscous")
    out["rollers"]["positions"] = _pairs("rollers.positions", out["rollers"]["positions"])
    out["drive"]["curve"] = _pairs("drive.curve", out["drive"]["curve"], True, LP_CURVE_POINTS)
    if out["drive"]["kind"] == "torque" and "drive.torque" not in explicit and not out["drive"]["curve"]:
        raise ScenarioError("drive.kind = 'torque' needs drive.torque (N m) or drive.curve")
    _check_drawbar(out)
    try:
        g = closed_geometry(out["vehicle"], out["track"], out["sprocket"], out["idler"], out["rollers"],
                            frozenset(explicit))
    except ClosedLayoutError as e:
        raise ScenarioError(str(e)) from None
    # the speed drive holds the start speed; the contact geometry without force jumps: the
    # rolling loop crosses the paper's switches at the pin-passing frequency, and at a
    # switch a static equilibrium may not exist (docs/model.md)
    resolved = {**g.resolved(), "drive.target": out["speed"], "contact.geometry": "continuous"}
    for name, value in resolved.items():
        if name not in explicit:
            set_dotted(out, name, value)


def _dotted_keys(d, prefix=""):
    """The dotted parameter names set in a (possibly nested) overrides dict."""
    out = set()
    for k, v in d.items():
        name = prefix + k
        if isinstance(v, dict) and name != "terrain" and not name.startswith("terrain."):
            out |= _dotted_keys(v, name + ".")
        else:
            out.add(name)
    return out


def _apply_preset(d, explicit):
    """Every parameter a preset may set takes the scenario's preset value (or the paper's
    where this preset leaves it), unless it was given explicitly."""
    paper = flatten(paper_step())
    values = preset_values(d["preset"], d)
    controlled = set()
    for name in PRESETS:
        controlled |= set(preset_values(name, d))
    for name in controlled - set(explicit):
        set_dotted(d, name, copy.deepcopy(values.get(name, paper[name])))


@dataclass(frozen=True)
class Scenario:
    """A validated, fully resolved scenario. Build with from_dict or paper().
    explicit: the dotted names set by the user rather than by defaults or a preset."""
    data: dict
    explicit: frozenset = frozenset()

    @classmethod
    def paper(cls, **overrides):
        return cls.from_dict(overrides)

    @classmethod
    def from_dict(cls, overrides=None, base=None, explicit=None):
        """Defaults (the paper's run, or ``base``) updated by ``overrides``; keys may be
        nested tables or dotted names. A base given as a plain dict counts as explicit
        throughout (it is a resolved scenario: its preset values stay as they are)."""
        d = copy.deepcopy(base if base is not None else paper_step())
        if explicit is None:
            explicit = frozenset(flatten(d)) if base is not None else frozenset()
        nested = {}
        for k, v in (overrides or {}).items():
            if not isinstance(k, str):
                raise ScenarioError(f"parameter names must be text, got {k!r}")
            if "." in k and not k.startswith("terrain."):
                if k not in RULES:
                    raise _unknown(k, parameter_names())
            set_dotted(nested, k, v)
        _merge(d, nested)
        explicit = frozenset(explicit | _dotted_keys(nested))
        d["preset"] = _check_value("preset", d.get("preset"), RULES["preset"])
        _apply_preset(d, explicit)
        return cls(validate(d, explicit), explicit)

    def with_overrides(self, overrides):
        return Scenario.from_dict(overrides, base=self.data, explicit=self.explicit)

    def to_dict(self):
        return copy.deepcopy(self.data)

    def __getitem__(self, name):
        d = self.data
        for p in name.split("."):
            d = d[p]
        return d

    @property
    def name(self):
        return self.data["name"]


def _check_extensions(d, explicit):
    """The models beyond the paper: coefficients that belong together, sizes that must
    match, and what the lee solver supports."""
    c = d["contact"]
    if c["damping"] == "viscous" and c["damping_ratio"] <= 0.0:
        raise ScenarioError("contact.damping = 'viscous' needs contact.damping_ratio > 0 (e.g. 0.1); "
                            "or contact.damping = 'none'")
    if c["damping"] in ("hunt_crossley", "lankarani_nikravesh", "flores") and \
            "contact.restitution" not in explicit:
        raise ScenarioError(f"contact.damping = '{c['damping']}' needs contact.restitution, a number in (0, 1] "
                            "(e.g. 0.75)")
    arms = d["vehicle"]["arm_damping"]
    n = d["vehicle"]["n_wheels"]
    if arms and len(arms) != n:
        raise ScenarioError(f"vehicle.arm_damping has {len(arms)} values for {n} road wheels: give one per wheel "
                            "(0 = no shock absorber), or [] for none")
    for i, a in enumerate(arms):
        if isinstance(a, bool) or not isinstance(a, (int, float)) or not (math.isfinite(a) and a >= 0.0):
            raise ScenarioError(f"vehicle.arm_damping[{i}] = {a!r} is not allowed: expected a number >= 0 (N m s/rad)")
    if d["solver"] == "lee":
        ext = [name for name, on in (
            ("contact.law", c["law"] != "linear"), ("contact.damping", c["damping"] != "none"),
            ("contact.geometry", c["geometry"] != "paper"), ("contact.friction", c["friction"] > 0),
            ("track.link_damping", d["track"]["link_damping"] > 0),
            ("terrain.soil", d["terrain"].get("soil", "rigid") != "rigid"),
            ("vehicle.arm_damping", any(a > 0 for a in arms))) if on]
        if ext:
            raise ScenarioError(f"solver = 'lee' runs the paper's model only, but {ext[0]} is set; "
                                "use solver = 'reduced' for the models beyond the paper")


def _check_placed_by_time(out):
    """An obstacle placed by first_contact_time stands speed x time ahead of the resting track:
    at speed 0 it would stand against the track at t = 0, whatever time was asked."""
    t = out["terrain"]
    first = t["obstacles"][0] if t["kind"] == "sequence" else t
    if out["speed"] == 0.0 and first.get("first_contact_time", 0.0) > 0.0:
        raise ScenarioError(f"terrain.first_contact_time = {first['first_contact_time']} s needs speed > 0 (the "
                            "obstacle is placed speed x time ahead of the track); at speed 0 give terrain.position "
                            "(m) or a flat terrain")


def validate(d, explicit=frozenset()):
    out = copy.deepcopy(d)
    flat = flatten({k: v for k, v in d.items() if k != "terrain"})
    for name, value in flat.items():
        if name not in RULES:
            raise _unknown(name, parameter_names())
        set_dotted(out, name, _check_value(name, value, RULES[name], name in _OPEN_LOW))
    out["terrain"] = validate_terrain(d["terrain"])
    if out["output_interval"] > out["duration"]:
        raise ScenarioError(f"output_interval = {out['output_interval']} s is longer than duration = "
                            f"{out['duration']} s; allowed: (0, duration]")
    if out["duration"] / out["output_interval"] > 2_000_000:
        raise ScenarioError("output_interval is too small for this duration: at most 2,000,000 output samples")
    _check_geometry(out["vehicle"], out["track"])
    _check_placed_by_time(out)
    out["vehicle"]["arm_damping"] = [float(a) for a in out["vehicle"]["arm_damping"]]
    _check_extensions(out, explicit)
    _check_closed(out, explicit)
    return out
