"""The paper's result figures (Figs. 8-18 of Lee, 2000) as PNG files, and study plots.

    plot_run(ds_or_path, out_dir, times=(0.1, 0.35, 0.45)) -> [PNG paths]
    plot_study(study_dir, out_dir) -> [PNG paths]      # one figure per grid axis (+ drawbar pull
                                                       #   against slip for soil runs)

matplotlib is an optional dependency (extra "plot"); it is imported here only.
"""

from pathlib import Path

import numpy as np

from ..quantities import accounted_balance
from . import geometry as G

DEFAULT_TIMES = (0.1, 0.35, 0.45)
DPI = 130
SOIL_DENT = "#f2dc9b"   # soft soil: the rut, between the original surface and the dent


def _plt():
    try:
        import matplotlib
    except ImportError as e:  # pragma: no cover - depends on the install
        raise ImportError("plotting needs matplotlib: pip install 'trackbench[plot]'") from e
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt
    return plt


def find_timeseries(path):
    """A .nc file, or a run folder holding timeseries.nc (or exactly one .nc) -> the .nc Path."""
    path = Path(path)
    if path.is_file():
        return path
    if path.is_dir():
        if (path / "timeseries.nc").exists():
            return path / "timeseries.nc"
        ncs = sorted(path.glob("*.nc"))
        if len(ncs) == 1:
            return ncs[0]
        if len(ncs) > 1:
            raise FileNotFoundError(f"{path} holds several .nc files ({', '.join(p.name for p in ncs)}); give one")
        raise FileNotFoundError(f"{path} holds no timeseries.nc (nor any .nc file)")
    raise FileNotFoundError(f"{path} does not exist")


def load_run(ds_or_path):
    """A Dataset is returned as is; a path (a .nc file or a run folder) is loaded into memory."""
    if hasattr(ds_or_path, "data_vars"):
        return ds_or_path
    import xarray as xr
    return xr.load_dataset(find_timeseries(ds_or_path))


