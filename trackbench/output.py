"""Solver result -> xarray.Dataset (every variable documented in results_schema.md),
and an atomic netCDF writer."""

import json
from pathlib import Path

import numpy as np
import xarray as xr

from .atomic import atomic_path
from .model import layout as L
from .model.energy import paper_balance, work_residual
from .model.kinematics import place_samples
from .status import Result
from .version import MODEL_VERSION, __version__, toolchain
from .model import fixed_math as fm



def _var(dims, data, units, long_name, **attrs):
    return xr.Variable(dims, np.asarray(data), {"units": units, "long_name": long_name, **attrs})


T, WH, P, K = ("time",), ("time", "wheel"), ("time", "pin"), ("time", "link")


def _place(model, q):
    """Pins, road wheels (and the closed layout's idler and rollers) of every sample."""
    n, nw, nl = q.shape[0], model.nw, model.n_links
    wheels = np.empty((n, nw, 2))
    q = np.ascontiguousarray(q)
    if model.closed:
        from .model.loop import place_loop_samples
        pins = np.empty((n, nl, 2))
        guides = np.empty((n, model.arrays.guides.shape[0], 2))
        place_loop_samples(q, model.arrays, pins, wheels, guides)
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
        "arm_angle": _var(WH, q[:, L.Q_ARM:L.Q_ARM + nw], "rad",
                          "torsion-bar arm angle phi (pivot to wheel centre) relative to the chassis x axis"),
        "wheel_x": _var(WH, wheels[:, :, 0], "m", "road-wheel centre x"),
        "wheel_y": _var(WH, wheels[:, :, 1], "m", "road-wheel centre y"),
        "wheel_force_x": _var(WH, wheel_f[:, :, 0], "N", "horizontal wheel-track contact force on the wheel"),
        "wheel_force_y": _var(WH, wheel_f[:, :, 1], "N", "vertical wheel-track contact force on the wheel"),
        "ground_force_x": _var(T, d[:, L.D_GROUND_FX], "N", "total horizontal ground force on the track"),
        "ground_force_y": _var(T, d[:, L.D_GROUND_FY], "N", "total vertical ground force on the track"),
        "obstacle_force": _var(T, d[:, L.D_CORNER_FORCE], "N", "sum of the ground-corner contact forces"),
        "pin_x": _var(P, pins[:, :, 0], "m", "track pin x (paper's layout: pins 0 and last fixed to the chassis)"),
        "pin_y": _var(P, pins[:, :, 1], "m", "track pin y"),
        "link_tension": _var(K, d[:, L.diag_tension(nw):L.diag_tension(nw) + nl], "N",
                             "link tension, Eq. (8) (with the link dashpot if any); negative is compression"),
    }


def _energies(result, nq):
    """The paper's balance and the work-based residual (model/energy.py), relative to E0."""
    d, y = result.diag, result.y
    work, dissipated = y[:, 2 * nq + L.Y_WORK], y[:, 2 * nq + L.Y_DISSIPATED]
    kin, tors, tens = d[:, L.D_E_KINETIC], d[:, L.D_E_TORSION], d[:, L.D_E_TENSION]
    grav = d[:, L.D_E_GRAVITY] - d[0, L.D_E_GRAVITY]
    e0 = result.stats[L.S_E0]
    balance = paper_balance(kin, tors, tens, d[:, L.D_E_PAD_WHEEL], d[:, L.D_E_PAD_GROUND], grav)
    residual = work_residual(kin, tors, tens, grav, work)
    return {
        "energy_kinetic": _var(T, kin, "J", "kinetic energy"),
        "energy_elastic": _var(T, tors + tens + d[:, L.D_E_PAD_WHEEL] + d[:, L.D_E_PAD_GROUND], "J",
                               "elastic energy: torsion bars, links, wheel and ground pads"),
        "energy_gravity": _var(T, grav, "J", "gravity potential relative to t = 0"),
        "energy_balance": _var(T, balance, "J", "paper's energy balance: kinetic + elastic + gravity potential"),
        "energy_balance_error": _var(T, (balance - balance[0]) / e0, "1",
                                     "energy balance deviation relative to the initial total energy"),
        "contact_work": _var(T, work, "J", "work done by all contact forces and dampers since t = 0"),
        "energy_dissipated": _var(T, dissipated, "J", "energy dissipated by all dampers since t = 0 (contact "
                                  "damping, link dashpots, shock absorbers) and ground friction; 0 in "
                                  "the paper's model"),
        "energy_residual": _var(T, (residual - residual[0]) / e0, "1",
                                "work-based residual: kinetic + torsion + tension + gravity - work of the "
                                "contact forces and dampers, change since t = 0 relative to the initial total "
                                "energy"),
    }


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
    ("first_contact_time", L.PK_FIRST_OBSTACLE, "first accepted step with the track touching an obstacle (its "
     "face, corner or top: any ground feature after the first segment)"),
    ("first_corner_contact_time", L.PK_FIRST_CORNER, "first accepted step with a ground corner touching the track"),
    ("first_compression_time", L.PK_FIRST_COMPRESSION, "first time a link goes into compression (linear between "
     "steps) (after it the motion is sensitive, see results_schema.md)"),
]


