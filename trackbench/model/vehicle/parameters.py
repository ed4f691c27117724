"""The paper's vehicle (Lee 2000, section 5, as pinned down by the model spec).

``paper_vehicle()`` and ``paper_track()`` return fresh dicts so that a caller can
change a copy without touching the defaults. ``pack()`` turns validated vehicle and
track dicts into the arrays the compiled kernels use.
"""

import math

import numpy as np

from ..contact.laws import BRISTLE_DAMPING_RATIO, DAMPING_LAWS, ELASTIC_LAWS, FRICTION_LAWS, GEOMETRIES
from ..core import indices as L


def paper_vehicle():
    """Chassis, torsion-bar arms and road wheels (SI units, angles in degrees)."""
    return {
        "chassis_mass": 20000.0,          # hull + turret (kg)
        "chassis_inertia": 47700.0,       # about the mass centre (kg m^2)
        "arm_mass": 300.0,                # torsion-bar arm + road wheel (kg)
        "arm_inertia": 12.5,              # about the wheel centre (kg m^2)
        "arm_length": 0.5,                # pivot to wheel centre (m)
        "arm_angle": 45.0,                # below the chassis x axis, trailing, at equilibrium (deg)
        "torsion_stiffness": 191000.0,    # k_t (N m/rad)
        "wheel_radius": 0.28,             # r (m)
        "n_wheels": 5,
        "first_pivot_x": 1.70,            # body point of wheel 1's torsion-bar axis (m)
        "pivot_y": -0.20,
        "pivot_spacing": 0.81,            # pivot i at first_pivot_x - i * spacing
        "front_track_end": [2.54, 0.0],   # body point where pin 0 is fixed (m)
        "rear_track_end": [-2.81, 0.0],   # body point where the last pin is fixed (m)
        "arm_damping": [],                # rotary shock absorber per station (N m s/rad); [] = none
        # the driver's seat (no part of the paper's model: the ride metrics are read there), a
        # body point from the mass centre: in the front third of the hull (track ends at 2.54
        # and -2.81 m), between road wheels 1 and 2, 0.3 m above the mass centre
        "seat_x": 1.5,
        "seat_y": 0.3,
    }


def paper_track():
    """Track links, pins, rubber pads and contact stiffnesses."""
    return {
        "n_links": 30,
        "link_length": 0.19,  # L0, undeformed (m)
        "pin_mass": 20.0,  # each free pin (kg)
        "link_stiffness": 8.0e6,  # k_tau, Eq. (8) (N/m)
        "pad_wheel": 0.02,  # h_w: centre line to wheel-side surface (m)
        "pad_ground": 0.02,  # h_g: centre line to ground-side surface (m)
        "wheel_stiffness": 1.0e8,  # k_w, Eq. (4) (N/m)
        "ground_stiffness": 1.0e8,  # k_g, Eq. (6) (N/m)
        "link_damping": 0.0,  # axial dashpot parallel to each link spring (N s/m)
        "layout": "paper",  # "paper": ends fixed to the chassis; "closed": a loop (vehicle/closed_track.py)
        "tension": 80000.0,  # closed layout: static tension the derived link count and preload aim at (N)
        "width": 0.5,  # b: soft soil's pressure acts over this width (m; the paper gives none)
    }


