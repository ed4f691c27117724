"""A vehicle at rest and the catalogue's listing (`trackbench vehicles`, `trackbench vehicle
show`): the static equilibrium on level ground of a vehicle file (run/assemble.equilibrium),
each wheel's load, the track's tension and sag, the ground pressure and the seat's height."""

import math
from dataclasses import dataclass

import numpy as np

from trackbench.model.core import indices as L
from trackbench.model.vehicle.parameters import pivots, total_mass
from trackbench.scenario import Scenario
from trackbench.vehicles import catalogue, read


def vehicle_scenario(model, folder=None):
    """The scenario of a vehicle file (a catalogue name or a path) on level ground."""
    return Scenario.from_dict({"vehicle.model": model, "terrain": {"kind": "flat"}}, folder=folder)


def vehicle_mass(sc):
    """Everything the model carries (kg): chassis, arms with their wheels, the track's free
    pins; the closed track's every pin and the idler."""
    m = total_mass(sc["vehicle"], sc["track"])
    if sc["track.layout"] == "closed":
        m += sc["track.pin_mass"] + sc["idler.mass"]
    return m


def catalogue_rows():
    """(name, description, mass kg, road wheels, layout, reference) of every catalogue vehicle."""
    rows = []
    for name in catalogue():
        vf = read(name)
        sc = vehicle_scenario(name)
        rows.append(
            (
                name,
                vf.description,
                vehicle_mass(sc),
                sc["vehicle.n_wheels"],
                sc["track.layout"],
                vf.reference,
            )
        )
    return rows


def catalogue_table():
    lines = [f"{'name':10s} {'mass':>8s} {'wheels':>6s}  {'track':6s}  description; source"]
    for name, desc, mass, nw, layout, ref in catalogue_rows():
        lines.append(f"{name:10s} {mass / 1e3:6.2f} t {nw:6d}  {layout:6s}  {desc}; {ref}")
    return "\n".join(lines)


@dataclass
class Statics:
    scenario: Scenario
    eq: object  # solvers/equilibrium/static.Equilibrium
    pitch: float  # rad
    wheels: np.ndarray  # wheel centres, world (m)
    pivots: np.ndarray  # arm pivots, world
    pins: np.ndarray  # track pins, world
    seat: np.ndarray  # the seat, world
    contact_length: float  # of the track on the ground (m)
    ground_pressure: float  # weight over contact length x track width (Pa)
    sag: float  # of the closed track's return run below its chord (m); nan: paper layout

    def world(self, body):
        """Body points (n, 2) in the world at rest (the chassis' mass centre at x = 0)."""
        c, s = math.cos(self.pitch), math.sin(self.pitch)
        b = np.atleast_2d(np.asarray(body, float))
        return np.column_stack(
            [c * b[:, 0] - s * b[:, 1], self.eq.chassis_height + s * b[:, 0] + c * b[:, 1]]
        )


def statics(sc):
    """The vehicle of scenario sc at rest on level ground (an EquilibriumError when it has none)."""
    from trackbench.run.assemble import equilibrium

    eq = equilibrium(sc)
    st = Statics(
        sc,
        eq,
        eq.chassis_pitch,
        eq.info["wheel_centres"],
        np.zeros((0, 2)),
        eq.info["pins"],
        np.zeros(2),
        0.0,
        0.0,
        math.nan,
    )
    st.pivots = st.world(pivots(sc["vehicle"]))
    st.seat = st.world([sc["vehicle.seat_x"], sc["vehicle.seat_y"]])[0]
    hg, p = sc["track.pad_ground"], sc["track.link_length"]
    down = st.pins[:, 1] < hg  # pins pressing their ground pads
    if down.any():
        st.contact_length = float(np.ptp(st.pins[down, 0]) + p)  # each pin stands for a link
        st.ground_pressure = eq.weight / (st.contact_length * sc["track.width"])
    if sc["track.layout"] == "closed":
        st.sag = _return_run_sag(st, sc)
    return st


def _return_run_sag(st, sc):
    """The return run: the pins above every road wheel's top between the sprocket's and the
    idler's axes; its sag: the largest drop of a pin below the straight line between the
    run's first and last pins."""
    reach = np.asarray(sc["vehicle.wheel_radius"], float) + sc["track.pad_wheel"]
    top = float(np.max(st.wheels[:, 1] + reach))
    parts = closed_drawing(st)
    lo, hi = sorted((parts["sprocket"][0], parts["idler"][0]))
    p = st.pins
    run = p[(p[:, 1] > top) & (p[:, 0] > lo) & (p[:, 0] < hi)]
    if len(run) < 3:
        return 0.0
    run = run[np.argsort(run[:, 0])]
    a, b = run[0], run[-1]
    chord = a[1] + (run[:, 0] - a[0]) * (b[1] - a[1]) / (b[0] - a[0])
    return float(max(0.0, np.max(chord - run[:, 1])))


def rest_angles(eq):
    """Each arm's angle at rest, degrees below the chassis x axis (as vehicle.arm_angle)."""
    nw = eq.wheel_load.size
    return np.degrees(eq.q[L.Q_ARM:L.Q_ARM + nw] + math.pi)