def _span_links(on_teeth, mid_y):
    """Per sample, the links of the upper and the lower span one link away from the sprocket:
    the link after the one from the last pin that can touch the teeth (that one's pull still
    depends on where its pin sits on a flank). Pins in array order; link b joins pins[b - 1]
    and pins[b] (link 0: the last pin and the first). -1 where the loop does not leave the
    teeth at exactly two places. Whole arrays at once: a loop over 5001 samples took 0.3 s."""
    n = on_teeth.shape[1]
    before = np.roll(on_teeth, 1, axis=1)                 # t[b - 1]
    change = before != on_teeth
    two = change.sum(axis=1) == 2
    ends = np.argsort(~change, axis=1, kind="stable")[:, :2]   # the two changes, in pin order
    rows = np.arange(on_teeth.shape[0])[:, None]
    spans = np.where(before[rows, ends], (ends + 1) % n, (ends - 1) % n)   # one link further away
    m = mid_y[rows, spans]
    # the upper span first; argmax's choice on ties and NaN: the first unless only it is NaN
    up = (m[:, 1] > m[:, 0]) | (np.isnan(m[:, 1]) & ~np.isnan(m[:, 0]))
    out = np.where(up[:, None], spans[:, ::-1], spans)
    out[~two] = -1
    return out


def _span_tensions(model, q, pins, tension, g):
    """Tension of the upper and of the lower span where they leave the sprocket (_span_links;
    NaN where the loop does not leave the teeth at exactly two places)."""
    c, s = fm.vcos(q[:, L.Q_PITCH]), fm.vsin(q[:, L.Q_PITCH])
    sx, sy = g.sprocket
    ax = q[:, L.Q_X] + c * sx - s * sy
    ay = q[:, L.Q_Y] + s * sx + c * sy
    r = fm.vhypot(pins[:, :, 0] - ax[:, None], pins[:, :, 1] - ay[:, None])
    on_teeth = r < g.tip_radius + model.arrays.loop[L.LP_PIN_RADIUS]
    mid_y = 0.5 * (pins[:, :, 1] + np.roll(pins[:, :, 1], 1, axis=1))
    links = _span_links(on_teeth, mid_y)
    rows = np.arange(len(q))[:, None]
    out = np.where(links >= 0, tension[rows, np.maximum(links, 0)], np.nan)
    return out


def _closed_layout(model, result, scenario, placed):
    """The closed layout's own variables: sprocket, idler, drive, span tensions."""
    from .assembly import closed_parts
    g = closed_parts(scenario)[0]
    nw, nl, nq = model.nw, model.n_links, model.nq
    q, qd, d, y = result.y[:, :nq], result.y[:, nq:2 * nq], result.diag, result.y
    i_s, i_i = L.q_sprocket(nw, nl), L.q_idler(nw, nl)
    pins, _, guides = placed
    tension = d[:, L.diag_tension(nw):L.diag_tension(nw) + nl]
    pk = result.peaks
    spans = _span_tensions(model, q, pins, tension, g)
    v = {
        "sprocket_angle": _var(T, -q[:, i_s], "rad", "sprocket angle relative to the chassis, forward (clockwise) positive"),
        "sprocket_speed": _var(T, -qd[:, i_s], "rad s-1", "sprocket speed relative to the chassis, forward positive"),
        "sprocket_torque": _var(T, d[:, L.D_DRIVE_TORQUE], "N m", "drive torque on the sprocket, forward positive"),
        "teeth_torque": _var(T, d[:, L.D_TEETH_TORQUE], "N m",
                             "torque of the track pins on the sprocket teeth about its axis, forward positive"),
        "idler_position": _var(T, q[:, i_i], "m", "idler carrier's slide along its guide from its middle, outward "
                               "positive"),
        "idler_force": _var(T, d[:, L.D_IDLER_FORCE], "N", "tensioner force on the idler carrier along its guide, "
                            "outward positive"),
        "idler_x": _var(T, guides[:, 0, 0], "m", "idler centre x"),
        "idler_y": _var(T, guides[:, 0, 1], "m", "idler centre y"),
        "drive_work": _var(T, y[:, 2 * nq + L.Y_DRIVE_WORK], "J", "work done by the drive on the sprocket since t = 0"),
        "drawbar_load": _var(T, d[:, L.D_DRAWBAR], "N", "force of the drawbar (constant load and towing rig) on the "
                             "chassis, rearward positive"),
        "upper_span_tension": _var(T, spans[:, 0], "N", "tension of the upper span where it leaves the sprocket "
                                   "(the second link from the last pin on the teeth)"),
        "lower_span_tension": _var(T, spans[:, 1], "N", "tension of the lower span where it leaves the sprocket"),
        "peak_sprocket_torque": _var((), pk[L.PK_DRIVE_TORQUE, 0], "N m", "max drive torque over all accepted steps"),
        "peak_sprocket_torque_time": _var((), pk[L.PK_DRIVE_TORQUE, 1], "s", "time of peak_sprocket_torque"),
        "peak_idler_force": _var((), pk[L.PK_IDLER_FORCE, 0], "N", "max tensioner force over all accepted steps"),
        "peak_idler_force_time": _var((), pk[L.PK_IDLER_FORCE, 1], "s", "time of peak_idler_force"),
    }
    return v


