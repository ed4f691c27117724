"""The paper's result figures of one run (Figs. 8-18 of Lee, 2000) as PNG files, with the
closed track's drive and the soil's traction figures where the run has them."""

from pathlib import Path

import numpy as np

from trackbench.figures.plot_common import (
    DPI,
    PAPER_TIMES,
    SOIL_DENT,
    _name,
    _plt,
    _status_note,
    _wheels_to_show,
    _wrap,
    load_run,
    run_label,
)
from trackbench.outputs import geometry as G
from trackbench.outputs.quantities import accounted_balance
from trackbench.outputs.recording import soil_view as S


def draw_configuration(ax, ds, i, x_range=None, arrows=True, colorbar=False, force_scale=G.FORCE_SCALE):
    """Side view of output frame i on a matplotlib Axes (metres, equal aspect). The frame holds
    the vehicle and the ground under it; force arrows are drawn at `force_scale` (m per N):
    the ground force's tail, which comes from below the ground, is cut at the frame's bottom
    edge and its size written beside its head."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle, Polygon

    g = G.side_view(ds, [i])
    pins, wheels = g["pins"][0], g["wheels"][0]
    radii = G.wheel_radii(ds)
    if x_range is None:
        x_range = (min(pins[:, 0].min(), g["chassis"][0][:, 0].min()) - 0.4,
                   max(pins[:, 0].max(), g["chassis"][0][:, 0].max()) + 0.4)
    ground = G.ground_polyline(ds, (x_range[0] - 1.0, x_range[1] + 1.0))
    y_floor = float(ground[:, 1].min()) - 0.4
    surface = ground
    if S.is_soil(ds):
        # soft soil: the ground lowered by the rut made up to this frame (geometry.soil_surface);
        # the soil pressed out of the way (between the original surface and the dent) is pale
        # sand under a dashed line at the original surface
        base, drop = S.soil_surface(ds, [i], (x_range[0] - 1.0, x_range[1] + 1.0))
        surface = base - np.stack([np.zeros_like(drop[0]), drop[0]], axis=-1)
        ax.fill_between(
            base[:, 0], base[:, 1], surface[:, 1], facecolor=SOIL_DENT, edgecolor="none", zorder=1.1
        )
        ax.plot(ground[:, 0], ground[:, 1], color="#785528", lw=0.8, ls=(0, (4, 3)), zorder=1.2)
        y_floor = min(y_floor, float(surface[:, 1].min()) - 0.4)
    ax.add_patch(
        Polygon(
            np.vstack([surface, [[surface[-1, 0], -50.0], [surface[0, 0], -50.0]]]),
            closed=True,
            facecolor="#d8c3a0",
            edgecolor="#785528",
            hatch="///",
            lw=1.2,
            zorder=1,
        )
    )
    ax.add_patch(
        Polygon(g["chassis"][0][:-1], closed=True, facecolor="#e9edf2", edgecolor="#3c3c3c", lw=1.5, zorder=2)
    )
    for (px, py), (wx, wy) in zip(g["pivots"][0], wheels):
        ax.plot([px, wx], [py, wy], color="#6e6e6e", lw=3, zorder=3, solid_capstyle="round")
        ax.plot([px], [py], "o", color="#3c3c3c", ms=3, zorder=4)
    for k, (wx, wy) in enumerate(wheels):
        ax.add_patch(Circle((wx, wy), radii[k], facecolor="#f4f4f4", edgecolor="#222222", lw=1.3, zorder=3))
        ax.text(
            wx, wy + 0.02, str(int(ds["wheel"].values[k])), ha="center", va="center", fontsize=7, zorder=6
        )
    if G.is_closed(ds):
        _draw_closed_parts(ax, ds, g)
    lc = LineCollection(
        g["links"][0], colors=G.tension_rgb(g["tension"][0]) / 255.0, linewidths=2.4, zorder=4
    )
    ax.add_collection(lc)
    ax.plot(pins[:, 0], pins[:, 1], "o", color="#1e1e1e", ms=2.2, zorder=5)
    if arrows:
        k = force_scale / G.FORCE_SCALE
        o, v = g["wheel_arrow_origin"][0], k * g["wheel_arrow_vector"][0]
        for (ox, oy), (vx, vy) in zip(o, v):
            _arrow(ax, ox, oy, vx, vy, "#c80000", 1.4)
        gv = g["ground_arrow_vector"][0]
        tip = g["ground_arrow_origin"][0] + gv
        gv = k * gv
        _arrow(ax, tip[0] - gv[0], tip[1] - gv[1], gv[0], gv[1], "#9632c8", 1.8)
        if np.hypot(*gv) > 0:
            ax.annotate(f"{np.hypot(*gv) / force_scale / 1e3:.0f} kN", (tip[0], y_floor), xytext=(6, 3),
                        textcoords="offset points", fontsize=7.5, color="#6a1f96", zorder=8,
                        bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8})
    ax.set_xlim(*x_range)
    top = float(g["chassis"][0][:, 1].max()) + 0.15
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
    ax.add_patch(
        Circle(
            (ix, iy), float(lay["idler_radius"]), facecolor="#f4f4f4", edgecolor="#5a5a5a", lw=1.3, zorder=3
        )
    )
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
    import matplotlib.cm as cm
    import matplotlib.colors as mcolors
    stops = (G.TENSION_STOPS - G.TENSION_STOPS[0]) / (G.TENSION_STOPS[-1] - G.TENSION_STOPS[0])
    cmap = mcolors.LinearSegmentedColormap.from_list("tension", list(zip(stops, G.TENSION_RGB / 255.0)))
    sm = cm.ScalarMappable(
        norm=mcolors.Normalize(G.TENSION_STOPS[0] / 1e3, G.TENSION_STOPS[-1] / 1e3), cmap=cmap
    )
    cb = fig.colorbar(sm, ax=axes, fraction=0.025, pad=0.01)
    cb.set_label("link tension (kN), < 0 compression")


def default_times(ds):
    """The configuration figure's times when none are given: the paper's 0.1, 0.35 and 0.45 s
    for a completed run of the paper's length (0.45 to 0.6 s), else three times spread over
    the run, the last at its last sample (where a failed run stopped)."""
    t = np.asarray(ds["time"].values, dtype=float)
    completed = ds.attrs.get("status", "completed") == "completed"
    if completed and t[0] <= PAPER_TIMES[0] and PAPER_TIMES[-1] <= t[-1] <= 0.6 + 1e-9:
        return PAPER_TIMES
    if len(t) < 2:
        return (float(t[-1]),)
    return tuple(float(x) for x in np.linspace(t[0], t[-1], 4)[1:])


def choose_times(ds, times=None):
    """(times to draw, note for the title): `times` inside the run (default_times(ds) when
    None, or when none of them is); the note names the times left out."""
    t = np.asarray(ds["time"].values, dtype=float)
    if times is None:
        return list(default_times(ds)), ""
    inside = [float(x) for x in times if t[0] - 1e-9 <= float(x) <= t[-1] + 1e-9]
    out = [float(x) for x in times if float(x) not in inside]
    note = ""
    if out:
        note = f"; {', '.join(f'{x:g}' for x in out)} s left out: the run covers {t[0]:.3g} .. {t[-1]:.4g} s"
    if not inside:
        inside = list(default_times(ds))
        note += ", times spread over it instead"
    return inside, note


def _arrow_scale(ds, idx, x_ranges):
    """m per N for the force arrows of these frames: the paper's 1 m per 200 kN, or a rounder,
    smaller scale at which every wheel arrow ends below the frame's top (the chassis + 0.15 m)."""
    g = G.side_view(ds, idx)
    room = np.inf
    for j in range(len(idx)):
        top = float(g["chassis"][j][:, 1].max()) + 0.15 - 0.05
        o, v = g["wheel_arrow_origin"][j], g["wheel_arrow_vector"][j]
        up = v[:, 1] > 1e-9
        if up.any():
            room = min(room, float(np.min((top - o[up, 1]) / v[up, 1])))
    if not room < 1.0:
        return G.FORCE_SCALE
    kn = 1e-3 / G.FORCE_SCALE / max(room, 1e-3)        # kN per metre needed
    nice = [m * 10.0 ** e for e in range(2, 7) for m in (1.0, 2.0, 2.5, 4.0, 5.0)]
    return 1e-3 / min(x for x in nice if x >= kn * (1 - 1e-9))


