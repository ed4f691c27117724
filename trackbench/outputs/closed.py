"""The closed track's and the soft soil's output variables (results_schema.md): the spans'
tensions, the sprocket and idler, the ruts and sinkage; output.py assembles them."""

import json

import numpy as np

from trackbench.model.core import fixed_math as fm
from trackbench.model.core import indices as L
from trackbench.outputs.variables import P, T
from trackbench.outputs.variables import var as _var


def _span_links(on_teeth, mid_y):
    """Per sample, the links of the upper and the lower span one link away from the sprocket:
    the link after the one from the last pin that can touch the teeth (that one's pull still
    depends on where its pin sits on a flank). Pins in array order; link b joins pins[b - 1]
    and pins[b] (link 0: the last pin and the first). -1 where the loop does not leave the
    teeth at exactly two places. Whole arrays at once: a loop over 5001 samples took 0.3 s."""
    n = on_teeth.shape[1]
    before = np.roll(on_teeth, 1, axis=1)  # t[b - 1]
    change = before != on_teeth
    two = change.sum(axis=1) == 2
    ends = np.argsort(~change, axis=1, kind="stable")[:, :2]  # the two changes, in pin order
    rows = np.arange(on_teeth.shape[0])[:, None]
    spans = np.where(before[rows, ends], (ends + 1) % n, (ends - 1) % n)  # one link further away
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


def closed_layout_vars(model, result, scenario, placed):
    """The closed layout's own variables: sprocket, idler, drive, span tensions."""
    g = model.closed_parts[0]
    nw, nl, nq = model.nw, model.n_links, model.nq
    q, qd, d, y = result.y[:, :nq], result.y[:, nq : 2 * nq], result.diag, result.y
    i_s, i_i = L.q_sprocket(nw, nl), L.q_idler(nw, nl)
    pins, _, guides = placed
    tension = d[:, L.diag_tension(nw) : L.diag_tension(nw) + nl]
    pk = result.peaks
    spans = _span_tensions(model, q, pins, tension, g)
    v = {
        "sprocket_angle": _var(
            T, -q[:, i_s], "rad", "sprocket angle relative to the chassis, forward (clockwise) positive"
        ),
        "sprocket_speed": _var(
            T, -qd[:, i_s], "rad s-1", "sprocket speed relative to the chassis, forward positive"
        ),
        "sprocket_torque": _var(
            T, d[:, L.D_DRIVE_TORQUE], "N m", "drive torque on the sprocket, forward positive"
        ),
        "teeth_torque": _var(
            T,
            d[:, L.D_TEETH_TORQUE],
            "N m",
            "torque of the track pins on the sprocket teeth about its axis, forward positive",
        ),
        "idler_position": _var(
            T, q[:, i_i], "m", "idler carrier's slide along its guide from its middle, outward positive"
        ),
        "idler_force": _var(
            T,
            d[:, L.D_IDLER_FORCE],
            "N",
            "tensioner force on the idler carrier along its guide, outward positive",
        ),
        "idler_x": _var(T, guides[:, 0, 0], "m", "idler centre x"),
        "idler_y": _var(T, guides[:, 0, 1], "m", "idler centre y"),
        "drive_work": _var(
            T, y[:, 2 * nq + L.Y_DRIVE_WORK], "J", "work done by the drive on the sprocket since t = 0"
        ),
        "drawbar_load": _var(
            T,
            d[:, L.D_DRAWBAR],
            "N",
            "force of the drawbar (constant load and towing rig) on the chassis, rearward positive",
        ),
        "upper_span_tension": _var(
            T,
            spans[:, 0],
            "N",
            "tension of the upper span where it leaves the sprocket "
            "(the second link from the last pin on the teeth)",
        ),
        "lower_span_tension": _var(
            T, spans[:, 1], "N", "tension of the lower span where it leaves the sprocket"
        ),
        "peak_sprocket_torque": _var(
            (), pk[L.PK_DRIVE_TORQUE, 0], "N m", "max drive torque over all accepted steps"
        ),
        "peak_sprocket_torque_time": _var((), pk[L.PK_DRIVE_TORQUE, 1], "s", "time of peak_sprocket_torque"),
        "peak_idler_force": _var(
            (), pk[L.PK_IDLER_FORCE, 0], "N", "max tensioner force over all accepted steps"
        ),
        "peak_idler_force_time": _var((), pk[L.PK_IDLER_FORCE, 1], "s", "time of peak_idler_force"),
    }
    return v