def _soil(model, result, ground, placed):
    """Soft soil: each pin's sinkage below the soil surface (the ground's profile, along the
    normal of the segment under it), the rut at the end of the run (the plastic sinkage each
    cell of the soil's memory keeps)."""
    par, rut = model.par, model.arrays.rut
    nq = model.nq
    qd, d = result.y[:, nq:2 * nq], result.diag
    pins, _, _ = placed
    px, py = pins[:, :, 0], pins[:, :, 1]
    seg = ground.segments
    k = np.clip(np.searchsorted(seg[:, L.SEG_X0], px, side="right") - 1, 0, len(seg) - 1)
    s = (px - seg[k, L.SEG_X0]) * seg[k, L.SEG_NX] + (py - seg[k, L.SEG_Y0]) * seg[k, L.SEG_NY]
    sink = np.maximum(par[L.P_PAD_GROUND] - s, 0.0)
    x = par[L.P_RUT_X0] + (np.arange(rut.size) + 0.5) * par[L.P_RUT_DX]
    plastic = np.maximum(rut - par[L.P_SOIL_K] * fm.vpow(rut, par[L.P_SOIL_N]) / par[L.P_SOIL_KE], 0.0)
    used = np.flatnonzero(rut > 0.0)
    lo, hi = (used[0], used[-1] + 1) if used.size else (0, 0)
    pull = d[:, L.D_GROUND_FX]
    late = result.time >= 0.5 * result.time[-1]     # the run's second half (quantities.py, "mean")
    deepest = np.unravel_index(np.argmax(sink), sink.shape)[0]
    v = {"drawbar_pull": _var(T, pull, "N", "net horizontal force of the ground (soil shear and "
                              "pressure) on the track: thrust minus the soil's resistance"),
         # the memory keeps the deepest sinkage of every accepted step; its time: the deepest sample's
         "peak_sinkage": _var((), float(rut.max(initial=0.0)), "m", "deepest sinkage into the soil over all "
                              "accepted steps"),
         "peak_sinkage_time": _var((), float(result.time[deepest]), "s", "time of the deepest sinkage among the "
                                   "output samples"),
         "mean_drawbar_pull": _var((), float(pull[late].mean()), "N", "drawbar_pull, mean over the run's "
                                   "second half")}
    if model.closed:
        track = -qd[:, L.q_sprocket(model.nw, model.n_links)] * model.arrays.loop[L.LP_PITCH_RADIUS]
        from .traction import mean_slip, slip
        v["slip"] = _var(T, slip(qd[:, L.Q_X], track), "1", "slip: 1 - chassis speed / (sprocket speed x pitch radius)")
        v["mean_slip"] = _var((), mean_slip(qd[late, L.Q_X], track[late]), "1", "slip over the run's second half: "
                              "1 - distance travelled / track laid by the sprocket")
    return {**v, "sinkage": _var(P, sink, "m", "pin's sinkage below the soil surface (0 off the soil)"),
            "rut_depth": _var(("rut_x",), plastic[lo:hi], "m", "plastic sinkage the soil keeps at the end of "
                              "the run (the rut), along x"),
            "rut_max_sinkage": _var(("rut_x",), rut[lo:hi], "m", "deepest sinkage reached, along x")}, x[lo:hi]


