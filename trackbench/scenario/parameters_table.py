"""The parameter table: the paper's defaults and, for every dotted name, its type, bounds,
allowed values and unit. Data only; the checks that read it sit beside it (check_*.py)."""

import math

from trackbench.scenario.presets import PRESETS

from ..model.contact.laws import DAMPING_LAWS, ELASTIC_LAWS, FRICTION_LAWS, GEOMETRIES
from ..model.core.indices import DRIVES
from ..model.ground.rough import CLASSES
from ..model.vehicle.parameters import GRAVITY, closed_defaults, paper_contact, paper_track, paper_vehicle
from ..solvers.registry import METHODS
from ..solvers.registry import SOLVERS as _REGISTRY

ROUGHNESS_CLASSES = tuple(CLASSES)
# the time integrators by name (solvers/registry.py) as imported: the parameter table's text;
# check_run.check_solver validates against the registry as it is
SOLVERS = tuple(_REGISTRY)
# each solver's own settings table (SolverEntry.settings, e.g. lee.*): its Settings by table
_SOLVER_TABLES = {e.settings: e.setting_rules for e in _REGISTRY.values() if e.settings}
TERRAIN_KINDS = ("flat", "step", "ramp", "block", "bump", "halfround", "points", "sequence", "random",
                 "profile")
