"""The paper's result figures (Figs. 8-18 of Lee, 2000) as PNG files, and study plots.

    plot_run(ds_or_path, out_dir, times=None) -> [PNG paths]   # times: default_times(ds)
    plot_study(study_dir, out_dir) -> [PNG paths]      # one figure per grid axis (+ drawbar pull
                                                       #   against slip for drawbar studies)

matplotlib is an optional dependency (extra "plot"); it is imported here only.
"""

import json
import re
import textwrap
from pathlib import Path

import numpy as np

from ..quantities import accounted_balance
from . import geometry as G

PAPER_TIMES = (0.1, 0.35, 0.45)   # the paper's Figs. 8-10 (a 0.5 s run)
DEFAULT_TIMES = PAPER_TIMES       # what `trackbench plot --times` passes when not given: see plot_run
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


def _wrap(text, width=95):
    """Long titles broken into lines (each paragraph on its own)."""
    return "\n".join(textwrap.fill(line, width) for line in text.split("\n"))


# ------------------------------------------------------------ parameters and their units ----

# units of parameters whose rule text (trackbench/scenario.py) names none
_UNITS = {"output_interval": "s", "vehicle.chassis_mass": "kg", "vehicle.chassis_inertia": "kg m^2",
          "vehicle.arm_mass": "kg", "vehicle.arm_inertia": "kg m^2", "vehicle.arm_length": "m",
          "vehicle.torsion_stiffness": "N m/rad", "vehicle.wheel_radius": "m", "vehicle.pivot_spacing": "m",
          "track.link_length": "m", "track.pin_mass": "kg", "track.link_stiffness": "N/m", "track.pad_wheel": "m",
          "track.pad_ground": "m", "track.wheel_stiffness": "N/m", "track.ground_stiffness": "N/m",
          "sprocket.seat_radius": "m", "sprocket.pin_radius": "m", "sprocket.stiffness": "N m/rad",
          "sprocket.inertia": "kg m^2", "idler.radius": "m", "idler.mass": "kg", "idler.stiffness": "N/m",
          "idler.damping": "N s/m", "idler.travel": "m", "rollers.radius": "m", "drive.gain_p": "N m s/rad",
          "drive.gain_i": "N m/rad", "drive.torque_limit": "N m", "terrain.gap": "m"}
_UNIT_PARTS = {"m", "s", "N", "kg", "deg", "rad", "Pa", "kPa", "2", "3"}


def _is_unit(text):
    parts = [x for x in re.split(r"[ /^]", text.strip()) if x]
    return bool(parts) and all(x in _UNIT_PARTS for x in parts)


def parameter_unit(name):
    """The unit of a scenario parameter ('' when it has none): from its rule's text in
    trackbench/scenario.py ("a number in [0, 100] m/s", "(N; 0: derived ...)"), else from a
    table of the parameters whose rule text names none."""
    from ..scenario import RULES, TERRAIN_RULES
    rule = RULES.get(name) or (TERRAIN_RULES.get(name[len("terrain."):]) if name.startswith("terrain.") else None)
    text = rule[3] if rule else ""
    m = re.search(r"[\])]\s+([^(;:]+?)\s*(?:\(|$)", text)
    if m and _is_unit(m.group(1)):
        return m.group(1).strip()
    for m in re.finditer(r"\(([^;:,()]+)[;:,)]", text):
        if _is_unit(m.group(1)):
            return m.group(1).strip()
    return _UNITS.get(name, "")


def display_scale(name, values=()):
    """(factor, unit) a parameter is shown in: slips in %, forces of 10 kN and more in kN,
    torques in kN m; else (1, its unit)."""
    if name.endswith("slip"):
        return 100.0, "%"
    unit = parameter_unit(name)
    big = np.nanmax(np.abs(np.asarray(values, dtype=float))) >= 1e4 if len(values) else False
    if unit in ("N", "N m") and big:
        return 1e-3, "k" + unit
    return 1.0, unit


