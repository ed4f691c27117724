"""Study figures: each summary quantity against each grid axis (one line per value of the
other axes, up to a few), and drawbar pull against slip for drawbar studies."""

import json
from pathlib import Path

import numpy as np

from trackbench.figures.plot_common import (
    DPI,
    _parsed,
    _plt,
    _wrap,
    axis_label,
    display_scale,
    manifest,
    value_label,
)
from trackbench.outputs.variables import scenario_of

BOOKKEEPING = {
    "run_id", "status", "status_message", "variant", "replicate", "steps", "rejected_steps",
    "t_final", "wall_time", "solve_time", "recording", "recording_error", "seed"
}


def study_axes(df):
    """Grid axes of a study summary: every column that is neither book-keeping nor a summary
    quantity (trackbench/quantities.py) and takes more than one value."""
    from trackbench.outputs.quantities import quantity_of
    axes = []
    for c in df.columns:
        if c in BOOKKEEPING or quantity_of(c) is not None:
            continue
        if df[c].nunique(dropna=True) > 1:
            axes.append(c)
    return axes


def _wheel_of(column):
    from trackbench.outputs.quantities import BY_NAME
    return BY_NAME["peak_wheel_force_y"].wheel_of(column)


def _wheel_columns(df):
    from trackbench.outputs.quantities import BY_NAME
    wheel = BY_NAME["peak_wheel_force_y"]
    return sorted(wheel.present(df.columns), key=wheel.wheel_of)


def _find_summary(study_dir):
    p = Path(study_dir)
    if p.is_file() and p.suffix == ".toml":
        from trackbench.study.read.folder import study_output
        p = study_output(p)
    if p.is_file() and p.name.startswith("summary"):
        return p
    for name in ("summary.csv", "summary.parquet"):
        if (p / name).exists():
            return p / name
    raise FileNotFoundError(f"{study_dir}: no summary.csv (run `trackbench study run` first)")


MAX_LINES = 6        # one line per value of the other axes up to this many, else the median
_STYLES = [
    ("-", "o"),
    ("--", "s"),
    (":", "^"),
    ("-.", "D"),
    ((0, (5, 1, 1, 1, 1, 1)), "v"),
    ((0, (1, 3)), "P"),
]


def _study_name(src):
    """The study's own name (runs.json), not its results folder's, which --output may have set."""
    return manifest(src).get("name") or src.parent.name


def _run_scenarios(src):
    """run id -> resolved scenario, from the study's runs.json ({} without one)."""
    runs = manifest(src).get("runs") or []
    return {str(r.get("run_id")): r.get("scenario") or {} for r in runs}


def _axis_column(df, axis, src):
    """The axis's values per run; a terrain axis takes each run's terrain from runs.json where
    the grid left it out (the base scenario's terrain), so every run gets a label."""
    col = df[axis]
    if axis == "terrain" and col.isna().any() and "run_id" in df:
        scen = _run_scenarios(src)
        base = df["run_id"].astype(str).map(lambda r: json.dumps(scen[r]["terrain"], sort_keys=True)
                                            if "terrain" in scen.get(r, {}) else None)
        col = col.where(col.notna(), base)
    return col


def _category_key(v):
    p = _parsed(v)
    if isinstance(p, dict):
        return (
            str(p.get("kind", "")),
            float(p.get("height", 0.0) or 0.0),
            float(p.get("length", 0.0) or 0.0),
            "",
        )
    return ("", 0.0, 0.0, str(v))


def _groups(df, others, xs):
    """[(label, row mask)]: one group per combination of the other axes' values when some x
    holds runs of several combinations and there are at most MAX_LINES of them; else one
    group of every run (label None)."""
    import pandas as pd
    if not others:
        return [(None, np.ones(len(df), bool))], False
    key = (
        df[others]
        .astype(object)
        .where(df[others].notna(), None)
        .apply(
            lambda r: json.dumps([None if v is None else (v if isinstance(v, str) else float(v)) for v in r]),
            axis=1,
        )
    )
    valid = np.isfinite(xs)
    mixed = (
        pd.Series(key[valid].to_numpy()).groupby(xs[valid]).nunique().gt(1).any() if valid.any() else False
    )
    combos = sorted(key[valid].unique(), key=lambda k: [_category_key(v) if isinstance(v, str) else
                                                         ("", -np.inf if v is None else v, 0.0, "")
                                                         for v in json.loads(k)])
    if not mixed:
        return [(None, np.ones(len(df), bool))], False
    if len(combos) > MAX_LINES:
        return [(None, np.ones(len(df), bool))], True
    out = []
    for k in combos:
        vals = json.loads(k)
        label = (
            ", ".join(f"{a} {value_label(a, v)}" for a, v in zip(others, vals) if v is not None) or "others"
        )
        out.append((label, (key == k).to_numpy()))
    return out, False