def plot_configuration(ds, times, path, label=None):
    plt = _plt()
    t = np.asarray(ds["time"].values)
    chosen, note = choose_times(ds, times)
    idx = sorted({int(np.argmin(np.abs(t - x))) for x in chosen})
    fig, axes = plt.subplots(
        len(idx), 1, figsize=(11, 3.3 * len(idx) + 0.9), squeeze=False, layout="constrained"
    )
    axes = axes[:, 0]
    # one x window wide enough for the vehicle at every chosen time, moved with the vehicle
    width = max(float(np.ptp(ds["pin_x"].values[i])) for i in idx) + 1.6
    ranges = []
    for i in idx:
        cx = 0.5 * (float(ds["pin_x"].values[i].min()) + float(ds["pin_x"].values[i].max()))
        ranges.append((cx - width / 2, cx + width / 2))
    scale = _arrow_scale(ds, idx, ranges)
    for ax, i, xr_ in zip(axes, idx, ranges):
        draw_configuration(ax, ds, i, x_range=xr_, force_scale=scale)
    _tension_colorbar(fig, list(axes))
    soil = ("\nsoft soil: the rut made up to each time (pale sand) below the original surface (dashed)"
            if S.is_soil(ds) else "")
    parts = ("\nclosed track: sprocket with its teeth (blue, the line marks its turn), "
             "idler on its guide (bronze bar), support rollers" if G.is_closed(ds) else "")
    fig.suptitle(_wrap(f"{label or _name(ds)}: configuration (cf. Figs. 8-10){_status_note(ds)}{note}", 120)
                 + f"\narrows: wheel-track force on the wheels (red), total ground force (purple, its size "
                 f"written at its tail), 1 m = {1e-3 / scale:.0f} kN{parts}{soil}", fontsize=9.5)
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
    fig.suptitle(_wrap(title + _status_note(ds)) + note, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def plot_run(ds_or_path, out_dir, times=None, label=None):
    """Write the run's figures as PNG files into out_dir; returns their paths.

    configuration.png  the vehicle at `times` (Figs. 8-10)
    wheel_force.png    vertical wheel-track force of wheels 1, 3, 5 (Figs. 11-14)
    chassis_ay.png     chassis vertical acceleration (Figs. 15-16)
    chassis_vx.png     chassis horizontal velocity (Fig. 17)
    energy.png         energies and the energy-balance deviation (Fig. 18)
    drive.png          closed track: sprocket torque, track and chassis speed, idler force
    traction.png       soft soil or a drawbar: slip, drawbar pull, deepest sinkage
    times None: default_times(ds); given times outside the run are left out (said in the
    title).
    Titles start with `label`, default run_label: the study, run id and grid values."""
    ds = load_run(ds_or_path)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    name = label or run_label(ds, None if hasattr(ds_or_path, "data_vars") else ds_or_path)
    paths = [plot_configuration(ds, times, out / "configuration.png", label=name)]
    wheels = _wheels_to_show(ds)
    fy = ds["wheel_force_y"]
    paths.append(
        _time_plot(
            out / "wheel_force.png",
            f"{name}: vertical contact force between road wheel and track (cf. Figs. 11-14)",
            [
                (f"wheel {w}: F_y (kN)", [(fy.sel(wheel=w).values / 1e3, "", {"color": "C0", "lw": 0.9})])
                for w in wheels
            ],
            ds,
        )
    )
    paths.append(
        _time_plot(
            out / "chassis_ay.png",
            f"{name}: vertical acceleration of the chassis mass centre (cf. Figs. 15-16)",
            [("a_y (m/s$^2$)", [(ds["chassis_ay"].values, "", {"color": "C3", "lw": 0.8})])],
            ds,
        )
    )
    paths.append(
        _time_plot(
            out / "chassis_vx.png",
            f"{name}: horizontal velocity of the chassis mass centre (cf. Fig. 17)",
            [("v_x (m/s)", [(ds["chassis_vx"].values, "", {"color": "C2", "lw": 1.0})])],
            ds,
        )
    )
    paths.append(_plot_energy(ds, name, out / "energy.png"))
    if G.is_closed(ds) and "sprocket_torque" in ds:
        paths.append(_plot_drive(ds, name, out / "drive.png"))
    if (
        "sinkage" in ds
        or "drawbar_pull" in ds
        or ("drawbar_load" in ds and np.any(ds["drawbar_load"].values != 0))
    ):
        paths.append(_plot_traction(ds, name, out / "traction.png"))
    return paths


def _plot_energy(ds, name, path):
    """The energies and the balance deviation (Fig. 18); with dampers, friction, soil or a
    drive, what left on purpose and the balance that accounts for it."""
    e = [
        (ds[v].values / 1e3, label, {"lw": 1.0, "color": c})
        for v, label, c in (
            ("energy_kinetic", "kinetic", "C0"),
            ("energy_elastic", "elastic (torsion bars, links, pads)", "C2"),
            ("energy_gravity", "gravity potential (from t = 0)", "C1"),
            ("energy_balance", "balance (sum)", "k"),
        )
    ]
    deviation = [(100 * ds["energy_balance_error"].values, "energy balance", {"color": "k", "lw": 0.9}),
                 (100 * ds["energy_residual"].values, "work-based residual", {"color": "C3", "lw": 0.9})]
    accounted = accounted_balance(ds)
    if accounted is not None:
        # energy that left on purpose (dampers, friction, soil, drawbar) added back, the drive's taken out
        closed, label = accounted
        dissipated = ds["energy_dissipated"].values
        e.append(
            (dissipated / 1e3, "dissipated (dampers, friction, soil, drawbar)", {"color": "C5", "lw": 1.0})
        )
        if "drive_work" in ds:
            e.append((ds["drive_work"].values / 1e3, "drive work", {"color": "C6", "lw": 1.0}))
        e0 = float(ds.attrs["initial_total_energy"])
        e.append(
            (
                (ds["energy_balance"].values[0] + e0 * (closed - closed[0])) / 1e3,
                label,
                {"color": "C4", "lw": 1.0},
            )
        )
        deviation.append((100 * closed, label, {"color": "C4", "lw": 0.9}))
    return _time_plot(path, f"{name}: energies (cf. Fig. 18)",
                      [("energy (kJ)", e), ("balance deviation (% of E0)", deviation)], ds)


def _plot_drive(ds, name, path):
    """Closed track: the drive's torque, the track's speed at the sprocket against the chassis
    speed, the tensioner's force."""
    rp = float(G.closed_layout(ds)["pitch_radius"])
    speeds = [(ds["sprocket_speed"].values * rp, f"sprocket speed x pitch radius ({rp:.3f} m)",
               {"color": "C0", "lw": 1.0}),
              (ds["chassis_vx"].values, "chassis speed", {"color": "C2", "lw": 1.0})]
    panels = [
        ("sprocket torque (kN m)", [(ds["sprocket_torque"].values / 1e3, "", {"color": "C3", "lw": 0.9})]),
        ("speed (m/s)", speeds),
    ]
    if "idler_force" in ds:
        panels.append(("idler force (kN),\noutward positive", [(ds["idler_force"].values / 1e3, "",
                                                               {"color": "C4", "lw": 0.9})]))
    return _time_plot(path, f"{name}: the drive", panels, ds)


def _plot_traction(ds, name, path):
    """Soft soil or a drawbar: slip (the sprocket's), drawbar pull and load, the deepest sinkage."""
    panels = []
    slip = ds["slip"].values if "slip" in ds else None
    if slip is None and G.is_closed(ds) and "sprocket_speed" in ds:
        track = ds["sprocket_speed"].values * float(G.closed_layout(ds)["pitch_radius"])
        with np.errstate(divide="ignore", invalid="ignore"):
            slip = np.where(track != 0, 1.0 - ds["chassis_vx"].values / track, np.nan)
    if slip is not None:
        panels.append(
            (
                "slip at the sprocket (%)",
                [
                    (
                        100 * slip,
                        "1 - chassis speed / (sprocket speed x pitch radius)",
                        {"color": "C0", "lw": 0.9},
                    )
                ],
            )
        )
    pull = []
    if "drawbar_pull" in ds:
        pull.append(
            (
                ds["drawbar_pull"].values / 1e3,
                "drawbar pull (ground's net horizontal force on the track)",
                {"color": "C1", "lw": 0.9},
            )
        )
    if "drawbar_load" in ds and np.any(ds["drawbar_load"].values != 0):
        pull.append((ds["drawbar_load"].values / 1e3, "drawbar load on the chassis (rearward positive)",
                     {"color": "C7", "lw": 0.9}))
    if pull:
        panels.append(("force (kN)", pull))
    if "sinkage" in ds:
        deepest = np.max(ds["sinkage"].values, axis=1)
        panels.append(("deepest sinkage (cm)", [(100 * deepest, "deepest pin", {"color": "C5", "lw": 0.9})]))
    return _time_plot(path, f"{name}: slip, drawbar pull, sinkage", panels, ds)


