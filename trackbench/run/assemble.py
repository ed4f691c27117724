"""What one run is made of before it runs: the vehicle's static equilibrium, the closed
layout's parts, the soft soil's values and memory, the initial state and the Model bundle the
compiled kernels take (each cached where a study's runs share it). simulate.py runs it;
output.py reads the closed layout's parts from here to build the Dataset."""

import functools
import json

import numpy as np

from trackbench.model.contact.laws import bristle_active
from trackbench.model.core import indices as L
from trackbench.model.core.bundles import arm_table, model_arrays, work_arrays
from trackbench.model.vehicle.parameters import (
    arm_damping,
    free_angle,
    pack,
    station_columns,
    total_mass,
    with_rest_angles,
)
from trackbench.scenario import Scenario
from trackbench.status import EquilibriumError


@functools.lru_cache(maxsize=32)
def _equilibrium_cached(key):
    from trackbench.solvers.equilibrium.static import solve_equilibrium
    vehicle, track, gravity, contact, soil = json.loads(key)
    return solve_equilibrium(vehicle, track, gravity, contact, {int(k): v for k, v in soil.items()})


def _closed(scenario):
    return scenario["track.layout"] == "closed"


_CLOSED_GROUPS = ("track", "gravity", "contact", "sprocket", "idler", "rollers", "drive", "drawbar")


def _closed_key(scenario):
    return json.dumps([resting_vehicle(scenario)] + [scenario[k] for k in _CLOSED_GROUPS], sort_keys=True)


REST_ANGLE_TOLERANCE = 1e-9   # rad: the rest angles the closed track is built round, settled
REST_ITERATIONS = 100
REST_STEP = 0.035   # rad (2 deg)


def resting_vehicle(scenario):
    """The scenario's vehicle with its arms at rest: itself, unless it gives the torsion bars'
    free angles (vehicle.torsion_free_angle); then arm_angle holds the rest angles the
    equilibrium solves for (cached)."""
    v = scenario["vehicle"]
    if v.get("torsion_free_angle") is None:
        return v
    return _resting(scenario)[0]


def _resting(scenario):
    """(the vehicle at rest, its equilibrium) of a scenario with free arms (cached)."""
    key = json.dumps([scenario["vehicle"]] + [scenario[k] for k in _CLOSED_GROUPS], sort_keys=True)
    return _resting_cached(key, json.dumps(soil_par(scenario)))


@functools.lru_cache(maxsize=32)
def _resting_cached(key, soil):
    """The rest angles of free arms: the vehicle with its arm_angle there, and its equilibrium
    (on the paper's layout, whose track ends sit on the hull, nothing is built round the wheels:
    one solve with the arm angles as Newton unknowns finds them).
    The closed track's loop, the idler's slide and its derived preload are built round the
    wheels at rest, and the rest angles follow from that loop's tension: a fixed-point
    iteration, the loop rebuilt round the last rest angles and each solve started from the
    last, until they change less than REST_ANGLE_TOLERANCE."""
    vehicle, track, gravity, contact, *rest = json.loads(key)
    nw = int(vehicle["n_wheels"])
    if track["layout"] != "closed":
        key = json.dumps([vehicle, track, gravity, contact, json.loads(soil)], sort_keys=True)
        eq = _equilibrium_cached(key)
        return with_rest_angles(vehicle, eq.q[L.Q_ARM:L.Q_ARM + nw]), eq
    # a path there from the design position, each solve started from the last (Newton's method
    # from a taut loop is not sure to find one; a loop built round the design position goes
    # slack once the wheels rise, the M113's idler spring being 1e7 N/m): the arms held at
    # arm_angle, then free, their torsion bars' free angles moved in steps of at most REST_STEP
    # from where they hold the arms at arm_angle to the given ones, the loop rebuilt round the
    # last rest angles at every step (held arms share the load by the pads' stiffness and come
    # off the track unevenly: no path for them)
    held = {k: x for k, x in vehicle.items() if k != "torsion_free_angle"}
    eq = _closed_solve(held, track, gravity, contact, rest, soil, "at arm_angle")
    phi = eq.q[L.Q_ARM:L.Q_ARM + nw]
    phi0 = free_angle(vehicle)
    steps = max(int(np.ceil(np.max(np.abs(phi0 - eq.phi0)) / REST_STEP)), 1)
    for j in range(1, steps):
        on_way = {**with_rest_angles(vehicle, phi), "torsion_free_angle":
                  list(np.degrees(eq.phi0 + (phi0 - eq.phi0) * j / steps + np.pi))}
        eq = _closed_solve(on_way, track, gravity, contact, rest, soil, "on the way to rest", eq)
        phi = eq.q[L.Q_ARM:L.Q_ARM + nw]
    for _ in range(REST_ITERATIONS):
        v = with_rest_angles(vehicle, phi)
        eq = _closed_solve(v, track, gravity, contact, rest, soil, "at rest", eq)
        new = eq.q[L.Q_ARM:L.Q_ARM + nw]
        change = float(np.max(np.abs(new - phi)))
        if change < REST_ANGLE_TOLERANCE:
            return v, eq
        phi = new
    raise EquilibriumError(
        f"the rest angles of the free arms (vehicle.torsion_free_angle) did not settle in {REST_ITERATIONS} "
        f"rounds of the closed track rebuilt round them (last change {change:.3g} rad)"
    )