def _wheels_to_show(ds):
    """The paper shows wheels 1, 3 and 5; for other vehicles: the first, middle and last."""
    w = [int(x) for x in ds["wheel"].values]
    if {1, 3, 5} <= set(w):
        return [1, 3, 5]
    return sorted({w[0], w[len(w) // 2], w[-1]})


def _name(ds):
    try:
        return G.scenario_of(ds).get("name", "run")
    except (KeyError, ValueError):
        return "run"


def _status_note(ds):
    if ds.attrs.get("status", "completed") == "completed":
        return ""
    return f"  [run {ds.attrs.get('status')} at t = {float(ds.attrs.get('t_final', np.nan)):.4f} s]"


# --------------------------------------------------------------------------------- run ----

def draw_configuration(ax, ds, i, x_range=None, arrows=True, colorbar=False):
    """Side view of output frame i on a matplotlib Axes (metres, equal aspect)."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle, Polygon

    g = G.side_view(ds, [i])
    pins, wheels = g["pins"][0], g["wheels"][0]
    r = float(ds.attrs["wheel_radius"])
    if x_range is None:
        x_range = (min(pins[:, 0].min(), g["chassis"][0][:, 0].min()) - 0.4,
                   max(pins[:, 0].max(), g["chassis"][0][:, 0].max()) + 0.4)
    ground = G.ground_polyline(ds, (x_range[0] - 1.0, x_range[1] + 1.0))
    y_floor = float(ground[:, 1].min()) - 0.25
    surface = ground
    if G.is_soil(ds):
        # soft soil: the ground lowered by the rut made up to this frame (geometry.soil_surface);
        # the soil pressed out of the way (between the original surface and the dent) is pale
        # sand under a dashed line at the original surface
        base, drop = G.soil_surface(ds, [i], (x_range[0] - 1.0, x_range[1] + 1.0))
        surface = base - np.stack([np.zeros_like(drop[0]), drop[0]], axis=-1)
        ax.fill_between(base[:, 0], base[:, 1], surface[:, 1], facecolor=SOIL_DENT, edgecolor="none", zorder=1.1)
        ax.plot(ground[:, 0], ground[:, 1], color="#785528", lw=0.8, ls=(0, (4, 3)), zorder=1.2)
        y_floor = min(y_floor, float(surface[:, 1].min()) - 0.25)
    ax.add_patch(Polygon(np.vstack([surface, [[surface[-1, 0], -50.0], [surface[0, 0], -50.0]]]),
                         closed=True, facecolor="#d8c3a0", edgecolor="#785528", hatch="///", lw=1.2, zorder=1))
    ax.add_patch(Polygon(g["chassis"][0][:-1], closed=True, facecolor="#e9edf2", edgecolor="#3c3c3c", lw=1.5, zorder=2))
    for (px, py), (wx, wy) in zip(g["pivots"][0], wheels):
        ax.plot([px, wx], [py, wy], color="#6e6e6e", lw=3, zorder=3, solid_capstyle="round")
        ax.plot([px], [py], "o", color="#3c3c3c", ms=3, zorder=4)
    for k, (wx, wy) in enumerate(wheels):
        ax.add_patch(Circle((wx, wy), r, facecolor="#f4f4f4", edgecolor="#222222", lw=1.3, zorder=3))
        ax.text(wx, wy + 0.02, str(int(ds["wheel"].values[k])), ha="center", va="center", fontsize=7, zorder=6)
    if G.is_closed(ds):
        _draw_closed_parts(ax, ds, g)
    lc = LineCollection(g["links"][0], colors=G.tension_rgb(g["tension"][0]) / 255.0, linewidths=2.4, zorder=4)
    ax.add_collection(lc)
    ax.plot(pins[:, 0], pins[:, 1], "o", color="#1e1e1e", ms=2.2, zorder=5)
    if arrows:
        o, v = g["wheel_arrow_origin"][0], g["wheel_arrow_vector"][0]
        for (ox, oy), (vx, vy) in zip(o, v):
            _arrow(ax, ox, oy, vx, vy, "#c80000", 1.4)
        go, gv = g["ground_arrow_origin"][0], g["ground_arrow_vector"][0]
        _arrow(ax, go[0], go[1], gv[0], gv[1], "#9632c8", 1.8)
        if np.hypot(*gv) > 0:  # the ground arrow comes from below the ground: show all of it
            y_floor = min(y_floor, float(go[1]) - 0.1)
    ax.set_xlim(*x_range)
    top = float(g["chassis"][0][:, 1].max()) + 0.15
    if arrows:
        top = max(top, float((g["wheel_arrow_origin"][0] + g["wheel_arrow_vector"][0])[:, 1].max()) + 0.1)
    ax.set_ylim(y_floor, max(top, y_floor + 1.0))
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"t = {float(g['time'][0]):.3f} s", fontsize=10)
    return lc


def _draw_closed_parts(ax, ds, g):
    """The closed layout's sprocket (tooth profile at this frame's angle, with a spoke to show
    it turning), idler on its guide, and support rollers; under the track (zorder 3)."""
    from matplotlib.patches import Circle, Polygon
    lay = G.closed_layout(ds)
    teeth = g["sprocket"][0]
    ax.add_patch(Polygon(teeth[:-1], closed=True, facecolor="#c9d3e6", edgecolor="#283c6e", lw=1.0, zorder=3))
    axis = np.asarray(g["sprocket_axis"][0])
    ax.plot([axis[0], teeth[0, 0]], [axis[1], teeth[0, 1]], color="#283c6e", lw=1.0, zorder=3)
    ax.plot([axis[0]], [axis[1]], "o", color="#283c6e", ms=3, zorder=4)
    ix, iy = g["idler"][0]
    ax.add_patch(Circle((ix, iy), float(lay["idler_radius"]), facecolor="#f4f4f4", edgecolor="#5a5a5a", lw=1.3,
                        zorder=3))
    # the guide is shorter than the idler is wide: drawn over the idler's face so it shows
    guide = g["guide"][0]
    ax.plot(guide[:, 0], guide[:, 1], color="#b4783c", lw=5, solid_capstyle="butt", zorder=3.5)
    ax.plot([ix], [iy], "o", color="#3c3c3c", ms=4, zorder=4)
    for rx, ry in g["rollers"][0]:
        ax.add_patch(Circle((rx, ry), float(lay["roller_radius"]), facecolor="#f4f4f4", edgecolor="#787878",
                            lw=1.1, zorder=3))


def _arrow(ax, x, y, dx, dy, color, lw):
    from matplotlib.patches import FancyArrowPatch
    if dx == 0.0 and dy == 0.0:
        return
    ax.add_patch(FancyArrowPatch((x, y), (x + dx, y + dy), arrowstyle="-|>", mutation_scale=12, color=color,
                                 lw=lw, shrinkA=0, shrinkB=0, zorder=7))


def _tension_colorbar(fig, axes):
    import matplotlib.colors as mcolors
    import matplotlib.cm as cm
    stops = (G.TENSION_STOPS - G.TENSION_STOPS[0]) / (G.TENSION_STOPS[-1] - G.TENSION_STOPS[0])
    cmap = mcolors.LinearSegmentedColormap.from_list("tension", list(zip(stops, G.TENSION_RGB / 255.0)))
    sm = cm.ScalarMappable(norm=mcolors.Normalize(G.TENSION_STOPS[0] / 1e3, G.TENSION_STOPS[-1] / 1e3), cmap=cmap)
    cb = fig.colorbar(sm, ax=axes, fraction=0.025, pad=0.01)
    cb.set_label("link tension (kN), < 0 compression")


def plot_configuration(ds, times, path):
    plt = _plt()
    t = np.asarray(ds["time"].values)
    chosen = [float(x) for x in times if t[0] - 1e-9 <= float(x) <= t[-1] + 1e-9]
    if not chosen:
        raise ValueError(f"none of the times {list(times)} s lies in the run ({t[0]:.3g} .. {t[-1]:.4g} s)")
    idx = [int(np.argmin(np.abs(t - x))) for x in chosen]
    fig, axes = plt.subplots(len(idx), 1, figsize=(11, 3.3 * len(idx) + 0.6), squeeze=False, layout="constrained")
    axes = axes[:, 0]
    # one x window wide enough for the vehicle at every chosen time, moved with the vehicle
    width = max(float(np.ptp(ds["pin_x"].values[i])) for i in idx) + 1.6
    for ax, i in zip(axes, idx):
        cx = 0.5 * (float(ds["pin_x"].values[i].min()) + float(ds["pin_x"].values[i].max()))
        draw_configuration(ax, ds, i, x_range=(cx - width / 2, cx + width / 2))
    _tension_colorbar(fig, list(axes))
    soil = ("\nsoft soil: the rut made up to each time (pale sand) below the original surface (dashed)"
            if G.is_soil(ds) else "")
    parts = ("\nclosed track: sprocket with its teeth (blue, the line marks its turn), "
             "idler on its guide (bronze bar), support rollers" if G.is_closed(ds) else "")
    fig.suptitle(f"{_name(ds)}: configuration (cf. Figs. 8-10); arrows: wheel-track force on the wheels (red), "
                 f"total ground force (purple), 1 m = {1e-3 / G.FORCE_SCALE:.0f} kN{_status_note(ds)}{parts}{soil}",
                 fontsize=9.5)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def _time_plot(path, title, panels, ds):
    """panels: list of (ylabel, [(y array, label, style dict)])."""
    plt = _plt()
    t = np.asarray(ds["time"].values)
    fig, axes = plt.subplots(len(panels), 1, figsize=(9, 2.6 * len(panels) + 0.6), sharex=True, squeeze=False)
    for ax, (ylabel, lines) in zip(axes[:, 0], panels):
        for y, label, style in lines:
            ax.plot(t, y, label=label, **style)
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
        if len(lines) > 1 or lines[0][1]:
            ax.legend(fontsize=8, loc="best")
    axes[-1, 0].set_xlabel("time (s)")
    axes[-1, 0].set_xlim(t[0], t[-1])
    fc = float(ds["first_contact_time"]) if "first_contact_time" in ds else np.nan
    if np.isfinite(fc):
        for ax in axes[:, 0]:
            ax.axvline(fc, color="0.5", ls=":", lw=1)
    note = f"\ndotted line: first obstacle contact (t = {fc:.4f} s)" if np.isfinite(fc) else ""
    fig.suptitle(title + _status_note(ds) + note, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def plot_run(ds_or_path, out_dir, times=DEFAULT_TIMES):
    """Write the run's figures as PNG files into out_dir; returns their paths.

    configuration.png  the vehicle at `times` (Figs. 8-10)
    wheel_force.png    vertical wheel-track force of wheels 1, 3, 5 (Figs. 11-14)
    chassis_ay.png     chassis vertical acceleration (Figs. 15-16)
    chassis_vx.png     chassis horizontal velocity (Fig. 17)
    energy.png         energies and the energy-balance deviation (Fig. 18)
    Times outside the run are left out of the configuration figure."""
    ds = load_run(ds_or_path)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    name = _name(ds)
    paths = [plot_configuration(ds, times, out / "configuration.png")]
    wheels = _wheels_to_show(ds)
    fy = ds["wheel_force_y"]
    paths.append(_time_plot(out / "wheel_force.png",
                            f"{name}: vertical contact force between road wheel and track (cf. Figs. 11-14)",
                            [(f"wheel {w}: F_y (kN)", [(fy.sel(wheel=w).values / 1e3, "", {"color": "C0", "lw": 0.9})])
                             for w in wheels], ds))
    paths.append(_time_plot(out / "chassis_ay.png", f"{name}: vertical acceleration of the chassis mass centre "
                            "(cf. Figs. 15-16)",
                            [("a_y (m/s$^2$)", [(ds["chassis_ay"].values, "", {"color": "C3", "lw": 0.8})])], ds))
    paths.append(_time_plot(out / "chassis_vx.png", f"{name}: horizontal velocity of the chassis mass centre (cf. Fig. 17)",
                            [("v_x (m/s)", [(ds["chassis_vx"].values, "", {"color": "C2", "lw": 1.0})])], ds))
    e = [(ds[v].values / 1e3, label, {"lw": 1.0, "color": c}) for v, label, c in
         (("energy_kinetic", "kinetic", "C0"), ("energy_elastic", "elastic (torsion bars, links, pads)", "C2"),
          ("energy_gravity", "gravity potential (from t = 0)", "C1"), ("energy_balance", "balance (sum)", "k"))]
    deviation = [(100 * ds["energy_balance_error"].values, "energy balance", {"color": "k", "lw": 0.9}),
                 (100 * ds["energy_residual"].values, "work-based residual", {"color": "C3", "lw": 0.9})]
    accounted = accounted_balance(ds)
    if accounted is not None:
        # energy that left on purpose (dampers, friction, soil, drawbar) added back, the drive's taken out
        closed, label = accounted
        dissipated = ds["energy_dissipated"].values
        e.append((dissipated / 1e3, "dissipated (dampers, friction, soil, drawbar)", {"color": "C5", "lw": 1.0}))
        if "drive_work" in ds:
            e.append((ds["drive_work"].values / 1e3, "drive work", {"color": "C6", "lw": 1.0}))
        e0 = float(ds.attrs["initial_total_energy"])
        e.append(((ds["energy_balance"].values[0] + e0 * (closed - closed[0])) / 1e3, label, {"color": "C4", "lw": 1.0}))
        deviation.append((100 * closed, label, {"color": "C4", "lw": 0.9}))
    paths.append(_time_plot(out / "energy.png", f"{name}: energies (cf. Fig. 18)",
                            [("energy (kJ)", e), ("balance deviation (% of E0)", deviation)], ds))
    return paths


# ------------------------------------------------------------------------------- study ----

BOOKKEEPING = {"run_id", "status", "status_message", "variant", "replicate", "steps", "rejected_steps", "t_final",
               "wall_time", "solve_time", "recording", "recording_error", "seed"}


def study_axes(df):
    """Grid axes of a study summary: every column that is neither book-keeping nor a summary
    quantity (trackbench/quantities.py) and takes more than one value."""
    from ..quantities import quantity_of
    axes = []
    for c in df.columns:
        if c in BOOKKEEPING or quantity_of(c) is not None:
            continue
        if df[c].nunique(dropna=True) > 1:
            axes.append(c)
    return axes


def _wheel_of(column):
    from ..quantities import BY_NAME
    return BY_NAME["peak_wheel_force_y"].wheel_of(column)


def _wheel_columns(df):
    from ..quantities import BY_NAME
    wheel = BY_NAME["peak_wheel_force_y"]
    return sorted(wheel.present(df.columns), key=wheel.wheel_of)


def _find_summary(study_dir):
    p = Path(study_dir)
    if p.is_file() and p.suffix == ".toml":
        from .view import study_output
        p = study_output(p)
    if p.is_file() and p.name.startswith("summary"):
        return p
    for name in ("summary.csv", "summary.parquet"):
        if (p / name).exists():
            return p / name
    raise FileNotFoundError(f"{study_dir}: no summary.csv (run `trackbench study run` first)")


def plot_study(study_dir, out_dir):
    """A peak-force-against-parameter figure per grid axis (study_<axis>.png); returns the paths.
    Completed runs only; with other axes varying too, every run is a point and the line
    joins the medians at each value; failed runs are marked on the x axis."""
    import pandas as pd
    plt = _plt()
    src = _find_summary(study_dir)
    df = pd.read_parquet(src) if src.suffix == ".parquet" else pd.read_csv(src)
    axes = study_axes(df)
    if not axes:
        raise ValueError(f"{src}: no parameter varies between the runs; nothing to plot against")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    wheel_cols = _wheel_columns(df)
    from ..quantities import PEAKS
    other_cols = [q.name for q in PEAKS if q.unit == "kN" and not q.per_wheel and q.name in df.columns]
    ok = df[df["status"] == "completed"] if "status" in df.columns else df
    bad = df[df["status"] != "completed"] if "status" in df.columns else df.iloc[:0]
    paths = []
    for axis in axes:
        values = df[axis].dropna().unique()
        numeric = pd.api.types.is_numeric_dtype(df[axis])
        if numeric:
            order = np.sort(values.astype(float))

            def xpos(s):
                return s.astype(float).to_numpy()
        else:
            order = sorted(values, key=str)
            where = {v: k for k, v in enumerate(order)}

            def xpos(s):
                return s.map(where).astype(float).to_numpy()
        panels = [("peak vertical wheel-track force (kN)", wheel_cols)]
        if other_cols:
            panels.append(("peak force (kN)", other_cols))
        fig, axs = plt.subplots(len(panels), 1, figsize=(8, 3.4 * len(panels) + 0.5), sharex=True, squeeze=False)
        for ax, (ylabel, cols) in zip(axs[:, 0], panels):
            for k, c in enumerate(cols):
                y = ok[c].astype(float).to_numpy() / 1e3
                x = xpos(ok[axis])
                label = (f"wheel {_wheel_of(c)}" if _wheel_of(c) is not None
                         else c.replace("peak_", "peak ").replace("_", " "))
                ax.plot(x, y, "o", color=f"C{k}", ms=4, alpha=0.6)
                xs = np.array(order, dtype=float) if numeric else np.arange(len(order), dtype=float)
                med = [np.nanmedian(y[x == v]) if np.any(x == v) else np.nan for v in xs]
                ax.plot(xs, med, "-", color=f"C{k}", lw=1.3, label=label)
            if len(bad):
                ax.plot(xpos(bad[axis]), np.zeros(len(bad)), "x", color="red", ms=8, mew=2,
                        label=f"failed run ({len(bad)})", clip_on=False)
            ax.set_ylabel(ylabel)
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=8, ncol=2)
        if not numeric:
            axs[-1, 0].set_xticks(range(len(order)), [str(v) for v in order])
        axs[-1, 0].set_xlabel(axis + _axis_units(axis))
        others = [a for a in axes if a != axis]
        note = f" (points: every run over {', '.join(others)}; line: median)" if others else ""
        fig.suptitle(f"study {src.parent.name}: peak forces against {axis}{note}", fontsize=10)
        fig.tight_layout()
        path = out / f"study_{axis.replace('.', '_').replace('/', '_')}.png"
        fig.savefig(path, dpi=DPI)
        plt.close(fig)
        paths.append(path)
    drawbar = _plot_drawbar_pull(src, ok, out)
    return paths + ([drawbar] if drawbar else [])


def _steady_point(ds):
    """(soil name, slip, drawbar pull N, Wong's thrust N): means over the second half of a
    closed run on soft soil (trackbench/traction.py), else None."""
    import json
    from ..traction import has_traction, run_soil, steady, wong
    if not has_traction(ds):
        return None
    sc = json.loads(ds.attrs["scenario"])
    soil = sc["terrain"].get("soil")
    fig = steady(ds, 0.5 * float(ds.time.values[-1]))
    # Wong's steady thrust only where a drawbar holds the vehicle at it: a free vehicle's few
    # kN of pull at a few % slip is not on his curve
    bar = sc.get("drawbar", {})
    held = bar.get("load", 0.0) != 0.0 or bar.get("slip", 0.0) > 0.0
    return (soil if isinstance(soil, str) else "soil table", fig["slip"], fig["thrust"],
            wong(fig, run_soil(ds))[0] if held else np.nan)


def _plot_drawbar_pull(src, ok, out):
    """Drawbar pull against slip, one curve per soil, when the study's completed runs drive
    the closed track on soft soil (study_drawbar_pull.png), and, for runs held by a drawbar,
    Wong's thrust of a uniformly loaded track of each run's contact and weight at the slip its
    soil sees (dashed; on flat soil the drawbar pull is the thrust: trackbench/traction.py);
    None otherwise."""
    import xarray as xr
    points = []
    for rid in ok.get("run_id", []):
        path = src.parent / "runs" / str(rid) / "timeseries.nc"
        if path.exists():
            with xr.open_dataset(path) as ds:
                p = _steady_point(ds)
            if p is not None:
                points.append(p)
    if not points:
        return None
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for k, soil in enumerate(sorted({p[0] for p in points})):
        xy = np.array(sorted(p[1:] for p in points if p[0] == soil))
        ax.plot(100 * xy[:, 0], xy[:, 1] / 1e3, "o-", color=f"C{k}", ms=4, label=soil.replace("_", " "))
        if np.isfinite(xy[:, 2]).any():
            ax.plot(100 * xy[:, 0], xy[:, 2] / 1e3, "--", color=f"C{k}", lw=1,
                    label=f"{soil.replace('_', ' ')}: Wong's thrust of the run (uniform pressure, the soil's slip)")
    ax.set_xlabel("slip at the sprocket (%)")
    ax.set_ylabel("drawbar pull (kN)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    ax.set_title(f"study {src.parent.name}: drawbar pull against slip (means over each run's second half)",
                 fontsize=10)
    fig.tight_layout()
    path = out / "study_drawbar_pull.png"
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


_UNITS = {"speed": "m/s", "duration": "s", "gravity": "m/s^2", "tolerance": "", "output_interval": "s",
          "perturbation": "m", "terrain.height": "m", "terrain.length": "m", "terrain.position": "m",
          "terrain.first_contact_time": "s", "terrain.gap": "m", "vehicle.chassis_mass": "kg",
          "vehicle.chassis_inertia": "kg m^2", "vehicle.arm_mass": "kg", "vehicle.arm_inertia": "kg m^2",
          "vehicle.arm_length": "m", "vehicle.arm_angle": "deg", "vehicle.torsion_stiffness": "N m/rad",
          "vehicle.wheel_radius": "m", "vehicle.first_pivot_x": "m", "vehicle.pivot_y": "m",
          "vehicle.pivot_spacing": "m", "track.link_length": "m", "track.pin_mass": "kg",
          "track.link_stiffness": "N/m", "track.pad_wheel": "m", "track.pad_ground": "m",
          "track.wheel_stiffness": "N/m", "track.ground_stiffness": "N/m"}


def _axis_units(axis):
    u = _UNITS.get(axis, "")
    return f" ({u})" if u else ""