def axis_label(name, values=()):
    k, unit = display_scale(name, values)
    extra = ", at the sprocket" if name == "drawbar.slip" else ""
    return f"{name} ({unit}{extra})" if unit else name


def _parsed(value):
    if isinstance(value, str) and value[:1] in "{[":
        try:
            return json.loads(value)
        except ValueError:
            return value
    return value


def terrain_label(t):
    """A short name of a terrain table: kind, height (and length), soil."""
    if not isinstance(t, dict):
        return str(t)
    kind = t.get("kind", "terrain")
    if kind == "sequence":
        text = " + ".join(terrain_label(o) for o in t.get("obstacles", []))[:60] or "sequence"
    elif kind == "points":
        text = f"points ({len(t.get('points', []))})"
    else:
        text = kind
        if "height" in t:
            text += f" {float(t['height']):g} m"
        if "length" in t:
            text += f" x {float(t['length']):g} m"
    soil = t.get("soil")
    if soil not in (None, "rigid"):
        text += f", {soil if isinstance(soil, str) else 'soil table'}"
    return text


def value_label(name, value):
    """A parameter's value for a title, a legend or a tick: '12.5 m/s', 'bump 0.1 m x 0.6 m'."""
    v = _parsed(value)
    if isinstance(v, dict):
        return terrain_label(v)
    if isinstance(v, (list, tuple)):
        return json.dumps(v, separators=(",", ":"))[:30]
    if isinstance(v, (bool, np.bool_)) or isinstance(v, str):
        return str(v)
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    k, unit = display_scale(name, [x])
    return f"{x * k:g} {unit}".strip()


def run_label(ds, path=None):
    """What a run's figure titles start with: the study, the run id and the run's grid values
    (run.json beside a study's timeseries.nc), e.g. 'speed_sweep run 1a2b3c4d: speed 12.5 m/s,
    terrain.height 0.1 m'; a run outside a study: its scenario's name."""
    name = _name(ds)
    if path is None:
        return name
    try:
        rec = json.loads((find_timeseries(path).parent / "run.json").read_text())
    except (OSError, ValueError):
        return name
    text = f"{rec.get('study', name)} run {str(rec.get('run_id', ''))[:8]}".rstrip()
    params = rec.get("params") or {}
    if rec.get("replicate"):
        params = {**params, "replicate": rec["replicate"]}
    if params:
        text += ": " + ", ".join(f"{k} {value_label(k, v)}" for k, v in params.items())
    return text


def _status_note(ds):
    if ds.attrs.get("status", "completed") == "completed":
        return ""
    return f"  [run {ds.attrs.get('status')} at t = {float(ds.attrs.get('t_final', np.nan)):.4f} s]"


# --------------------------------------------------------------------------------- run ----