def _x_of(df, axis, src):
    """(column, numeric, x of every run, the x values in order, the categories or None): a
    numeric axis in its display scale, a categorical one (terrain tables) at 0, 1, ..."""
    import pandas as pd
    col = _axis_column(df, axis, src)
    if pd.api.types.is_numeric_dtype(col):
        scale, _ = display_scale(axis, col.dropna().to_numpy())
        x_all = col.astype(float).to_numpy() * scale
        return col, True, x_all, np.unique(x_all[np.isfinite(x_all)]), None
    raw = sorted(col.dropna().unique(), key=_category_key)
    where = {v: k for k, v in enumerate(raw)}
    return col, False, col.map(where).astype(float).to_numpy(), np.arange(len(raw), dtype=float), raw


def _draw_panel(ax, df, cols, per_unit, groups, x_all, order, status):
    """Each column's runs as points and, per group, the line through the medians at each x;
    failed runs as red crosses on the axis, runs not run yet as grey rings there."""
    completed = status == "completed"
    for k, c in enumerate(cols):
        y = df[c].astype(float).to_numpy() / per_unit
        label = (
            f"wheel {_wheel_of(c)}"
            if _wheel_of(c) is not None
            else c.replace("peak_", "peak ").replace("_", " ")
        )
        for gi, (glabel, mask) in enumerate(groups):
            ls, marker = _STYLES[gi % len(_STYLES)] if glabel else ("-", "o")
            m = mask & completed & np.isfinite(x_all)
            ax.plot(x_all[m], y[m], marker, ls="none", color=f"C{k}", ms=4, alpha=0.6)
            med = np.array(
                [np.nanmedian(y[m][x_all[m] == v]) if np.any(x_all[m] == v) else np.nan for v in order]
            )
            fin = np.isfinite(med)
            ax.plot(order[fin], med[fin], ls=ls, color=f"C{k}", lw=1.3, label=label if gi == 0 else None)
    bad = (status == "failed") & np.isfinite(x_all)
    if bad.any():
        ax.plot(x_all[bad], np.zeros(int(bad.sum())), "x", color="red", ms=8, mew=2,
                label=f"failed run ({int(bad.sum())})", clip_on=False)
    todo = ~completed & (status != "failed") & np.isfinite(x_all)
    if todo.any():
        ax.plot(x_all[todo], np.zeros(int(todo.sum())), "o", mfc="none", color="0.5", ms=7,
                label=f"not run yet ({int(todo.sum())})", clip_on=False)
    ax.grid(True, alpha=0.3)


def _legend(ax, groups, plt):
    """One legend: colours are the quantities; with groups, line styles and markers the other
    axes' values (outside the panel: the layout makes room for it)."""
    if not groups[0][0]:
        ax.legend(fontsize=8, ncol=2)
        return
    handles, labels = ax.get_legend_handles_labels()
    handles += [plt.Line2D([], [], ls="none")] + [
        plt.Line2D(
            [],
            [],
            color="k",
            ls=_STYLES[gi % len(_STYLES)][0],
            marker=_STYLES[gi % len(_STYLES)][1],
            ms=4,
            lw=1.1,
        )
        for gi in range(len(groups))
    ]
    labels += ["line:"] + [_wrap(g[0], 34) for g in groups]
    ax.legend(handles, labels, fontsize=7.5, loc="upper left", bbox_to_anchor=(1.01, 1.0))


def _note(axis, others, tied, grouped, too_many, spread):
    """What the lines and points of a study figure are, for its title."""
    if grouped:
        note = f" (one line per {', '.join(others)}; points: every completed run)"
    elif too_many or (others and spread):
        note = f" (points: every run over {', '.join(others)}; line: median)"
    else:
        note = ""
    if tied:
        note += f"; {', '.join(tied)} {'goes' if len(tied) == 1 else 'go'} with {axis}"
    return note