def closed_defaults():
    """Sprocket, idler, rollers and drive of the closed layout (model/vehicle/closed_track.py derives the
    values given as 0 from the paper's vehicle; docs/model.md lists them)."""
    return {
        "sprocket": {
            "position": "rear",  # where the paper's track end is: "rear" or "front"; the idler at the other
            "teeth": 10,
            "pitch_radius": 0.0,  # seated pin centres (m); 0: p / (2 sin(pi/N)), p the link under `tension`
            "seat_radius": 0.03,  # circular seat between two teeth (m)
            "pin_radius": 0.027,  # a pin where it meets the teeth (m)
            "tip_radius": 0.0,  # tooth tips (m); 0: pitch_radius + pin_radius
            "flank_angle": 15.0,  # the flanks' flare, the pressure angle (deg)
            "stiffness": 1.0e8,  # pin-tooth penalty stiffness (N/m; the paper's pad stiffness)
            "inertia": 5.0,  # about its axis, drive line included (kg m^2)
        },
        "idler": {
            "radius": 0.28,  # the road wheels' (m)
            "mass": 150.0,  # wheel + carrier (kg)
            "preload": 0.0,  # tensioner force at slide 0 (N); 0: holds the loop at track.tension
            "stiffness": 1.0e6,  # tensioner spring (N/m; Chrono's M113)
            "damping": 1.4e4,  # tensioner damper (N s/m; Chrono's M113)
            "travel": 0.15,  # the carrier slides at most this far either way (m)
            "guide_angle": 0.0,  # the guide's tilt above the outward horizontal (deg)
        },
        "rollers": {
            "positions": [],  # body points of the support rollers' axes, [[x, y], ...] (m)
            "radius": 0.15,  # (m)
        },
        "drive": {
            "kind": "none",  # "none" (free sprocket), "torque", "speed"
            "torque": 0.0,  # torque drive: forward torque on the sprocket (N m)
            "curve": [],  # torque drive: [[sprocket speed rad/s, torque N m], ...] instead of torque
            "target": 10.0,  # speed drive: chassis speed to hold (m/s); default: the start speed
            "gain_p": 3.0e4,  # speed drive: PI gains (N m per m/s, N m per m)
            "gain_i": 3.0e4,
            "torque_limit": 3.0e4,  # speed drive: |torque| at most (N m)
        },
        "drawbar": {
            "load": 0.0,  # constant rearward horizontal force at the hitch (N); 0: none
            "hitch": [
                0.0,
                0.0,
            ],  # body point where the drawbar pulls (m); the mass centre: no pitching moment
            "slip": 0.0,  # towing rig: the slip it sets (0: no rig; needs drive.kind = "speed")
            # towing rig: dashpot from its carriage at drive.target to the hitch (N s/m)
            "rig_damping": 2.0e6,
        },
    }


def paper_contact():
    """Contact laws: the paper's frictionless, undamped linear springs (section 2.2)."""
    return {
        "law": "linear",                  # a name in model/contact/laws.py ELASTIC_LAWS
        "exponent": 1.5,                  # n of the power law (Hertz: 1.5)
        "damping": "none",                # a name in model/contact/laws.py DAMPING_LAWS
        "damping_ratio": 0.0,             # zeta of the viscous law
        "restitution": 1.0,               # e of the restitution-based laws
        "damping_ramp": 2e-4,             # d_r: depth over which the viscous dashpot ramps in (m)
        "min_approach_speed": 0.1,        # approach speeds below this count as this (m/s)
        "geometry": "paper",              # or "continuous"
        "friction": 0.0,                  # Coulomb mu between ground and track (0: the paper)
        "friction_velocity": 0.01,        # regularising speed of the friction law (m/s)
        "friction_law": "regularised",    # or "bristle": a spring and dashpot that slip at mu p
        "friction_stiffness": 2.0e7,      # the bristle's tangential stiffness per pin contact (N/m)
    }


GRAVITY = 9.81
NEIGHBOUR_SKIN = 0.05  # m; only sets how often the contact lists are rebuilt


# the vehicle's values that may differ from road wheel to road wheel: a list (one per wheel,
# front to rear; pivot_spacing one per gap between neighbours) or one number for every wheel
PER_WHEEL = ("arm_mass", "arm_inertia", "arm_length", "arm_angle", "torsion_stiffness", "wheel_radius",
             "pivot_y", "pivot_spacing") + ("jounce_stop_angle", "rebound_stop_angle", "bump_stop_stiffness",
                                             "torsion_free_angle")
# the optional ones among them (no default, absent from the paper's vehicle: a vehicle without
# them resolves, hashes and runs as before): the road arms' bump stops and the torsion bars'
# free angle, the ride height (docs/model.md, "Bump stops" and "Initial equilibrium")
ARM_OPTIONS = ("jounce_stop_angle", "rebound_stop_angle", "bump_stop_stiffness", "torsion_free_angle")


def per_wheel(vehicle, key):
    """vehicle[key] as one float per road wheel, front to rear (pivot_spacing: one per gap)."""
    n = int(vehicle["n_wheels"]) - (key == "pivot_spacing")
    value = vehicle[key]
    if isinstance(value, (list, tuple, np.ndarray)):
        return np.array(value, dtype=float)
    return np.full(n, float(value))