def draw_configuration(ax, ds, i, x_range=None, arrows=True, colorbar=False, force_scale=G.FORCE_SCALE):
    """Side view of output frame i on a matplotlib Axes (metres, equal aspect). The frame holds
    the vehicle and the ground under it; force arrows are drawn at `force_scale` (m per N):
    the ground force's tail, which comes from below the ground, is cut at the frame's bottom
    edge and its size written beside its head."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle, Polygon

    g = G.side_view(ds, [i])
    pins, wheels = g["pins"][0], g["wheels"][0]
    r = float(ds.attrs["wheel_radius"])
    if x_range is None:
        x_range = (min(pins[:, 0].min(), g["chassis"][0][:, 0].min()) - 0.4,
                   max(pins[:, 0].max(), g["chassis"][0][:, 0].max()) + 0.4)
    ground = G.ground_polyline(ds, (x_range[0] - 1.0, x_range[1] + 1.0))
    y_floor = float(ground[:, 1].min()) - 0.4
    surface = ground
    if G.is_soil(ds):
        # soft soil: the ground lowered by the rut made up to this frame (geometry.soil_surface);
        # the soil pressed out of the way (between the original surface and the dent) is pale
        # sand under a dashed line at the original surface
        base, drop = G.soil_surface(ds, [i], (x_range[0] - 1.0, x_range[1] + 1.0))
        surface = base - np.stack([np.zeros_like(drop[0]), drop[0]], axis=-1)
        ax.fill_between(base[:, 0], base[:, 1], surface[:, 1], facecolor=SOIL_DENT, edgecolor="none", zorder=1.1)
        ax.plot(ground[:, 0], ground[:, 1], color="#785528", lw=0.8, ls=(0, (4, 3)), zorder=1.2)
        y_floor = min(y_floor, float(surface[:, 1].min()) - 0.4)
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
        note = (f"; {', '.join(f'{x:g}' for x in out)} s left out: the run covers {t[0]:.3g} .. {t[-1]:.4g} s")
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
    fig, axes = plt.subplots(len(idx), 1, figsize=(11, 3.3 * len(idx) + 0.9), squeeze=False, layout="constrained")
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
            if G.is_soil(ds) else "")
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
    times None (or the paper's times, which `trackbench plot` passes when --times is not
    given): default_times(ds); given times outside the run are left out (said in the title).
    Titles start with `label`, default run_label: the study, run id and grid values."""
    ds = load_run(ds_or_path)
    if times is not None and tuple(float(x) for x in times) == PAPER_TIMES:
        times = None
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    name = label or run_label(ds, None if hasattr(ds_or_path, "data_vars") else ds_or_path)
    paths = [plot_configuration(ds, times, out / "configuration.png", label=name)]
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
    if G.is_closed(ds) and "sprocket_torque" in ds:
        paths.append(_plot_drive(ds, name, out / "drive.png"))
    if "sinkage" in ds or "drawbar_pull" in ds or ("drawbar_load" in ds and np.any(ds["drawbar_load"].values != 0)):
        paths.append(_plot_traction(ds, name, out / "traction.png"))
    return paths


def _plot_drive(ds, name, path):
    """Closed track: the drive's torque, the track's speed at the sprocket against the chassis
    speed, the tensioner's force."""
    rp = float(G.closed_layout(ds)["pitch_radius"])
    speeds = [(ds["sprocket_speed"].values * rp, f"sprocket speed x pitch radius ({rp:.3f} m)",
               {"color": "C0", "lw": 1.0}),
              (ds["chassis_vx"].values, "chassis speed", {"color": "C2", "lw": 1.0})]
    panels = [("sprocket torque (kN m)", [(ds["sprocket_torque"].values / 1e3, "", {"color": "C3", "lw": 0.9})]),
              ("speed (m/s)", speeds)]
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
        panels.append(("slip at the sprocket (%)", [(100 * slip, "1 - chassis speed / (sprocket speed x pitch radius)",
                                                     {"color": "C0", "lw": 0.9})]))
    pull = []
    if "drawbar_pull" in ds:
        pull.append((ds["drawbar_pull"].values / 1e3, "drawbar pull (ground's net horizontal force on the track)",
                     {"color": "C1", "lw": 0.9}))
    if "drawbar_load" in ds and np.any(ds["drawbar_load"].values != 0):
        pull.append((ds["drawbar_load"].values / 1e3, "drawbar load on the chassis (rearward positive)",
                     {"color": "C7", "lw": 0.9}))
    if pull:
        panels.append(("force (kN)", pull))
    if "sinkage" in ds:
        deepest = np.max(ds["sinkage"].values, axis=1)
        panels.append(("deepest sinkage (cm)", [(100 * deepest, "deepest pin", {"color": "C5", "lw": 0.9})]))
    return _time_plot(path, f"{name}: slip, drawbar pull, sinkage", panels, ds)


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