def _closed_attrs(scenario):
    from .assembly import closed_parts
    g, lp, guides = closed_parts(scenario)
    return {"track_layout": "closed", "closed_layout": json.dumps({
        "sprocket": g.sprocket.tolist(), "teeth": int(lp[L.LP_TEETH]), "pitch_radius": g.pitch_radius,
        "seat_radius": lp[L.LP_SEAT_RADIUS], "pin_radius": lp[L.LP_PIN_RADIUS], "tip_radius": g.tip_radius,
        "flank_angle": scenario["sprocket.flank_angle"],
        "idler": g.idler.tolist(), "guide": g.guide.tolist(), "travel": lp[L.LP_TRAVEL],
        "idler_radius": scenario["idler.radius"], "rollers": guides[1:, :2].tolist(),
        "roller_radius": scenario["rollers.radius"]})}


def _peaks(pk, nw, e0):
    v = {"peak_wheel_force_y": _var(("wheel",), pk[L.PK_WHEEL_FY:L.PK_WHEEL_FY + nw, 0], "N",
                                    "max vertical wheel-track force over all accepted steps"),
         "peak_wheel_force_y_time": _var(("wheel",), pk[L.PK_WHEEL_FY:L.PK_WHEEL_FY + nw, 1], "s",
                                         "time of peak_wheel_force_y")}
    for name, row, units, text, relative in _SCALAR_PEAKS:
        v[name] = _var((), pk[row, 0] * (1 / e0 if relative else 1.0), units, text + " over all accepted steps")
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
        "method": scenario["method"] if scenario["solver"] == "reduced" else "lee-rkn",
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
        "ground_vertices": json.dumps(np.round(ground.vertices, 12).tolist()),
        "equilibrium": json.dumps(eq.summary()),
        "arm_pivots": json.dumps(model.arms[:, [L.ARMS_PX, L.ARMS_PY]].tolist()),
        "track_ends": json.dumps(model.ends.tolist()),
        "wheel_radius": float(model.par[L.P_WHEEL_RADIUS]),
        "arm_length": float(model.par[L.P_ARM_LENGTH]),
        "pad_wheel": float(model.par[L.P_PAD_WHEEL]),
        "pad_ground": float(model.par[L.P_PAD_GROUND]),
    }


def build_dataset(scenario, model, eq, ground, resolved, result, wall_time, solve_time):
    """The Dataset of one run. Solvers hand over arrays; solver-specific ones come in
    result.extra as (dims, data, units, long_name)."""
    nw, nl = model.nw, model.n_links
    placed = _place(model, result.y[:, :model.nq])
    v = _motion(model, result, placed)
    v.update(_energies(result, model.nq))
    v.update(_peaks(result.peaks, nw, result.stats[L.S_E0]))
    if model.closed:
        v.update(_closed_layout(model, result, scenario, placed))
    rut_x = None
    if model.par[L.P_SOIL] != 0.0:
        soil_vars, rut_x = _soil(model, result, ground, placed)
        v.update(soil_vars)
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
        coords["pin"] = _var(("pin",), np.arange(1, nl + 1), "1", "track pin number, clockwise from the front "
                             "of the ground run")
        coords["link"] = _var(("link",), np.arange(nl), "1", "track link number (joins pins b and b+1; link 0 "
                              "joins the last pin and pin 1)")
        attrs.update(_closed_attrs(scenario))
    if rut_x is not None:
        coords["rut_x"] = _var(("rut_x",), rut_x, "m", "x of the soil's memory cells (centres)")
    return xr.Dataset(v, coords=coords, attrs=attrs)


def write_netcdf(ds, path, storage="full"):
    """Write atomically (trackbench/atomic.py): ``storage`` "full" (lossless, zstd) or
    "compact" (time histories at a stated resolution), see trackbench/storage.py."""
    from .storage import check_storage, write
    check_storage(storage)
    path = Path(path)
    with atomic_path(path) as tmp:
        write(ds, tmp, storage)
    return path


def summary_numbers(ds):
    """The one-screen summary of a run, as a dict of plain numbers in display units
    (keys from the summary table, quantities.py)."""
    from .quantities import entries
    out = {"status": ds.attrs["status"]}
    for q, column, value, _ in entries(ds):
        out[q.display_key(column)] = q.display(value)
    out["steps"] = ds.attrs["steps"]
    out["wall_time"] = ds.attrs["wall_time"]
    return out