def _axis_figure(df, axis, axes, src, panels, status, plt):
    """The figure of one grid axis (study_<axis>.png's content)."""
    completed = status == "completed"
    col, numeric, x_all, order, raw = _x_of(df, axis, src)
    # axes zipped with this one (one value per x) are not others: they go with it
    valid = completed & np.isfinite(x_all)
    present = [a for a in axes if a != axis and df[a][valid].notna().any()]
    tied = [a for a in present if df[a][valid].astype(str).groupby(x_all[valid]).nunique().max() <= 1]
    others = [a for a in present if a not in tied]
    groups, too_many = _groups(df, others, np.where(completed, x_all, np.nan))
    grouped = bool(groups[0][0])
    fig, axs = plt.subplots(
        len(panels),
        1,
        figsize=(10 if grouped else 8, (3.4 if len(panels) < 3 else 2.6) * len(panels) + 0.7),
        sharex=True,
        squeeze=False,
        layout="constrained",
    )
    for ax, (ylabel, cols, per_unit) in zip(axs[:, 0], panels):
        _draw_panel(ax, df, cols, per_unit, groups, x_all, order, status)
        ax.set_ylabel(ylabel)
        _legend(ax, groups, plt)
    if not numeric:
        labels = [value_label(axis, v) for v in raw]
        tilt = max(map(len, labels), default=0) > 12 or len(labels) > 6
        axs[-1, 0].set_xticks(
            range(len(raw)), labels, rotation=25 if tilt else 0, ha="right" if tilt else "center"
        )
    axs[-1, 0].set_xlabel(axis_label(axis, col.dropna().to_numpy() if numeric else ()))
    note = _note(axis, others, tied, grouped, too_many, np.isfinite(x_all).sum() > len(order))
    what = _what(panels)
    fig.suptitle(_wrap(f"study {_study_name(src)}: {what} against {axis}{note}", 110 if grouped else 85),
                 fontsize=10)
    return fig


# the panels beyond the forces, each alone in its own unit: what the title calls them, and the
# y label where the quantity's own label is too long for the panel's height (None: its own)
_OWN_PANELS = {
    "peak_sprocket_torque": ("sprocket torque", "peak sprocket torque"),
    "peak_sinkage": ("sinkage", None),
    "mean_drawbar_pull": ("drawbar pull", None),
    "mean_slip": ("slip", None),
}


def _what(panels):
    """The figure title's list of what it shows: 'peak forces, sprocket torque and slip'."""
    own = [_OWN_PANELS[cols[0]][0] for _, cols, _ in panels if cols and cols[0] in _OWN_PANELS]
    names = ["peak forces"] + own
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def _panels(df):
    """(y label, summary columns, SI value of one display unit) of each panel: the wheels' peak
    forces, the other peak forces, and those of the closed track and the soft soil (the peak
    sprocket torque, the deepest sinkage, the mean drawbar pull and the mean slip), each alone
    (their own units)."""
    from trackbench.outputs.quantities import BY_NAME, PEAKS

    forces = [
        q.name
        for q in PEAKS
        if q.unit == "kN" and q.kind == "peak" and not q.per_wheel and q.name in df.columns
    ]
    panels = [("peak vertical wheel-track force (kN)", _wheel_columns(df), 1e3)]
    if forces:
        panels.append(("peak force (kN)", forces, 1e3))
    for name, (_, label) in _OWN_PANELS.items():
        if name in df.columns and df[name].notna().any():
            q = BY_NAME[name]
            panels.append((f"{label or q.label} ({q.unit})", [name], q.per_unit))
    return panels


def plot_study(study_dir, out_dir):
    """A peak-force-against-parameter figure per grid axis (study_<axis>.png); returns the paths.
    Completed runs only; failed runs and runs not run yet are marked on the x axis. With other
    axes varying too: one line per combination of their values (up to MAX_LINES; the line joins the medians of
    replicates), else every run a point and the line the median over them."""
    import pandas as pd
    plt = _plt()
    src = _find_summary(study_dir)
    df = pd.read_parquet(src) if src.suffix == ".parquet" else pd.read_csv(src)
    axes = study_axes(df)
    if not axes:
        raise ValueError(f"{src}: no parameter varies between the runs; nothing to plot against")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    panels = _panels(df)
    status = df["status"].astype(str).to_numpy() if "status" in df.columns else np.full(len(df), "completed")
    completed = status == "completed"
    paths = []
    for axis in axes:
        fig = _axis_figure(df, axis, axes, src, panels, status, plt)
        path = out / f"study_{axis.replace('.', '_').replace('/', '_')}.png"
        fig.savefig(path, dpi=DPI)
        plt.close(fig)
        paths.append(path)
    held = _has_drawbar(df, axes)   # else only runs on soft soil may have one: no other file opened
    drawbar = _plot_drawbar_pull(src, df[completed], out, has_drawbar=held) if held or _on_soil(df) else None
    from trackbench.figures.limit_figures import plot_limits
    return paths + ([drawbar] if drawbar else []) + plot_limits(src, df, out, plt)


def remove_stale(out_dir, written):
    """Remove the study figures (study_*.png) in out_dir that this plotting did not write: a
    figure of an axis the edited study no longer has would pass for a current one. Returns
    the removed paths."""
    keep = {Path(p).resolve() for p in written}
    stale = [p for p in sorted(Path(out_dir).glob("study_*.png")) if p.resolve() not in keep]
    for p in stale:
        p.unlink(missing_ok=True)
    return stale


def _on_soil(df):
    """Some run of the summary is on soft soil (its soil quantities are columns)."""
    from trackbench.outputs.quantities import TABLE
    return any(q.needs == "soil" and q.present(df.columns) for q in TABLE)


