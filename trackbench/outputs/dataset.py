"""Solver result -> xarray.Dataset (every variable documented in results_schema.md),
and an atomic netCDF writer."""

import json

import numpy as np
import xarray as xr

from trackbench.model.core import indices as L
from trackbench.model.dynamics.energy import paper_balance, work_residual
from trackbench.model.vehicle.kinematics import place_samples
from trackbench.outputs.closed import closed_attrs, closed_layout_vars, soil_vars
from trackbench.outputs.variables import WH, K, P, T
from trackbench.outputs.variables import var as _var
from trackbench.solvers.base import n_samples
from trackbench.solvers.registry import SOLVERS
from trackbench.status import Result
from trackbench.version import MODEL_VERSION, __version__, toolchain


def _place(model, q):
    """Pins, road wheels (and the closed layout's idler and rollers) of every sample."""
    n, nw, nl = q.shape[0], model.nw, model.n_links
    wheels = np.empty((n, nw, 2))
    q = np.ascontiguousarray(q)
    if model.closed:
        from trackbench.model.dynamics.closed_track_jit import place_closed_samples
        pins = np.empty((n, nl, 2))
        guides = np.empty((n, model.arrays.guides.shape[0], 2))
        place_closed_samples(q, model.arrays, pins, wheels, guides)
        return pins, wheels, guides
    pins = np.empty((n, nl + 1, 2))
    place_samples(q, model.par, model.arms, model.ends, pins, wheels)
    return pins, wheels, None


def _motion(model, result, placed):
    """Chassis, arms, wheels and pins (placed: _place's, the kernels' own kinematics)."""
    nw, nl, n = model.nw, model.n_links, len(result.time)
    nq = model.nq
    q, qd, d = result.y[:, :nq], result.y[:, nq:2 * nq], result.diag
    pins, wheels, _ = placed
    wheel_f = d[:, L.D_WHEEL:L.D_WHEEL + 2 * nw].reshape(n, nw, 2)
    return {
        "chassis_x": _var(T, q[:, L.Q_X], "m", "chassis mass-centre x"),
        "chassis_y": _var(T, q[:, L.Q_Y], "m", "chassis mass-centre height"),
        "chassis_pitch": _var(T, q[:, L.Q_PITCH], "rad", "chassis pitch, positive raises the front"),
        "chassis_vx": _var(T, qd[:, L.Q_X], "m s-1", "chassis mass-centre horizontal velocity"),
        "chassis_vy": _var(T, qd[:, L.Q_Y], "m s-1", "chassis mass-centre vertical velocity"),
        "chassis_ax": _var(T, d[:, L.D_CHASSIS_AX], "m s-2", "chassis mass-centre horizontal acceleration"),
        "chassis_ay": _var(T, d[:, L.D_CHASSIS_AY], "m s-2", "chassis mass-centre vertical acceleration"),
        "chassis_pitch_rate": _var(T, qd[:, L.Q_PITCH], "rad s-1", "chassis pitch rate"),
        "chassis_pitch_acceleration": _var(
            T, d[:, L.D_CHASSIS_ALPHA], "rad s-2", "chassis pitch acceleration"
        ),
        "arm_angle": _var(
            WH,
            q[:, L.Q_ARM : L.Q_ARM + nw],
            "rad",
            "torsion-bar arm angle phi (pivot to wheel centre) relative to the chassis x axis",
        ),
        "wheel_x": _var(WH, wheels[:, :, 0], "m", "road-wheel centre x"),
        "wheel_y": _var(WH, wheels[:, :, 1], "m", "road-wheel centre y"),
        "wheel_force_x": _var(WH, wheel_f[:, :, 0], "N", "horizontal wheel-track contact force on the wheel"),
        "wheel_force_y": _var(WH, wheel_f[:, :, 1], "N", "vertical wheel-track contact force on the wheel"),
        "ground_force_x": _var(T, d[:, L.D_GROUND_FX], "N", "total horizontal ground force on the track"),
        "ground_force_y": _var(T, d[:, L.D_GROUND_FY], "N", "total vertical ground force on the track"),
        "obstacle_force": _var(T, d[:, L.D_CORNER_FORCE], "N", "sum of the ground-corner contact forces"),
        "pin_x": _var(
            P, pins[:, :, 0], "m", "track pin x (paper's layout: pins 0 and last fixed to the chassis)"
        ),
        "pin_y": _var(P, pins[:, :, 1], "m", "track pin y"),
        "link_tension": _var(
            K,
            d[:, L.diag_tension(nw) : L.diag_tension(nw) + nl],
            "N",
            "link tension, Eq. (8) (with the link dashpot if any); negative is compression",
        ),
    }