def _closed_solve(v, track, gravity, contact, rest, soil, where, start=None):
    """The closed layout's equilibrium with the loop built round vehicle v's wheels (uncached),
    from the taut loop or from start."""
    from trackbench.model.vehicle.closed_track import ClosedLayoutError, without_drawbar
    from trackbench.solvers.equilibrium.static import solve_closed_equilibrium

    try:
        g, lp, guides = _closed_parts_cached(json.dumps([v, track, gravity, contact, *rest], sort_keys=True))
    except ClosedLayoutError as e:
        raise EquilibriumError(f"the closed track round the wheels {where}: {e}") from None
    return solve_closed_equilibrium(v, track, gravity, contact, g, without_drawbar(lp), guides,
                                    {int(k): x for k, x in json.loads(soil).items()}, start=start)


@functools.lru_cache(maxsize=32)
def _closed_parts_cached(key):
    from trackbench.model.vehicle.closed_track import closed_geometry, closed_vector, guide_table
    vehicle, track, gravity, contact, spr, idl, rol, drive, drawbar = json.loads(key)
    g = closed_geometry(vehicle, track, spr, idl, rol, frozenset({"track.n_links"}))
    c = 0.0
    if contact["damping"] == "viscous":   # the contacts' rule: c = 2 zeta sqrt(k m_pin)
        c = 2.0 * contact["damping_ratio"] * np.sqrt(spr["stiffness"] * track["pin_mass"])
    return g, closed_vector(g, spr, idl, drive, c, drawbar), guide_table(g, track, idl, rol)


def closed_parts(scenario: Scenario):
    """The closed layout's geometry, LP_* vector and guide table (cached), or None."""
    return _closed_parts_cached(_closed_key(scenario)) if _closed(scenario) else None


@functools.lru_cache(maxsize=32)
def _closed_equilibrium_cached(key, soil):
    from trackbench.model.vehicle.closed_track import without_drawbar
    from trackbench.solvers.equilibrium.static import solve_closed_equilibrium
    vehicle, track, gravity, contact, *_ = json.loads(key)
    g, lp, guides = _closed_parts_cached(key)
    return solve_closed_equilibrium(vehicle, track, gravity, contact, g, without_drawbar(lp), guides,
                                  {int(k): v for k, v in json.loads(soil).items()})


def equilibrium(scenario: Scenario):
    """Static equilibrium of the scenario's vehicle on flat ground (cached)."""
    if scenario["vehicle"].get("torsion_free_angle") is not None:
        return _resting(scenario)[1]   # found with the rest angles
    if _closed(scenario):
        return _closed_equilibrium_cached(_closed_key(scenario), json.dumps(soil_par(scenario)))
    key = json.dumps([resting_vehicle(scenario), scenario["track"], scenario["gravity"], scenario["contact"],
                      soil_par(scenario)], sort_keys=True)
    return _equilibrium_cached(key)


def _closed_velocities(scenario, eq, y0):
    """The closed track moving at `speed` without slip on the ground: every pin runs round
    the loop (clockwise, along its neighbours' chord) at `speed` relative to the chassis,
    the sprocket turns to match."""
    from trackbench.model.core import fixed_math as fm  # numba: loaded when first needed
    nq = eq.q.size
    nw, n = scenario["vehicle.n_wheels"], scenario["track.n_links"]
    v = scenario["speed"]
    off = L.pin_offset(nw)
    pins = eq.q[off:off + 2 * n].reshape(n, 2)
    chord = np.roll(pins, -1, axis=0) - np.roll(pins, 1, axis=0)
    rel = v * chord / fm.vhypot(*chord.T)[:, None]
    y0[nq + off:nq + off + 2 * n] = (rel + [v, 0.0]).ravel()
    g = closed_parts(scenario)[0]
    y0[nq + L.q_sprocket(nw, n)] = -v / g.pitch_radius
    if scenario["drive.kind"] == "speed" and scenario["drive.gain_i"] > 0.0:
        # the controller starts with the torque that held the sprocket in the equilibrium
        y0[2 * nq + L.Y_DRIVE_INTEGRAL] = eq.info["holding_torque"] / scenario["drive.gain_i"]


def bristle_states(scenario: Scenario):
    """How many bristle deflections the run's state holds after its extras: one per free pin
    where the bristle law acts (contact/laws.bristle_active; Model.n_bristles), else none."""
    par = pack(scenario["vehicle"], scenario["track"], scenario["gravity"], scenario["contact"])[0]
    for k, v in soil_par(scenario).items():
        par[k] = v
    if not bristle_active(par):
        return 0
    n = scenario["track.n_links"]
    return n if _closed(scenario) else n - 1