def pivots(vehicle):
    """Body points of the arm pivots, wheel 1 (front) first: shape (n_wheels, 2). Pivot i
    lies pivot_spacing behind pivot i - 1 (one spacing, or each gap its own)."""
    i = np.arange(int(vehicle["n_wheels"]))
    spacing = vehicle["pivot_spacing"]
    if isinstance(spacing, (list, tuple, np.ndarray)):
        x = vehicle["first_pivot_x"] - np.concatenate([[0.0], np.cumsum(np.array(spacing, dtype=float))])
    else:
        x = vehicle["first_pivot_x"] - spacing * i
    return np.column_stack([x, per_wheel(vehicle, "pivot_y")])


def per_wheel_or_none(vehicle, key):
    """per_wheel of an optional key (ARM_OPTIONS), None where the vehicle does not give it."""
    return None if vehicle.get(key) is None else per_wheel(vehicle, key)


def arm_phi(angle_deg):
    """phi of arms at these angles below the chassis x axis (deg), trailing: -pi + angle."""
    return np.array([-math.pi + math.radians(a) for a in angle_deg])


def equilibrium_arm_angle(vehicle):
    """phi of each arm at the initial equilibrium (one per wheel): trailing arm, arm_angle
    below the chassis x axis. With vehicle.torsion_free_angle, arm_angle is the design position
    and the equilibrium's first guess, until with_rest_angles puts the solved rest angles there."""
    return arm_phi(per_wheel(vehicle, "arm_angle"))


def free_angle(vehicle):
    """phi of each torsion bar's free angle (vehicle.torsion_free_angle), or None: then the
    arms rest at arm_angle and the free angles follow from the equilibrium."""
    a = per_wheel_or_none(vehicle, "torsion_free_angle")
    return None if a is None else arm_phi(a)


def with_rest_angles(vehicle, phi):
    """A copy of vehicle whose arm_angle holds the rest angles phi (one per arm): the wheels at
    rest that the closed track's geometry and the equilibrium's start are built round."""
    return {**vehicle, "arm_angle": [math.degrees(p + math.pi) for p in phi]}


def stop_columns(vehicle):
    """{ARMS_* column: values} of the bump stops: k_stop and the stops' phi (jounce: the wheel
    up, a smaller angle below the x axis; a stop not given: -inf or +inf, never reached); k_stop
    0 where the vehicle gives none (the kernels then skip the stops: the paper's model)."""
    n = int(vehicle["n_wheels"])
    k = per_wheel_or_none(vehicle, "bump_stop_stiffness")
    jounce = per_wheel_or_none(vehicle, "jounce_stop_angle")
    rebound = per_wheel_or_none(vehicle, "rebound_stop_angle")
    return {L.ARMS_STOP_K: np.zeros(n) if k is None else k,
            L.ARMS_JOUNCE: np.full(n, -math.inf) if jounce is None else arm_phi(jounce),
            L.ARMS_REBOUND: np.full(n, math.inf) if rebound is None else arm_phi(rebound)}


def wheel_centres_body(vehicle):
    """Wheel centres in the chassis frame at the initial equilibrium: the scenario's checks,
    the closed track's geometry and the equilibrium's start."""
    from ..core import fixed_math as fm  # numba: loaded when first needed

    return wheel_centres_with(vehicle, fm.cos, fm.sin)


def wheel_centres_with(vehicle, cos, sin):
    """wheel_centres_body with the given cos and sin (a check's may use the C library's)."""
    la = per_wheel(vehicle, "arm_length")
    phi = equilibrium_arm_angle(vehicle)
    return pivots(vehicle) + np.array([[la[i] * cos(p), la[i] * sin(p)] for i, p in enumerate(phi)])


def station_columns(vehicle, track):
    """{ARMS_* column: one value per road wheel}: what the kernels read per station."""
    ma, ia, la = (per_wheel(vehicle, k) for k in ("arm_mass", "arm_inertia", "arm_length"))
    r = per_wheel(vehicle, "wheel_radius")
    return {L.ARMS_LENGTH: la, L.ARMS_REACH: r + track["pad_wheel"], L.ARMS_MASS: ma, L.ARMS_INERTIA: ia,
            L.ARMS_STIFFNESS: per_wheel(vehicle, "torsion_stiffness"), L.ARMS_DIAGONAL: ma * la * la + ia,
            L.ARMS_RADIUS: r, **stop_columns(vehicle)}