def _seat(scenario, result, nq):
    """The driver's seat's vertical acceleration at the samples (ride_metrics.seat_acceleration)."""
    from trackbench.outputs.metrics.ride import seat_acceleration

    q, qd, d = result.y[:, :nq], result.y[:, nq:2 * nq], result.diag
    v = scenario["vehicle"]
    a = seat_acceleration(d[:, L.D_CHASSIS_AY], d[:, L.D_CHASSIS_ALPHA], qd[:, L.Q_PITCH],
                          v["seat_x"], v["seat_y"], q[:, L.Q_PITCH])
    text = "the seat's (vehicle.seat_x, seat_y) vertical acceleration, gravity not included"
    return {"seat_acceleration_y": _var(T, np.asarray(a), "m s-2", text)}


def ride_variables(scenario, a, time):
    """The ride metrics of the seat's acceleration a at the sample times (ride_metrics.py;
    results_schema.md says over which samples): over the whole run, so a run written chunk by
    chunk (stream.py) gives them its whole history. NaN where they cannot be had: samples
    more than 1/250 s apart (the weightings reach 100 Hz), fewer than two, or not finite (a
    failed run)."""
    from trackbench.outputs.metrics.ride import MIN_RATE, SECOND_HALF, ride_figures

    dt = scenario["output_interval"]
    nan = float("nan")
    names = ("peak_seat_acceleration_g", *SECOND_HALF)
    fig = dict.fromkeys(names, nan)
    peak_time = nan
    if dt <= 1.0 / MIN_RATE and a.shape[0] >= 2 and np.isfinite(a).all():
        # the second half of the run's samples (a chunk of a streamed run, stream.py, has the
        # run's first sample in front and its own figures are not kept); of a run that stopped
        # early, the second half it was to have: its figures are then the least the whole
        # run's could be (ride_figures)
        n = max(a.shape[0], n_samples(scenario["duration"], dt))
        fig = ride_figures(a, dt, 0.5 * ((n - 1) * dt), n)
        peak_time = float(time[fig.pop("peak_index")])
    return {
        "peak_seat_acceleration_g": _var((), fig["peak_seat_acceleration_g"], "1",
                                         "max |seat acceleration| after a 30 Hz low-pass, in g"),
        "peak_seat_acceleration_g_time": _var((), peak_time, "s", "time of peak_seat_acceleration_g"),
        "absorbed_power": _var((), fig["absorbed_power"], "W",
                               "vertical absorbed power at the seat (Pradko and Lee), 2nd half"),
        "weighted_rms_acceleration": _var((), fig["weighted_rms_acceleration"], "m s-2",
                                          "ISO 2631-1 Wk-weighted RMS seat acceleration, 2nd half"),
        "vdv": _var((), fig["vdv"], "m s-1.75", "vibration dose value (Wk-weighted), 2nd half"),
    }


def _energies(result, nq):
    """The paper's balance and the work-based residual (model/dynamics/energy.py), relative to E0."""
    d, y = result.diag, result.y
    work, dissipated = y[:, 2 * nq + L.Y_WORK], y[:, 2 * nq + L.Y_DISSIPATED]
    kin, tors, tens = d[:, L.D_E_KINETIC], d[:, L.D_E_TORSION], d[:, L.D_E_TENSION]
    grav = d[:, L.D_E_GRAVITY] - d[0, L.D_E_GRAVITY]
    e0 = result.stats[L.S_E0]
    balance = paper_balance(kin, tors, tens, d[:, L.D_E_PAD_WHEEL], d[:, L.D_E_PAD_GROUND], grav)
    residual = work_residual(kin, tors, tens, grav, work)
    return {
        "energy_kinetic": _var(T, kin, "J", "kinetic energy"),
        "energy_elastic": _var(
            T,
            tors + tens + d[:, L.D_E_PAD_WHEEL] + d[:, L.D_E_PAD_GROUND],
            "J",
            "elastic energy: torsion bars, links, wheel and ground pads (and bristles)",
        ),
        "energy_gravity": _var(T, grav, "J", "gravity potential relative to t = 0"),
        "energy_balance": _var(
            T, balance, "J", "paper's energy balance: kinetic + elastic + gravity potential"
        ),
        "energy_balance_error": _var(
            T,
            (balance - balance[0]) / e0,
            "1",
            "energy balance deviation relative to the initial total energy",
        ),
        "contact_work": _var(T, work, "J", "work done by all contact forces and dampers since t = 0"),
        "energy_dissipated": _var(
            T,
            dissipated,
            "J",
            "energy dissipated by all dampers since t = 0 (contact "
            "damping, link dashpots, shock absorbers) and ground friction; 0 in "
            "the paper's model",
        ),
        "energy_residual": _var(
            T,
            (residual - residual[0]) / e0,
            "1",
            "work-based residual: kinetic + torsion + tension + gravity - work of the "
            "contact forces and dampers, change since t = 0 relative to the initial total "
            "energy",
        ),
    }