def soil_vars(model, result, ground, placed):
    """Soft soil: each pin's sinkage below the soil surface (the ground's profile, along the
    normal of the segment under it), the rut at the end of the run (the plastic sinkage each
    cell of the soil's memory keeps)."""
    par, rut = model.par, model.arrays.rut
    nq = model.nq
    qd, d = result.y[:, nq : 2 * nq], result.diag
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
    late = result.time >= 0.5 * result.time[-1]  # the run's second half (quantities.py, "mean")
    deepest = np.unravel_index(np.argmax(sink), sink.shape)[0]
    v = {
        "drawbar_pull": _var(
            T,
            pull,
            "N",
            "net horizontal force of the ground (soil shear and "
            "pressure) on the track: thrust minus the soil's resistance",
        ),
        # the memory keeps the deepest sinkage of every accepted step; its time: the deepest sample's
        "peak_sinkage": _var(
            (), float(rut.max(initial=0.0)), "m", "deepest sinkage into the soil over all accepted steps"
        ),
        "peak_sinkage_time": _var(
            (), float(result.time[deepest]), "s", "time of the deepest sinkage among the output samples"
        ),
        "mean_drawbar_pull": _var(
            (), float(pull[late].mean()), "N", "drawbar_pull, mean over the run's second half"
        ),
    }
    if model.closed:
        track = -qd[:, L.q_sprocket(model.nw, model.n_links)] * model.arrays.loop[L.LP_PITCH_RADIUS]
        from trackbench.outputs.metrics.traction import mean_slip, slip

        v["slip"] = _var(
            T, slip(qd[:, L.Q_X], track), "1", "slip: 1 - chassis speed / (sprocket speed x pitch radius)"
        )
        v["mean_slip"] = _var(
            (),
            mean_slip(qd[late, L.Q_X], track[late]),
            "1",
            "slip over the run's second half: 1 - distance travelled / track laid by the sprocket",
        )
    return {
        **v,
        "sinkage": _var(P, sink, "m", "pin's sinkage below the soil surface (0 off the soil)"),
        "rut_depth": _var(
            ("rut_x",),
            plastic[lo:hi],
            "m",
            "plastic sinkage the soil keeps at the end of the run (the rut), along x",
        ),
        "rut_max_sinkage": _var(("rut_x",), rut[lo:hi], "m", "deepest sinkage reached, along x"),
    }, x[lo:hi]


def closed_attrs(scenario, model):
    g, lp, guides = model.closed_parts
    return {
        "track_layout": "closed",
        "closed_layout": json.dumps(
            {
                "sprocket": g.sprocket.tolist(),
                "teeth": int(lp[L.LP_TEETH]),
                "pitch_radius": g.pitch_radius,
                "seat_radius": lp[L.LP_SEAT_RADIUS],
                "pin_radius": lp[L.LP_PIN_RADIUS],
                "tip_radius": g.tip_radius,
                "flank_angle": scenario["sprocket.flank_angle"],
                "idler": g.idler.tolist(),
                "guide": g.guide.tolist(),
                "travel": lp[L.LP_TRAVEL],
                "idler_radius": scenario["idler.radius"],
                "rollers": guides[1:, :2].tolist(),
                "roller_radius": scenario["rollers.radius"],
            }
        ),
    }