OBSTACLE_KINDS = ("step", "ramp", "block", "bump", "halfround")
PLACEMENT_KEYS = ("position", "first_contact_time", "gap")  # where an obstacle stands: one of them
PAPER_FIRST_CONTACT_TIME = 0.0568  # s: also the default of a first obstacle given no placement
# The grounds a run rides over rather than meets obstacles on: what is read of them is the
# ride (accelerations up to the 80 Hz of the Wk weighting, over 10-60 s), not the shape of
# impacts lasting a millisecond or two. Their defaults (check_run.apply_sampling): samples
# at RIDE_OUTPUT_INTERVAL (12 samples a period at 80 Hz; a 60 s run writes ~36 MB) and
# recording frames at RIDE_FPS (a screen's rate; every 20th sample, so each frame is a
# sample of the dense output). On obstacles the paper's 1e-4 s and every 5th sample stay:
# sampled at 1e-3 s the paper's wheel-force histories miss 13-24 % of their peaks.
RIDE_KINDS = ("flat", "random", "profile")
RIDE_OUTPUT_INTERVAL = 1e-3   # s
RIDE_FPS = 50.0               # frames per simulated second
# the groups only the closed track layout uses (track.tension too)
CLOSED_GROUPS = ("sprocket", "idler", "rollers", "drive", "drawbar")


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
        "max_step": 1e-4,   # s, 0: none; the paper preset: the output interval on obstacles (presets.py)
        "max_steps": 0,       # 0: STEPS_PER_SECOND a simulated second, at least MIN_STEPS (solvers/base.py)
        "perturbation": 0.0,  # m: seeded nudge of the free pins (study replicates)
        "seed": 0,
        "vehicle": paper_vehicle(),
        "track": paper_track(),
        "contact": paper_contact(),
        "terrain": {"kind": "step", "height": 0.1, "first_contact_time": PAPER_FIRST_CONTACT_TIME},
        **closed_defaults(),
        **{table: {v.key: v.default for v in values} for table, values in _SOLVER_TABLES.items()},
        # side-view frames: every 5th output sample on obstacles (impacts in slow motion), at
        # record.fps on ride ground (check_run.apply_sampling)
        "record": {"enabled": True, "every": 5, "fps": RIDE_FPS},
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
    # any text here: check_run.check_solver checks both against the registry
    "solver": (str, None, None, "one of " + ", ".join(SOLVERS)),
    "method": (str, None, None, "one of " + ", ".join(METHODS)),
    "tolerance": (float, 1e-14, 1e-3, "a number in [1e-14, 1e-3]"),   # its defaults: CLOSED_TOLERANCE
    "output_interval": (float, 0.0, math.inf,
                        "a number > 0 (s; default 1e-4 on obstacles, 1e-3 on flat ground)"),
    "max_step": (float, 0.0, 1000.0, "a number in [0, 1000] s (0: no cap, the error control alone; "
                 "default: the output interval for the paper preset on obstacles, else 0)"),
    "max_steps": (int, 0, 10**9, "an integer >= 0 (0: 400,000 a simulated second, at least 2,000,000)"),
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
    "vehicle.seat_x": (float, -100.0, 100.0, "a number in [-100, 100] m (forward of the mass centre)"),
    "vehicle.seat_y": (float, -100.0, 100.0, "a number in [-100, 100] m (above the mass centre)"),
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
    # the law tables themselves: a law added to a table is allowed at once (str(): "one of ...")
    "contact.law": (str, ELASTIC_LAWS, None, ELASTIC_LAWS),
    "contact.exponent": (float, 0.0, 3.0, "a number in (0, 3]"),
    "contact.damping": (str, DAMPING_LAWS, None, DAMPING_LAWS),
    "contact.damping_ratio": (float, 0.0, 10.0, "a number in [0, 10]"),
    "contact.restitution": (float, 0.0, 1.0, "a number in (0, 1]"),
    "contact.damping_ramp": (float, 0.0, 0.1, "a number in (0, 0.1] m"),
    "contact.min_approach_speed": (float, 0.0, 100.0, "a number in (0, 100] m/s"),
    "contact.geometry": (str, tuple(GEOMETRIES), None, "one of " + ", ".join(GEOMETRIES)),
    "contact.friction": (float, 0.0, 10.0, "a number in [0, 10] (Coulomb mu; 0 = frictionless)"),
    "contact.friction_velocity": (float, 0.0, 10.0, "a number in (0, 10] m/s"),
    "contact.friction_law": (str, tuple(FRICTION_LAWS), None, "one of " + ", ".join(FRICTION_LAWS)),
    "contact.friction_stiffness": (
        float,
        0.0,
        1e12,
        "a number in (0, 1e12] (N/m: the bristle's tangential stiffness)",
    ),
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
    "drive.curve": (
        list,
        None,
        None,
        "a list of [sprocket speed rad/s, torque N m] pairs, speeds increasing, or []",
    ),
    "drive.target": (float, -100.0, 100.0, "a number in [-100, 100] m/s (default: the start speed)"),
    "drive.gain_p": _NONNEG,
    "drive.gain_i": _NONNEG,
    "drive.torque_limit": _POS,
    "drawbar.load": (float, -1e7, 1e7, "a number in [-1e7, 1e7] N (rearward positive; 0: none)"),
    "drawbar.hitch": (list, None, None, "a pair [x, y] of finite numbers (m, body point)"),
    "drawbar.slip": (float, 0.0, 0.95, "a number in [0, 0.95] (0: no towing rig)"),
    "drawbar.rig_damping": (float, 0.0, math.inf, "a number > 0 (N s/m)"),
    **{f"{table}.{v.key}": v.rule for table, values in _SOLVER_TABLES.items() for v in values},
    "record.enabled": (bool, None, None, "true or false"),
    "record.every": (int, 0, 10**6, "an integer >= 0 (0: frames at record.fps)"),
    "record.fps": (float, 0.0, 10000.0, "a number in (0, 10000] frames per simulated second"),
}
# The unit of every parameter that has one (axis labels and titles of the figures).
UNITS = {
    "speed": "m/s",
    "duration": "s",
    "gravity": "m/s^2",
    "output_interval": "s",
    "max_step": "s",
    "record.fps": "1/s",
    "perturbation": "m",
    "vehicle.chassis_mass": "kg",
    "vehicle.chassis_inertia": "kg m^2",
    "vehicle.arm_mass": "kg",
    "vehicle.arm_inertia": "kg m^2",
    "vehicle.arm_length": "m",
    "vehicle.arm_angle": "deg",
    "vehicle.torsion_stiffness": "N m/rad",
    "vehicle.wheel_radius": "m",
    "vehicle.first_pivot_x": "m",
    "vehicle.pivot_y": "m",
    "vehicle.pivot_spacing": "m",
    "vehicle.front_track_end": "m",
    "vehicle.rear_track_end": "m",
    "vehicle.seat_x": "m",
    "vehicle.seat_y": "m",
    "track.link_length": "m",
    "track.pin_mass": "kg",
    "track.link_stiffness": "N/m",
    "track.pad_wheel": "m",
    "track.pad_ground": "m",
    "track.wheel_stiffness": "N/m",
    "track.ground_stiffness": "N/m",
    "track.link_damping": "N s/m",
    "vehicle.arm_damping": "N m s/rad",
    "contact.damping_ramp": "m",
    "contact.min_approach_speed": "m/s",
    "contact.friction_velocity": "m/s",
    "contact.friction_stiffness": "N/m",
    "track.tension": "N",
    "track.width": "m",
    "sprocket.pitch_radius": "m",
    "sprocket.seat_radius": "m",
    "sprocket.pin_radius": "m",
    "sprocket.tip_radius": "m",
    "sprocket.flank_angle": "deg",
    "sprocket.stiffness": "N/m",
    "sprocket.inertia": "kg m^2",
    "idler.radius": "m",
    "idler.mass": "kg",
    "idler.preload": "N",
    "idler.stiffness": "N/m",
    "idler.damping": "N s/m",
    "idler.travel": "m",
    "idler.guide_angle": "deg",
    "rollers.positions": "m",
    "rollers.radius": "m",
    "drive.torque": "N m",
    "drive.target": "m/s",
    "drive.gain_p": "N m s/m",
    "drive.gain_i": "N m/m",
    "drive.torque_limit": "N m",
    "drawbar.load": "N",
    "drawbar.hitch": "m",
    "drawbar.rig_damping": "N s/m",
    **{f"{table}.{v.key}": v.unit for table, values in _SOLVER_TABLES.items() for v in values if v.unit},
    "terrain.height": "m",
    "terrain.length": "m",
    "terrain.position": "m",
    "terrain.first_contact_time": "s",
    "terrain.gap": "m",
    "terrain.rms": "m",
    "terrain.rms_in": "in",
    "terrain.radius": "m",
    "terrain.wavelength_min": "m",
    "terrain.wavelength_max": "m",
    "terrain.run_in": "m",
}