def _bristles(model, result):
    """The bristle law's deflections (states after y's extras), per pin; NaN for the paper
    layout's track ends, which hold none."""
    first = L.bristle_state(model.nq, 1)
    z = result.y[:, first:first + model.n_bristles]
    if not model.closed:
        z = np.pad(z, ((0, 0), (1, 1)), constant_values=np.nan)
    text = "deflection of the pin's bristle along the ground's tangent (bristle friction law)"
    return {"bristle_deflection": _var(P, z, "m", text)}


_SCALAR_PEAKS = [  # name, peaks row, units, text, divided by E0
    ("peak_ground_force_y", L.PK_GROUND_FY, "N", "max total vertical ground force", False),
    ("peak_link_tension", L.PK_TENSION_MAX, "N", "max link tension", False),
    ("min_link_tension", L.PK_TENSION_MIN, "N", "min link tension", False),
    ("peak_chassis_ay", L.PK_AY_MAX, "m s-2", "max chassis vertical acceleration", False),
    ("min_chassis_ay", L.PK_AY_MIN, "m s-2", "min chassis vertical acceleration", False),
    ("min_chassis_vx", L.PK_VX_MIN, "m s-1", "min chassis horizontal velocity", False),
    ("max_energy_balance_error", L.PK_ENERGY_BALANCE, "1", "max |energy balance deviation| / E0", True),
    ("max_energy_residual", L.PK_ENERGY_RESIDUAL, "1", "max |work-based energy residual| / E0", True),
]
_FIRST_TIMES = [  # name, peaks row, text
    (
        "first_contact_time",
        L.PK_FIRST_OBSTACLE,
        "first accepted step with the track touching an obstacle (its "
        "face, corner or top: any ground feature after the first segment)",
    ),
    (
        "first_corner_contact_time",
        L.PK_FIRST_CORNER,
        "first accepted step with a ground corner touching the track",
    ),
    (
        "first_compression_time",
        L.PK_FIRST_COMPRESSION,
        "first time a link goes into compression (linear between "
        "steps) (after it the motion is sensitive, see results_schema.md)",
    ),
]


def _peaks(pk, nw, e0):
    v = {"peak_wheel_force_y": _var(("wheel",), pk[L.PK_WHEEL_FY:L.PK_WHEEL_FY + nw, 0], "N",
                                    "max vertical wheel-track force over all accepted steps"),
         "peak_wheel_force_y_time": _var(("wheel",), pk[L.PK_WHEEL_FY:L.PK_WHEEL_FY + nw, 1], "s",
                                         "time of peak_wheel_force_y")}
    for name, row, units, text, relative in _SCALAR_PEAKS:
        v[name] = _var(
            (), pk[row, 0] * (1 / e0 if relative else 1.0), units, text + " over all accepted steps"
        )
        v[name + "_time"] = _var((), pk[row, 1], "s", "time of " + name)
    for name, row, text in _FIRST_TIMES:
        v[name] = _var((), pk[row, 1] if pk[row, 0] > 0 else np.nan, "s", text)
    return v