def _has_drawbar(df, axes):
    """A drawbar study: drawbar.slip or drawbar.load a grid axis, or set (not 0) in its runs."""
    for c in ("drawbar.slip", "drawbar.load"):
        if c in axes or (c in df.columns and pd_nonzero(df[c])):
            return True
    return False


def pd_nonzero(col):
    v = np.asarray(col.astype(float), dtype=float)
    return bool(np.any(np.isfinite(v) & (v != 0.0)))


def _steady_point(ds):
    """{soil, slip (the sprocket's), track_slip (the soil's), pull N, wong N, held}: means over
    the second half of a closed run on soft soil (trackbench/traction.py), else None. Wong's
    thrust (at the soil's slip) only where a drawbar holds the vehicle at it (held): a free
    vehicle's few kN of pull at a few % slip is not on his curve."""
    from trackbench.outputs.metrics.traction import has_traction, run_soil, steady, wong
    if not has_traction(ds):
        return None
    sc = scenario_of(ds)
    soil = sc["terrain"].get("soil")
    fig = steady(ds, 0.5 * float(ds.time.values[-1]))
    bar = sc.get("drawbar", {})
    held = bar.get("load", 0.0) != 0.0 or bar.get("slip", 0.0) > 0.0
    wong_thrust = wong(fig, run_soil(ds))[0] if held and np.isfinite(fig["track_slip"]) else np.nan
    return {"soil": soil if isinstance(soil, str) else "soil table", "slip": fig["slip"],
            "track_slip": fig["track_slip"], "pull": fig["thrust"], "wong": wong_thrust, "held": held}


def _plot_drawbar_pull(src, ok, out, has_drawbar=False):
    """Drawbar pull against slip, one curve per soil, for a study that holds the closed track on
    soft soil with a drawbar (study_drawbar_pull.png); None for other studies (free-running
    runs' pull at their own few % of slip is not a drawbar test). x: the slip the soil sees
    (track_slip); each point is marked with the sprocket's slip the rig held. Dashed: Wong's
    thrust of a uniformly loaded track of each run's contact and weight at that soil slip (on
    flat soil the drawbar pull is the thrust: trackbench/traction.py). Runs in such a study
    that no drawbar holds are drawn as open circles, not joined."""
    import xarray as xr
    points = []
    for rid in ok.get("run_id", []):
        path = src.parent / "runs" / str(rid) / "timeseries.nc"
        if path.exists():
            with xr.open_dataset(path) as ds:
                p = _steady_point(ds)
            if p is not None:
                points.append(p)
    if not points or not (has_drawbar or any(p["held"] for p in points)):
        return None
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 4.8), layout="constrained")
    ax.axhline(0.0, color="0.4", lw=0.8)
    for k, soil in enumerate(sorted({p["soil"] for p in points})):
        name = soil.replace("_", " ")
        mine = [p for p in points if p["soil"] == soil and np.isfinite(p["track_slip"])]
        held = sorted((p for p in mine if p["held"]), key=lambda p: p["slip"])
        free = [p for p in mine if not p["held"]]
        if held:
            x = 100 * np.array([p["track_slip"] for p in held])
            ax.plot(x, [p["pull"] / 1e3 for p in held], "o-", color=f"C{k}", ms=5, lw=1.3,
                    label=f"{name}: drawbar pull (measured)")
            for p, xi in zip(held, x):
                ax.annotate(f"{100 * p['slip']:.0f} %", (xi, p["pull"] / 1e3), xytext=(4, -10),
                            textcoords="offset points", fontsize=7, color=f"C{k}")
            w = np.array([p["wong"] for p in held])
            if np.isfinite(w).any():
                xw = 100 * np.clip([p["track_slip"] for p in held], 0.0, 1.0)
                ax.plot(xw, w / 1e3, "s--", color=f"C{k}", ms=4, lw=1, mfc="none",
                        label=f"{name}: Wong's thrust at the soil's slip (uniform pressure)")
        if free:
            ax.plot(
                100 * np.array([p["track_slip"] for p in free]),
                [p["pull"] / 1e3 for p in free],
                "o",
                color=f"C{k}",
                mfc="none",
                ms=6,
                ls="none",
                label=f"{name}: free-running runs (no drawbar)",
            )
    ax.set_xlabel("slip the soil sees (%): 1 - chassis speed / the track's speed in the contact")
    ax.set_ylabel("drawbar pull (kN)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    ax.set_title(
        _wrap(
            f"study {_study_name(src)}: drawbar pull against the soil's slip (means over each run's "
            "second half); the numbers at the points: the slip at the sprocket the towing rig held",
            90,
        ),
        fontsize=10,
    )
    path = out / "study_drawbar_pull.png"
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path
