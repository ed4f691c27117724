"""The recording's text panels (the run's parameters and solver figures) and the viewer's
layout (blueprint): what a user reads beside the side view."""

import json

import numpy as np
import rerun.blueprint as rrb

from trackbench.outputs import geometry as G
from trackbench.outputs.recording.entities import (
    E_AY,
    E_ENERGY,
    E_IDLER_FORCE,
    E_PARAMS,
    E_SEAT,
    E_SOLVER,
    E_SPROCKET_TORQUE,
    E_TENSION,
    E_VX,
    E_WHEEL_FY,
    E_WORLD,
    PLAYBACK_SPEED,
    TIMELINE,
)


def _md_table(rows):
    out = ["| name | value |", "| --- | --- |"]
    out += [f"| {k} | {v} |" for k, v in rows]
    return "\n".join(out)


def _flat(d, prefix=""):
    out = []
    for k, v in d.items():
        if isinstance(v, dict):
            out += _flat(v, prefix + k + ".")
        else:
            out.append((prefix + k, json.dumps(v) if isinstance(v, (list, dict)) else v))
    return out


def parameters_text(ds):
    sc = G.scenario_of(ds)
    extra = G.attr_json(ds, "terrain_resolved") if "terrain_resolved" in ds.attrs else {}
    text = f"# Run parameters: {sc.get('name', '')}\n\n" + _md_table(sorted(_flat(sc)))
    if extra:
        text += "\n\n## Resolved terrain\n\n" + _md_table(sorted(extra.items()))
    return text


def solver_text(ds):
    a = ds.attrs
    keys = (
        "status",
        "status_message",
        "t_final",
        "solver",
        "method",
        "tolerance",
        "steps",
        "rejected_steps",
        "rhs_evaluations",
        "min_step",
        "max_step",
        "neighbour_rebuilds",
        "wall_time",
        "solve_time",
        "initial_total_energy",
        "weight",
        "trackbench_version",
        "model_version",
    )
    rows = [(k, a[k]) for k in keys if k in a]
    from trackbench.outputs.quantities import TABLE

    for q in TABLE:  # every summary quantity, in SI units
        if q.variable not in ds:
            continue
        v, units = ds.variables[q.variable], ds.variables[q.variable].attrs.get("units", "")
        if q.per_wheel:
            t = ds.variables[q.variable + "_time"].values
            rows += [
                (f"{q.variable} wheel {int(w)} ({units})", f"{float(f):.6g} at t = {float(tw):.5f} s")
                for w, f, tw in zip(ds.variables["wheel"].values, v.values, t)
            ]
        else:
            rows.append((f"{q.variable} ({units})", f"{float(v.values):.6g}"))
    text = "# Solver statistics\n\n" + _md_table(rows)
    if "equilibrium" in a:
        text += (
            "\n\n## Initial equilibrium\n\n```json\n"
            + json.dumps(G.attr_json(ds, "equilibrium"), indent=1)
            + "\n```"
        )
    return text


def playback_speed(ds):
    """Real time where the side view is at a screen's frame rate (record.fps: ride runs), else
    PLAYBACK_SPEED, the slow motion that shows an impact frame by frame."""
    rec = G.scenario_of(ds).get("record", {})
    return 1.0 if rec.get("every", 1) == 0 else PLAYBACK_SPEED


def blueprint(ds, follow=False):
    """Side view large on the left; wheel forces, chassis acceleration and velocity on the
    right; energies, link tension and the text documents in tabs below them. A closed-layout
    run adds the drive torque and the tensioner force under the side view, where the
    sprocket and the idler they act on are seen. follow: a long run's side view shows the
    vehicle's surroundings (geometry.follow_window), the world moving under it."""
    x0, x1 = G.covered_x_range(ds)
    ground = G.ground_polyline(ds, (x0, x1))
    top = float(np.nanmax(ds.variables["chassis_y"].values)) + G.HULL_TOP + 0.5
    bottom = float(np.min(ground[:, 1])) - 0.5
    window = G.follow_window(ds) if follow else None
    # following: the root as origin, so that /world's own transform applies
    where = {"origin": "/", "contents": [E_WORLD + "/**"]} if window else {"origin": E_WORLD}
    side = rrb.Spatial2DView(
        name="side view (x forward; up is up)" + (", following the chassis" if window else ""),
        visual_bounds=rrb.VisualBounds2D(x_range=list(window or (x0, x1)), y_range=[-top, -bottom]),
        **where,
    )
    plots = rrb.Vertical(
        rrb.TimeSeriesView(origin=E_WHEEL_FY, name="vertical wheel-track force (N)"),
        rrb.TimeSeriesView(origin=E_AY, name="chassis vertical acceleration (m/s^2)"),
        rrb.TimeSeriesView(origin=E_VX, name="chassis horizontal velocity (m/s)"),
        rrb.Tabs(
            rrb.TimeSeriesView(origin=E_ENERGY, name="energies (J)"),
            rrb.TimeSeriesView(origin=E_SEAT, name="seat vertical acceleration (m/s^2)"),
            rrb.TimeSeriesView(origin=E_TENSION, name="max link tension (N)"),
            rrb.TextDocumentView(origin=E_PARAMS, name="parameters"),
            rrb.TextDocumentView(origin=E_SOLVER, name="solver"),
        ),
    )
    if G.is_closed(ds):
        side = rrb.Vertical(
            side,
            rrb.Horizontal(
                rrb.TimeSeriesView(origin=E_SPROCKET_TORQUE, name="sprocket drive torque (N m)"),
                rrb.TimeSeriesView(origin=E_IDLER_FORCE, name="idler tensioner force (N)"),
            ),
            row_shares=[3, 1],
        )
    return rrb.Blueprint(
        rrb.Horizontal(side, plots, column_shares=[3, 2]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="expanded", timeline=TIMELINE, playback_speed=playback_speed(ds)),
    )