def _attrs(scenario, model, eq, ground, resolved, st, wall_time, solve_time):
    status = Result(int(st[L.S_STATUS]))
    return {
        "Conventions": "CF-1.11",
        "title": f"trackbench run: {scenario.name}",
        "trackbench_version": __version__,
        "model_version": MODEL_VERSION,
        "toolchain": toolchain(),
        "status": "completed" if status == Result.SUCCESSFUL else "failed",
        "status_code": int(status),
        "status_message": status.message,
        "t_final": float(st[L.S_T_FINAL]),
        "solver": scenario["solver"],
        "method": SOLVERS[scenario["solver"]].method_of(scenario["method"]),
        "tolerance": scenario["tolerance"],
        "steps": int(st[L.S_STEPS]),
        "rejected_steps": int(st[L.S_REJECTED]),
        "rhs_evaluations": int(st[L.S_RHS]),
        "min_step": float(st[L.S_H_MIN]),
        "max_step": float(st[L.S_H_MAX]),
        "neighbour_rebuilds": model.neighbour_rebuilds,
        "wall_time": wall_time,
        "solve_time": solve_time,
        "initial_total_energy": float(st[L.S_E0]),
        "weight": float(model.weight),
        "scenario": json.dumps(scenario.to_dict(), sort_keys=True),
        "terrain_resolved": json.dumps(resolved),
        "equilibrium": json.dumps(eq.summary()),
        "arm_pivots": json.dumps(model.arms[:, [L.ARMS_PX, L.ARMS_PY]].tolist()),
        "track_ends": json.dumps(model.ends.tolist()),
        "wheel_radius": float(model.par[L.P_WHEEL_RADIUS]),
        "arm_length": float(model.par[L.P_ARM_LENGTH]),
        "pad_wheel": float(model.par[L.P_PAD_WHEEL]),
        "pad_ground": float(model.par[L.P_PAD_GROUND]),
        **_station_attrs(model),
    }


def _station_attrs(model):
    """Each road wheel's radius and arm length (JSON lists) where the wheels differ; where they
    are alike, wheel_radius and arm_length say it (and the attributes stay as they were)."""
    out = {}
    for name, col in (("wheel_radii", L.ARMS_RADIUS), ("arm_lengths", L.ARMS_LENGTH)):
        values = model.arms[:, col]
        if np.any(values != values[0]):
            out[name] = json.dumps(values.tolist())
    return out


def build_dataset(scenario, model, eq, ground, resolved, result, wall_time, solve_time):
    """The Dataset of one run. Solvers hand over arrays; solver-specific ones come in
    result.extra as (dims, data, units, long_name)."""
    nw, nl = model.nw, model.n_links
    placed = _place(model, result.y[:, :model.nq])
    v = _motion(model, result, placed)
    v.update(_energies(result, model.nq))
    v.update(_seat(scenario, result, model.nq))
    v.update(ride_variables(scenario, v["seat_acceleration_y"].values, result.time))
    v.update(_peaks(result.peaks, nw, result.stats[L.S_E0]))
    if model.closed:
        v.update(closed_layout_vars(model, result, scenario, placed))
    if model.has_bristles:
        v.update(_bristles(model, result))
    rut_x = None
    if model.par[L.P_SOIL] != 0.0:
        sv, rut_x = soil_vars(model, result, ground, placed)
        v.update(sv)
    for name, (dims, data, units, text) in result.extra.items():
        v[name] = _var(dims, data, units, text)
    coords = {
        "time": _var(T, result.time, "s", "simulated time"),
        "wheel": _var(("wheel",), np.arange(1, nw + 1), "1", "road wheel number, 1 = front"),
        "pin": _var(("pin",), np.arange(nl + 1), "1", "track pin number, 0 = front track end"),
        "link": _var(("link",), np.arange(nl), "1", "track link number (joins pins b and b+1)"),
    }
    attrs = _attrs(scenario, model, eq, ground, resolved, result.stats, wall_time, solve_time)
    if model.closed:
        coords["pin"] = _var(
            ("pin",),
            np.arange(1, nl + 1),
            "1",
            "track pin number, clockwise from the front of the ground run",
        )
        coords["link"] = _var(
            ("link",),
            np.arange(nl),
            "1",
            "track link number (joins pins b and b+1; link 0 joins the last pin and pin 1)",
        )
        attrs.update(closed_attrs(scenario, model))
    gv = ("ground_vertex",)
    v["ground_x"] = _var(gv, ground.vertices[:, 0], "m", "x of the ground polyline's vertices")
    v["ground_y"] = _var(gv, ground.vertices[:, 1], "m", "height of the ground polyline's vertices")
    if rut_x is not None:
        coords["rut_x"] = _var(("rut_x",), rut_x, "m", "x of the soil's memory cells (centres)")
    return xr.Dataset(v, coords=coords, attrs=attrs)


def summary_numbers(ds):
    """The one-screen summary of a run, as a dict of plain numbers in display units
    (keys from the summary table, quantities.py)."""
    from trackbench.outputs.quantities import entries
    out = {"status": ds.attrs["status"]}
    for q, column, value, _ in entries(ds):
        out[q.display_key(column)] = q.display(value)
    out["steps"] = ds.attrs["steps"]
    out["wall_time"] = ds.attrs["wall_time"]
    return out
