"""The figures of a study that searched for a limit ([search], limits.csv): the limit curve
(the value found against the grid's first axis, one line per value of a second) and the
searched quantity against the searched parameter for every run it took, the limit drawn and
the run at the limit named so that it can be replayed (`trackbench view <run id>`)."""

from pathlib import Path

import numpy as np

from trackbench.figures.plot_common import DPI, axis_label, manifest, value_label

_MARKERS = ("o", "s", "^", "D", "v", "P")
_STATUS_MARK = {"limit_not_reached": ("^", "within the limit at high"),
                "limit_exceeded_at_low": ("v", "over the limit at low"),
                "non_monotone": ("X", "crosses the limit more than once")}


def _search_of(src):
    return manifest(src).get("search")


def plot_limits(src, summary, out, plt):
    """limit_<parameter>.png and search_<quantity>.png of the study whose summary is ``src``
    (read as the DataFrame ``summary``), or [] without a search or its limits.csv."""
    import pandas as pd

    search = _search_of(src)
    limits_path = Path(src).parent / "limits.csv"
    if not search or not limits_path.exists():
        return []
    limits = pd.read_csv(limits_path)
    axes = [c for c in limits.columns if c not in ("search_value", "status", "runs", "limit_run")]
    paths = [_limit_curve(limits, axes, search, out, plt),
             _quantity_figure(summary, limits, axes, search, out, plt)]
    return [p for p in paths if p is not None]


def _lines(limits, axes):
    """(label, rows) per line: one per value of the second axis (or one line)."""
    if len(axes) < 2:
        return [("", limits)]
    groups = limits.groupby(axes[1], sort=True)
    return [(f"{axes[1]} = {value_label(axes[1], v)}", rows) for v, rows in groups]


def _limit_curve(limits, axes, search, out, plt):
    """The value found against the first grid axis; the other statuses marked at the bound
    they mean, the run at each limit named beside it."""
    name, quantity = search["parameter"], search["quantity"]
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    x_name = axes[0] if axes else None
    named = {}   # (x, limit): the runs at it
    for k, (label, rows) in enumerate(_lines(limits, axes)):
        rows = rows.sort_values(x_name) if x_name else rows
        xs = rows[x_name].to_numpy(float) if x_name else np.zeros(len(rows))
        found = rows["status"].isin(["found", "non_monotone"])
        line = ax.plot(xs[found.to_numpy()], rows["search_value"][found], marker=_MARKERS[k % 6],
                       label=label or None)
        colour = line[0].get_color()
        for status, (marker, _) in _STATUS_MARK.items():
            at = (rows["status"] == status).to_numpy()
            bound = search["high"] if status == "limit_not_reached" else search["low"]
            y = rows["search_value"].where(rows["search_value"].notna(), bound)[at]
            ax.scatter(xs[at], y, marker=marker, s=70, color=colour, zorder=3)
        if "limit_run" in rows:
            for x, y, run in zip(xs, rows["search_value"], rows["limit_run"]):
                if isinstance(run, str) and np.isfinite(y):
                    named.setdefault((x, y), []).append(run)
    for (x, y), runs in named.items():   # seeds at one limit: their runs one above another
        ax.annotate("\n".join(runs), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    for status, (marker, text) in _STATUS_MARK.items():
        if (limits["status"] == status).any():
            ax.scatter([], [], marker=marker, color="grey", label=text)
    if x_name and len(axes) == 2 and axes[1].endswith("seed"):
        _median_over_seeds(ax, limits, x_name, axes[1])
    ax.set_xlabel(axis_label(x_name, limits[x_name]) if x_name else "grid point")
    ax.set_ylabel(f"highest {axis_label(name)}")
    ax.set_title(f"{name} limit: {quantity} <= {search['limit']:g} (to {search['tolerance']:g})",
                 fontsize=10)
    return _saved(fig, ax, Path(out) / f"limit_{name.replace('.', '_')}.png", plt, 8)


def _median_over_seeds(ax, limits, x_name, seed):
    """The seeds' median limit as a thick line, their range shaded (study/read/limits.over_seeds)."""
    from trackbench.study.read.limits import over_seeds
    m = over_seeds(limits, seed).dropna(subset=["median"]).sort_values(x_name)
    xs = m[x_name].to_numpy(float)
    ax.fill_between(xs, m["min"], m["max"], color="black", alpha=0.12, label="the seeds' range")
    ax.plot(xs, m["median"], color="black", lw=2.5, label="median over the seeds")


def _quantity_figure(summary, limits, axes, search, out, plt):
    """The searched quantity against the searched parameter for every run of the search, one
    line per grid point, the limit as a line and the run at each point's limit ringed."""
    name, quantity = search["parameter"], search["quantity"]
    if name not in summary or quantity not in summary:
        return None
    import pandas as pd

    from trackbench.outputs.quantities import quantity_of
    status = summary["status"].astype(str) if "status" in summary else pd.Series("completed", summary.index)
    done = summary[status == "completed"]
    from trackbench.study.read.limits import failed_over_limit
    failed = summary[failed_over_limit(summary, quantity, search["limit"])]   # counted as over
    q = quantity_of(quantity)
    scale, unit = (q[0].per_unit, q[0].unit) if q else (1.0, "")
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    for k, (_, point) in enumerate(limits.iterrows()):
        rows = _at_point(done, axes, point).sort_values(name)
        label = ", ".join(f"{a} = {value_label(a, point[a])}" for a in axes)
        line = ax.plot(rows[name], rows[quantity] / scale, marker=_MARKERS[k % 6], ms=4, lw=1,
                       label=label or None)
        over = _at_point(failed, axes, point)
        ax.scatter(over[name], over[quantity] / scale, marker="x", s=60, color=line[0].get_color(), zorder=3)
        at = rows[rows[name] == point["search_value"]] if np.isfinite(point["search_value"]) else rows[:0]
        ax.scatter(at[name], at[quantity] / scale, s=160, facecolors="none", edgecolors=line[0].get_color(),
                   zorder=3)
    limit = search["limit"] / scale
    ax.axhline(limit, color="black", lw=1, ls="--", label=f"limit {limit:g} {unit}")
    ax.set_xlabel(axis_label(name))
    ax.set_ylabel(f"{quantity} ({unit})" if unit else quantity)
    if len(failed):
        ax.scatter([], [], marker="x", color="grey", label="failed over the limit (when it stopped)")
    values = np.append(done[quantity].to_numpy(float) / scale, limit)
    values = values[np.isfinite(values)]
    if values.size and values.min() > 0.0 and values.max() > 20.0 * values.min():
        ax.set_yscale("log")   # runs far over the limit would squash the ones near it
    ax.set_title(f"{quantity} of every run of the search (ringed: the run at the limit)", fontsize=10)
    return _saved(fig, ax, Path(out) / f"search_{quantity}.png", plt, 7)


def _at_point(frame, axes, point):
    """The rows of frame at the grid point ``point`` (its values on every axis the frame has)."""
    for a in axes:
        if a in frame:
            frame = frame[np.isclose(frame[a].astype(float), float(point[a]))]
    return frame


def _saved(fig, ax, path, plt, legend_size):
    """The figure with its grid and legend, written to path (PNG) and closed; returns path."""
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=legend_size)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path