def _arm_notes(sc, eq, rest):
    """Where the arms rest: set (arm_angle), or where the torsion bars from their free angles
    carry the wheels, against the design position; and any arm resting on a bump stop."""
    v = sc["vehicle"]
    lines = []
    if v.get("torsion_free_angle") is not None:
        design = np.broadcast_to(np.asarray(v["arm_angle"], float), rest.shape)
        la = np.broadcast_to(np.asarray(v["arm_length"], float), rest.shape)
        rise = la * (np.sin(np.radians(design)) - np.sin(np.radians(rest)))
        lines.append(
            f"arms at rest where the torsion bars carry the wheels (free angle "
            f"{_listed(v['torsion_free_angle'])} deg): {rest.min():.2f} to {rest.max():.2f} deg below the "
            f"hull's x axis, the design position {_listed(v['arm_angle'])} deg; the wheels "
            f"{1e3 * rise.min():.1f} to {1e3 * rise.max():.1f} mm higher on the hull"
        )
    for key, side in (("jounce_stop_angle", "jounce"), ("rebound_stop_angle", "rebound")):
        if v.get(key) is None or not np.any(np.asarray(v.get("bump_stop_stiffness") or 0.0) > 0.0):
            continue
        stop = np.broadcast_to(np.asarray(v[key], float), rest.shape)
        past = np.flatnonzero(rest < stop if side == "jounce" else rest > stop)
        for i in past:
            lines.append(
                f"wheel {i + 1} rests on its {side} stop ({rest[i]:.2f} deg, the stop {stop[i]:.2f} deg)"
            )
    return lines


def _listed(value):
    """One number, or a per-wheel list shortened to its first value and '...'."""
    if isinstance(value, (list, tuple)):
        return f"{value[0]:g}" if len(set(value)) == 1 else f"{value[0]:g}, ..."
    return f"{value:g}"


def describe(st):
    """The text `trackbench vehicle show` prints."""
    sc, eq = st.scenario, st.eq
    g = sc["gravity"]
    lines = [
        f"{sc['vehicle.model']}: {vehicle_mass(sc) / 1e3:.3f} t, {sc['vehicle.n_wheels']} road wheels, "
        f"{sc['track.n_links']} links ({sc['track.layout']} track)",
        f"at rest on level ground: mass centre {eq.chassis_height:.4f} m high, pitch "
        f"{math.degrees(st.pitch):+.3f} deg (nose up +); residual {eq.residual / eq.weight:.1e} "
        "of the weight",
        f"{'wheel':>5s} {'load kN':>9s} {'share':>7s} {'arm deg':>8s} {'torsion N m':>12s} "
        f"{'centre x, y (m)':>18s}",
    ]
    carried = float(np.sum(eq.wheel_load))
    rest = rest_angles(eq)
    for i, (load, a, tq, (x, y)) in enumerate(zip(eq.wheel_load, rest, eq.preload, st.wheels)):
        lines.append(
            f"{i + 1:5d} {load / 1e3:9.2f} {100 * load / carried:6.1f}% {a:8.2f} {tq:12.0f} "
            f"{x:9.3f}, {y:.3f}"
        )
    lines += _arm_notes(sc, eq, rest)
    lines.append(
        f"the ground carries {eq.ground_force / 1e3:.2f} kN, the weight {eq.weight / 1e3:.2f} kN "
        f"({eq.weight / g / 1e3:.3f} t); the wheels {carried / 1e3:.2f} kN (the weight and the "
        "track's tension pressing them)"
    )
    t = eq.tension
    lines.append(
        f"track tension: mean {t.mean() / 1e3:.2f} kN, {t.min() / 1e3:.2f} to {t.max() / 1e3:.2f} kN"
    )
    if sc["track.layout"] == "closed":
        lines.append(
            f"tensioner force {eq.info['idler_force'] / 1e3:.2f} kN, idler slide "
            f"{1e3 * eq.info['idler_slide']:+.1f} mm; return run sag {1e3 * st.sag:.1f} mm"
        )
    else:
        lines.append("sag: none to report (the paper's layout: the track's ends are bolted to the hull)")
    lines.append(
        f"on the ground: {st.contact_length:.3f} m of track x {sc['track.width']} m wide: "
        f"nominal ground pressure {st.ground_pressure / 1e3:.1f} kPa "
        f"({st.ground_pressure / 6894.757:.2f} psi)"
    )
    lines.append(
        f"seat ({sc['vehicle.seat_x']}, {sc['vehicle.seat_y']}) m on the hull: "
        f"{st.seat[1]:.3f} m above the ground"
    )
    return "\n".join(lines)


def closed_drawing(st):
    """Sprocket, idler and rollers at rest, world: {part: (x, y, radius)} (closed layout)."""
    from trackbench.run.assemble import closed_parts

    sc = st.scenario
    g = closed_parts(sc)[0]
    idler = g.idler + st.eq.info["idler_slide"] * g.guide
    out = {
        "sprocket": (*st.world(g.sprocket)[0], g.pitch_radius),
        "idler": (*st.world(idler)[0], sc["idler.radius"]),
    }
    for j, p in enumerate(sc["rollers.positions"]):
        out[f"roller {j + 1}"] = (*st.world(p)[0], sc["rollers.radius"])
    return out