def _pack_contact(par, contact):
    """The contact laws' codes and coefficients (their rows in model/contact/laws.py) into par."""
    elastic = ELASTIC_LAWS[contact["law"]]
    par[L.P_CONTACT_LAW] = elastic.code
    par[L.P_CONTACT_EXPONENT] = contact["exponent"] if elastic.parameter == "contact.exponent" else 1.0
    damping = DAMPING_LAWS[contact["damping"]]
    par[L.P_CONTACT_DAMPING] = damping.code
    zeta = contact["damping_ratio"] if damping.parameter == "contact.damping_ratio" else 0.0
    # c = 2 zeta sqrt(k m_pin): the same rule for wheel, ground and corner contacts
    par[L.P_C_WHEEL] = 2.0 * zeta * math.sqrt(par[L.P_K_WHEEL] * par[L.P_PIN_MASS])
    par[L.P_C_GROUND] = 2.0 * zeta * math.sqrt(par[L.P_K_GROUND] * par[L.P_PIN_MASS])
    par[L.P_RESTITUTION_FACTOR] = damping.coefficient(contact["restitution"]) if damping.coefficient else 0.0
    par[L.P_DAMPING_RAMP] = contact["damping_ramp"]
    par[L.P_MIN_APPROACH] = contact["min_approach_speed"]
    par[L.P_CONTACT_GEOMETRY] = GEOMETRIES[contact["geometry"]]
    par[L.P_FRICTION] = contact["friction"]
    par[L.P_FRICTION_VELOCITY] = contact["friction_velocity"]
    par[L.P_FRICTION_LAW] = FRICTION_LAWS[contact["friction_law"]]
    par[L.P_BRISTLE_K] = contact["friction_stiffness"]
    par[L.P_BRISTLE_C] = (
        2.0 * BRISTLE_DAMPING_RATIO * math.sqrt(contact["friction_stiffness"] * par[L.P_PIN_MASS])
    )


def pack(vehicle, track, gravity, contact=None):
    """Scalar parameter vector ``par`` (see indices.P_*) and the body-point tables."""
    par = np.zeros(L.N_PAR)
    par[L.P_CHASSIS_MASS] = vehicle["chassis_mass"]
    par[L.P_CHASSIS_INERTIA] = vehicle["chassis_inertia"]
    for k, key in ((L.P_ARM_MASS, "arm_mass"), (L.P_ARM_INERTIA, "arm_inertia"),
                   (L.P_ARM_LENGTH, "arm_length"), (L.P_TORSION_STIFFNESS, "torsion_stiffness"),
                   (L.P_WHEEL_RADIUS, "wheel_radius")):
        par[k] = per_wheel(vehicle, key)[0]   # wheel 1's; each station's own: station_columns
    par[L.P_PIN_MASS] = track["pin_mass"]
    par[L.P_LINK_LENGTH] = track["link_length"]
    par[L.P_LINK_STIFFNESS] = track["link_stiffness"]
    par[L.P_PAD_WHEEL] = track["pad_wheel"]
    par[L.P_PAD_GROUND] = track["pad_ground"]
    par[L.P_K_WHEEL] = track["wheel_stiffness"]
    par[L.P_K_GROUND] = track["ground_stiffness"]
    par[L.P_GRAVITY] = gravity
    par[L.P_SKIN] = NEIGHBOUR_SKIN
    par[L.P_LINK_DAMPING] = track.get("link_damping", 0.0)
    _pack_contact(par, contact or paper_contact())
    ends = np.array([vehicle["front_track_end"], vehicle["rear_track_end"]], dtype=float)
    return par, pivots(vehicle), ends


def total_mass(vehicle, track):
    arms = vehicle["arm_mass"]
    arms = float(np.sum(arms)) if isinstance(arms, (list, tuple)) else vehicle["n_wheels"] * arms
    return vehicle["chassis_mass"] + arms + (track["n_links"] - 1) * track["pin_mass"]


def arm_damping(vehicle):
    """One rotary damper coefficient per road-wheel station (zeros when none given)."""
    c = vehicle.get("arm_damping") or []
    return np.array(c, dtype=float) if len(c) else np.zeros(int(vehicle["n_wheels"]))