# the names whose low bound is itself not allowed
OPEN_LOW = {
    "duration",
    "record.fps",
    "drawbar.rig_damping",
    "tolerance",
    "output_interval",
    "vehicle.arm_angle",
    "contact.exponent",
    "track.width",
    "contact.restitution",
    "contact.damping_ramp",
    "contact.min_approach_speed",
    "contact.friction_velocity",
    "contact.friction_stiffness",
} | {k for k, r in RULES.items() if r is _POS}

# terrain.* and obstacle keys: the terrain table is checked as a whole (its keys depend on its kind)
TERRAIN_RULES = {
    "kind": (str, TERRAIN_KINDS, None, "one of " + ", ".join(TERRAIN_KINDS)),
    "height": (float, 0.0, 10.0, "a number in (0, 10] m"),
    "length": (float, 0.0, 1000.0, "a number in (0, 1000] m"),
    "radius": (float, 0.0, 5.0, "a number in (0, 5] m (a half-round's radius, its height)"),
    "position": (float, -900.0, 900.0, "a number in [-900, 900] m (x of the obstacle's start)"),
    "first_contact_time": (float, 0.0, 1000.0, "a number in (0, 1000] s"),
    "gap": (float, 0.0, 1000.0, "a number in [0, 1000] m"),
    "points": (list, None, None, "a list of [x, y] pairs with x non-decreasing"),
    "obstacles": (list, None, None, "a list of obstacle tables"),
    "soil": (str, None, None, "rigid, a soil name (trackbench params) or a table of soil values"),
    "roughness_class": (str, ROUGHNESS_CLASSES, None, "one of " + ", ".join(ROUGHNESS_CLASSES)),
    "rms": (float, 0.0, 1.0, "a number in (0, 1] m (the profile's RMS elevation over its band)"),
    "rms_in": (float, 0.0, 40.0, "a number in (0, 40] in (NRMM's RMS elevation: wavelengths up to 60 ft)"),
    "seed": (int, 0, 2**63 - 1, "an integer >= 0"),
    "wavelength_min": (float, 0.0, 1000.0, "a number in (0, 1000] m"),
    "wavelength_max": (float, 0.0, 1000.0, "a number in (0, 1000] m"),
    "run_in": (float, 0.0, 1000.0, "a number in [0, 1000] m (flat ground before the rough section)"),
    "file": (str, None, None, "a CSV file of x, height (m)"),
}
TERRAIN_OPEN_LOW = ("height", "length", "radius", "first_contact_time", "rms", "rms_in", "wavelength_min",
                    "wavelength_max")
OBSTACLE_KIND_RULE = (str, OBSTACLE_KINDS, None, "one of " + ", ".join(OBSTACLE_KINDS))
# the keys each kind takes: as the whole terrain, and as one obstacle of a sequence
TERRAIN_KEYS = {
    "flat": set(),
    "step": {"height", "position", "first_contact_time"},
    "ramp": {"height", "length", "position"},
    "block": {"height", "length", "position", "first_contact_time"},
    "bump": {"height", "length", "position"},
    "halfround": {"radius", "position"},
    "points": {"points"},
    "sequence": {"obstacles"},
    "random": {"roughness_class", "rms", "rms_in", "length", "seed", "wavelength_min", "wavelength_max",
               "run_in"},
    "profile": {"file"},
}
# a random profile's defaults (model/ground/rough.py): 100 m of rough ground after 10 m of flat
# run-in (the vehicle starts at rest on flat ground), wavelengths 0.5-20 m (below 0.5 m the
# track's pitch and pads bridge the ground; 20 m is 10 s of pitch at 2 m/s)
RANDOM_DEFAULTS = {"length": 100.0, "seed": 0, "wavelength_min": 0.5, "wavelength_max": 20.0, "run_in": 10.0}
OBSTACLE_KEYS = {
    "step": {"height", "position", "gap", "first_contact_time"},
    "ramp": {"height", "length", "position", "gap"},
    "block": {"height", "length", "position", "gap", "first_contact_time"},
    "bump": {"height", "length", "position", "gap"},
    "halfround": {"radius", "position", "gap"},
}