def initial_state(scenario: Scenario, eq):
    """y0 = (q, qd, W, ..., bristles): the equilibrium moving at `speed`, pins nudged if
    asked; every bristle at rest (z = 0: the equilibrium holds the pins without friction)."""
    nq = eq.q.size
    y0 = np.zeros(L.n_state(nq, bristle_states(scenario)))
    y0[:nq] = eq.q
    nw = scenario["vehicle.n_wheels"]
    off = L.pin_offset(nw)
    y0[nq + L.Q_X] = scenario["speed"]
    closed = _closed(scenario)
    end = off + 2 * scenario["track.n_links"] if closed else nq
    if closed:
        _closed_velocities(scenario, eq, y0)
    else:
        y0[nq + off:2 * nq:2] = scenario["speed"]
    if scenario["perturbation"] > 0.0:
        rng = np.random.default_rng(scenario["seed"])
        y0[off:end] += scenario["perturbation"] * rng.uniform(-1.0, 1.0, end - off)
    return y0


RUT_CELL = 0.01          # m: the soil's memory, one value per cell along x
RUT_CELLS_MAX = 2_000_000


def soil_par(scenario):
    """{P_* index: value} of the scenario's soft soil, {} on rigid ground."""
    from trackbench.model.core import fixed_math as fm  # numba: loaded when first needed
    from trackbench.model.ground.soil import resolve_soil
    soil = resolve_soil(scenario["terrain"].get("soil", "rigid"))
    if soil is None:
        return {}
    b = scenario["track.width"]
    area = b * scenario["track.link_length"]
    return {
        L.P_SOIL: 1.0,
        L.P_SOIL_N: soil["n"],
        L.P_SOIL_K: soil["k_c"] / b + soil["k_phi"],
        L.P_SOIL_KE: soil["unloading_stiffness"],
        L.P_PIN_AREA: area,
        L.P_SOIL_COHESION: soil["cohesion"] * area,
        L.P_SOIL_TAN_PHI: float(fm.vtan(np.radians(soil["friction_angle"]))),
        L.P_SOIL_SHEAR_K: soil["shear_modulus"],
    }


def _soil(scenario, eq, par):
    """Soft soil's values into par and its memory cells, over where the track can go in the
    run; None on rigid ground."""
    values = soil_par(scenario)
    if not values:
        return None
    for k, v in values.items():
        par[k] = v
    x = eq.info["pins"][:, 0]
    reach = abs(scenario["speed"]) * scenario["duration"] * 2.0 + 5.0
    lo, hi = x.min() - reach, x.max() + reach
    dx = max(RUT_CELL, (hi - lo) / RUT_CELLS_MAX)
    par[L.P_RUT_X0] = lo
    par[L.P_RUT_DX] = dx
    return np.zeros(int(np.ceil((hi - lo) / dx)))


class Model:
    """One scenario's vehicle and ground as the compiled kernels take them: the bundles
    of model/bundles.py, and the sizes and figures the Python side needs."""

    def __init__(self, scenario: Scenario, eq, ground):
        v, tr = scenario["vehicle"], scenario["track"]
        par, piv, ends = pack(v, tr, scenario["gravity"], scenario["contact"])
        self.nw = int(v["n_wheels"])
        self.n_links = int(tr["n_links"])
        arms = arm_table(piv, eq.phi0, arm_damping(v), station_columns(v, tr))
        parts = closed_parts(scenario)
        self.closed_parts = parts   # (geometry, LP_* vector, guide table) of the closed layout, or None
        self.closed = parts is not None
        loop, guides = (parts[1], parts[2]) if self.closed else (None, None)
        rut = _soil(scenario, eq, par)
        self.arrays = model_arrays(
            par, arms, ends, ground.segments, ground.corners, self.n_links, loop, guides, rut
        )
        self.work = work_arrays(self.arrays, self.nw, self.n_links, at_rest=False)
        self.weight = eq.weight if self.closed else total_mass(v, tr) * scenario["gravity"]
        self.nq = int(self.arrays.pins[L.PN_NQ])
        self.ny = int(self.arrays.pins[L.PN_NY])   # the state's length
        # bristle deflections after the extras of y (indices.bristle_state), 0 unless the bristle law acts
        self.n_bristles = self.ny - L.n_state(self.nq)

    @property
    def has_bristles(self):
        """The state holds a bristle deflection per free pin (contact.friction_law = "bristle")."""
        return self.n_bristles > 0

    @property
    def par(self):
        return self.arrays.par

    @property
    def arms(self):
        return self.arrays.arms

    @property
    def ends(self):
        return self.arrays.ends

    @property
    def neighbour_rebuilds(self):
        return int(self.arrays.counters[L.C_REBUILDS])