MAX_LINES = 6        # one line per value of the other axes up to this many, else the median
_STYLES = [("-", "o"), ("--", "s"), (":", "^"), ("-.", "D"), ((0, (5, 1, 1, 1, 1, 1)), "v"), ((0, (1, 3)), "P")]


def _run_scenarios(src):
    """run id -> resolved scenario, from the study's runs.json ({} without one)."""
    try:
        runs = json.loads((src.parent / "runs.json").read_text())["runs"]
    except (OSError, ValueError, KeyError, TypeError):
        return {}
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
        return (str(p.get("kind", "")), float(p.get("height", 0.0) or 0.0), float(p.get("length", 0.0) or 0.0), "")
    return ("", 0.0, 0.0, str(v))


def _groups(df, others, xs):
    """[(label, row mask)]: one group per combination of the other axes' values when some x
    holds runs of several combinations and there are at most MAX_LINES of them; else one
    group of every run (label None)."""
    import pandas as pd
    if not others:
        return [(None, np.ones(len(df), bool))], False
    key = df[others].astype(object).where(df[others].notna(), None).apply(
        lambda r: json.dumps([None if v is None else (v if isinstance(v, str) else float(v)) for v in r]), axis=1)
    valid = np.isfinite(xs)
    mixed = pd.Series(key[valid].to_numpy()).groupby(xs[valid]).nunique().gt(1).any() if valid.any() else False
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
        label = ", ".join(f"{a} {value_label(a, v)}" for a, v in zip(others, vals) if v is not None) or "others"
        out.append((label, (key == k).to_numpy()))
    return out, False