# --- The closed track's default tolerance ------------------------------------------------------
# Where a scenario with the closed track and the damped preset sets no tolerance and integrates
# with dopri5: every driven model's step run passes the accuracy criterion (docs/validation.md,
# "Judging a driven run") from 1e-7 (regularised and bristle friction, LETE sand), but the
# energy residual stays within 1e-6 of E0 over a 6 s drive from rest only from 3e-8 (8.2e-7;
# 1e-7: 6.4e-6); 1e-8 keeps it at 3.8e-7, a margin (docs/benchmarks.md, "The driven track's
# default"). The bolted track (the paper's model) keeps `tolerance`'s 1e-9.
CLOSED_TOLERANCE = 1e-8
CLOSED_TOLERANCE_METHOD = "dopri5"
_TOLERANCES = [f"{t:g}".replace("e-0", "e-") for t in (paper_step()["tolerance"], CLOSED_TOLERANCE)]
RULES["tolerance"] = RULES["tolerance"][:3] + (
    f"a number in [1e-14, 1e-3] (default {_TOLERANCES[0]}; the closed track with the damped preset and "
    f"{CLOSED_TOLERANCE_METHOD}: {_TOLERANCES[1]})",)


# --- The pins' velocities' own tolerance (solvers/base.py: the error norm) --------------------
# Optional: absent from the paper's defaults, so that a scenario that does not set it resolves
# (and hashes: study run ids, the recorded runs' attributes) as before. Unset, method =
# "ros34pw2" holds the pins' velocities to its default multiple of `tolerance`
# (solvers/rosenbrock/ros_run.py); the other methods hold every component to `tolerance`.
OPTIONAL = ("tolerance_pin_velocity",)
RULES["tolerance_pin_velocity"] = (
    float, 0.0, 1e-3,
    "a number in (0, 1e-3]: the pins' velocities' tolerance of method ros34pw2 (unset: its default)",
)
OPEN_LOW.add("tolerance_pin_velocity")

# --- the road arms' bump stops and the torsion bars' free angle (model/vehicle/parameters.py
# ARM_OPTIONS): optional, per wheel; angles below the chassis x axis as vehicle.arm_angle ----
_ARM_ANGLE = (float, -90.0, 180.0, "a number in (-90, 180] deg (below the chassis x axis, as arm_angle)")
RULES["vehicle.jounce_stop_angle"] = _ARM_ANGLE
RULES["vehicle.rebound_stop_angle"] = _ARM_ANGLE
RULES["vehicle.torsion_free_angle"] = _ARM_ANGLE
RULES["vehicle.bump_stop_stiffness"] = (float, 0.0, 1e12, "a number in [0, 1e12] (N m/rad; 0: no bump stops)")
OPTIONAL += ("vehicle.jounce_stop_angle", "vehicle.rebound_stop_angle", "vehicle.bump_stop_stiffness",
             "vehicle.torsion_free_angle")
OPEN_LOW.update({"vehicle.jounce_stop_angle", "vehicle.rebound_stop_angle", "vehicle.torsion_free_angle"})
UNITS.update({"vehicle.jounce_stop_angle": "deg", "vehicle.rebound_stop_angle": "deg",
              "vehicle.torsion_free_angle": "deg", "vehicle.bump_stop_stiffness": "N m/rad"})


def parameter_names():
    """Every dotted name a scenario accepts (terrain keys included)."""
    return sorted(RULES) + sorted("terrain." + k for k in TERRAIN_RULES)


# --- real vehicles as data (trackbench/vehicles/, scenario/vehicle_model.py) ---------------
from ..model.vehicle.parameters import PER_WHEEL  # noqa: E402  (this block's own, for merging)

# vehicle.model names a vehicle file: a catalogue name or a path. No default: a scenario
# without it keeps every name and value it had (its study run ids with them).
RULES["vehicle.model"] = (str, None, None, "a catalogue name (trackbench vehicles) or a vehicle file (.toml)")
# the groups a vehicle file sets (its values are the scenario's defaults; explicit ones win)
VEHICLE_GROUPS = ("vehicle", "track", "sprocket", "idler", "rollers")
# values that may differ from road wheel to road wheel: a list, front to rear, or one number for
# every wheel (model/vehicle/parameters.PER_WHEEL); pivot_spacing: one per gap between neighbours
PER_WHEEL_NAMES = tuple("vehicle." + k for k in PER_WHEEL)
for _name in PER_WHEEL_NAMES:
    _t, _lo, _hi, _text = RULES[_name]
    _each = "one per gap between neighbouring wheels" if _name == "vehicle.pivot_spacing" else (
        "one per road wheel, front to rear")
    RULES[_name] = (_t, _lo, _hi, f"{_text}, or a list of them ({_each})")