def plot_study(study_dir, out_dir):
    """A peak-force-against-parameter figure per grid axis (study_<axis>.png); returns the paths.
    Completed runs only, failed runs are marked on the x axis. With other axes varying too:
    one line per combination of their values (up to MAX_LINES; the line joins the medians of
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
    wheel_cols = _wheel_columns(df)
    from ..quantities import PEAKS
    other_cols = [q.name for q in PEAKS if q.unit == "kN" and not q.per_wheel and q.name in df.columns]
    completed = (df["status"] == "completed").to_numpy() if "status" in df.columns else np.ones(len(df), bool)
    paths = []
    for axis in axes:
        col = _axis_column(df, axis, src)
        numeric = pd.api.types.is_numeric_dtype(col)
        if numeric:
            scale, _ = display_scale(axis, col.dropna().to_numpy())
            x_all = col.astype(float).to_numpy() * scale
            order = np.unique(x_all[np.isfinite(x_all)])
        else:
            raw = sorted(col.dropna().unique(), key=_category_key)
            where = {v: k for k, v in enumerate(raw)}
            x_all = col.map(where).astype(float).to_numpy()
            order = np.arange(len(raw), dtype=float)
        # axes zipped with this one (one value per x) are not others: they go with it
        valid = completed & np.isfinite(x_all)
        present = [a for a in axes if a != axis and df[a][valid].notna().any()]
        tied = [a for a in present if df[a][valid].astype(str).groupby(x_all[valid]).nunique().max() <= 1]
        others = [a for a in present if a not in tied]
        groups, too_many = _groups(df, others, np.where(completed, x_all, np.nan))
        panels = [("peak vertical wheel-track force (kN)", wheel_cols)]
        if other_cols:
            panels.append(("peak force (kN)", other_cols))
        fig, axs = plt.subplots(len(panels), 1, figsize=(10 if groups[0][0] else 8, 3.4 * len(panels) + 0.7),
                                sharex=True, squeeze=False, layout="constrained")
        for ax, (ylabel, cols) in zip(axs[:, 0], panels):
            for k, c in enumerate(cols):
                y = df[c].astype(float).to_numpy() / 1e3
                label = (f"wheel {_wheel_of(c)}" if _wheel_of(c) is not None
                         else c.replace("peak_", "peak ").replace("_", " "))
                for gi, (glabel, mask) in enumerate(groups):
                    ls, marker = _STYLES[gi % len(_STYLES)] if glabel else ("-", "o")
                    m = mask & completed & np.isfinite(x_all)
                    ax.plot(x_all[m], y[m], marker, ls="none", color=f"C{k}", ms=4, alpha=0.6)
                    med = np.array([np.nanmedian(y[m][x_all[m] == v]) if np.any(x_all[m] == v) else np.nan
                                    for v in order])
                    fin = np.isfinite(med)
                    ax.plot(order[fin], med[fin], ls=ls, color=f"C{k}", lw=1.3, label=label if gi == 0 else None)
            bad = ~completed & np.isfinite(x_all)
            if bad.any():
                ax.plot(x_all[bad], np.zeros(int(bad.sum())), "x", color="red", ms=8, mew=2,
                        label=f"failed run ({int(bad.sum())})", clip_on=False)
            ax.set_ylabel(ylabel)
            ax.grid(True, alpha=0.3)
            if groups[0][0]:
                # one legend (the layout makes room for it): colours are the quantities, line
                # styles and markers the other axes' values
                handles, labels = ax.get_legend_handles_labels()
                blank = plt.Line2D([], [], ls="none")
                handles += [blank] + [plt.Line2D([], [], color="k", ls=_STYLES[gi % len(_STYLES)][0],
                                                 marker=_STYLES[gi % len(_STYLES)][1], ms=4, lw=1.1)
                                      for gi in range(len(groups))]
                labels += ["line:"] + [_wrap(g[0], 34) for g in groups]
                ax.legend(handles, labels, fontsize=7.5, loc="upper left", bbox_to_anchor=(1.01, 1.0))
            else:
                ax.legend(fontsize=8, ncol=2)
        if not numeric:
            labels = [value_label(axis, v) for v in raw]
            tilt = max(map(len, labels), default=0) > 12 or len(labels) > 6
            axs[-1, 0].set_xticks(range(len(raw)), labels, rotation=25 if tilt else 0, ha="right" if tilt else "center")
        axs[-1, 0].set_xlabel(axis_label(axis, col.dropna().to_numpy() if numeric else ()))
        if groups[0][0]:
            note = f" (one line per {', '.join(others)}; points: every completed run)"
        elif too_many or (others and np.isfinite(x_all).sum() > len(order)):
            note = f" (points: every run over {', '.join(others)}; line: median)"
        else:
            note = ""
        if tied:
            note += f"; {', '.join(tied)} {'goes' if len(tied) == 1 else 'go'} with {axis}"
        fig.suptitle(_wrap(f"study {src.parent.name}: peak forces against {axis}{note}", 110 if groups[0][0] else 85),
                     fontsize=10)
        path = out / f"study_{axis.replace('.', '_').replace('/', '_')}.png"
        fig.savefig(path, dpi=DPI)
        plt.close(fig)
        paths.append(path)
    ok = df[completed]
    drawbar = _plot_drawbar_pull(src, ok, out, has_drawbar=_has_drawbar(df, axes))
    return paths + ([drawbar] if drawbar else [])


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
    from ..traction import has_traction, run_soil, steady, wong
    if not has_traction(ds):
        return None
    sc = json.loads(ds.attrs["scenario"])
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
            ax.plot(100 * np.array([p["track_slip"] for p in free]), [p["pull"] / 1e3 for p in free], "o",
                    color=f"C{k}", mfc="none", ms=6, ls="none", label=f"{name}: free-running runs (no drawbar)")
    ax.set_xlabel("slip the soil sees (%): 1 - chassis speed / the track's speed in the contact")
    ax.set_ylabel("drawbar pull (kN)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    ax.set_title(_wrap(f"study {src.parent.name}: drawbar pull against the soil's slip (means over each run's "
                       "second half); the numbers at the points: the slip at the sprocket the towing rig held", 90),
                 fontsize=10)
    path = out / "study_drawbar_pull.png"
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path
