"""`trackbench vehicle show`'s side view: a vehicle at rest on level ground (run/vehicle_report.py),
each part drawn as the run figures draw it and named: hull, road wheels and arms, track,
sprocket, idler, rollers, mass centre and seat."""

from pathlib import Path

import numpy as np

from trackbench.figures.plot_common import DPI, _plt
from trackbench.outputs import geometry as G

_TEXT = dict(fontsize=7, zorder=7, color="#1f3b5a")


def _hull(st):
    """The hull's outline at rest, as the run figures draw it (geometry.hull_body)."""
    v = st.scenario["vehicle"]
    front, rear = (
        max(v["front_track_end"][0], v["rear_track_end"][0]),
        min(v["front_track_end"][0], v["rear_track_end"][0]),
    )
    bx = [rear - G.HULL_MARGIN, front + G.HULL_MARGIN, front + G.HULL_MARGIN, rear - G.HULL_MARGIN]
    by = [G.HULL_BOTTOM, G.HULL_BOTTOM, G.HULL_TOP, G.HULL_TOP]
    return st.world(np.column_stack([bx, by]))


def _track(ax, st):
    closed = st.scenario["track.layout"] == "closed"
    pins = st.pins
    links = np.vstack([pins, pins[:1]]) if closed else pins
    ax.plot(links[:, 0], links[:, 1], "-", color="#333333", lw=1.2, zorder=4)
    ax.plot(pins[:, 0], pins[:, 1], ".", color="#111111", ms=2.5, zorder=5)
    low = pins[np.argmin(pins[:, 1])]
    ax.annotate(
        "track",
        low,
        (low[0], low[1] - 0.35),
        ha="center",
        arrowprops=dict(arrowstyle="-", lw=0.6),
        **_TEXT,
    )


def _wheels(ax, st):
    from matplotlib.patches import Circle

    radii = np.broadcast_to(np.asarray(st.scenario["vehicle.wheel_radius"], float), (len(st.wheels),))
    for k, ((px, py), (wx, wy), r) in enumerate(zip(st.pivots, st.wheels, radii)):
        ax.plot([px, wx], [py, wy], color="#6e6e6e", lw=3, zorder=3, solid_capstyle="round")
        ax.plot([px], [py], "o", color="#3c3c3c", ms=3, zorder=4)
        ax.add_patch(Circle((wx, wy), r, facecolor="#f4f4f4", edgecolor="#222222", lw=1.3, zorder=3))
        ax.text(wx, wy, f"road\nwheel {k + 1}", ha="center", va="center", **_TEXT)


def _closed_parts(ax, st):
    from matplotlib.patches import Circle

    from trackbench.run.vehicle_report import closed_drawing

    for name, (x, y, r) in closed_drawing(st).items():
        ax.add_patch(Circle((x, y), r, facecolor="#e6eef6", edgecolor="#224466", lw=1.2, zorder=3))
        ax.text(x, y, name, ha="center", va="center", **_TEXT)


def draw_vehicle(ax, st):
    """Draw Statics st on the axes ax: hull, wheels and arms, track, closed-track parts,
    mass centre, seat, the ground, each named."""
    from matplotlib.patches import Polygon

    hull = _hull(st)
    ax.add_patch(Polygon(hull, closed=True, facecolor="#e9edf2", edgecolor="#3c3c3c", lw=1.5, zorder=2))
    ax.text(
        hull[:, 0].mean(), hull[2:, 1].mean() - 0.08, "hull (chassis)", ha="center", va="top", **_TEXT
    )
    _wheels(ax, st)
    _track(ax, st)
    if st.scenario["track.layout"] == "closed":
        _closed_parts(ax, st)
    cg = st.world([0.0, 0.0])[0]
    ax.plot(*cg, marker="$\\oplus$", ms=12, color="#b22222", zorder=6)
    ax.text(cg[0], cg[1] + 0.07, "mass centre", ha="center", **_TEXT)
    ax.plot(*st.seat, "s", color="#b22222", ms=6, zorder=6)
    # the seat's name below it: clear of the mass centre's above
    ax.text(st.seat[0], st.seat[1] - 0.07, "seat", ha="center", va="top", **_TEXT)
    lo, hi = (
        min(hull[:, 0].min(), st.pins[:, 0].min()) - 0.5,
        max(hull[:, 0].max(), st.pins[:, 0].max()) + 0.5,
    )
    ax.fill_between(
        [lo, hi],
        [0.0, 0.0],
        [-0.25, -0.25],
        facecolor="#d8c3a0",
        edgecolor="#785528",
        hatch="///",
        lw=1.0,
        zorder=1,
    )
    ax.text(lo + 0.1, -0.12, "level ground", va="center", **_TEXT)
    ax.set_xlim(lo, hi)
    ax.set_ylim(-0.3, hull[:, 1].max() + 0.3)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def vehicle_figure(st, path):
    """Write the side view of Statics st to path (PNG); returns the path."""
    plt = _plt()
    sc = st.scenario
    fig, ax = plt.subplots(figsize=(10, 4.2))
    draw_vehicle(ax, st)
    ax.set_title(
        f"{sc['vehicle.model']} at rest: {st.eq.weight / sc['gravity'] / 1e3:.2f} t, "
        f"{sc['vehicle.n_wheels']} road wheels, {sc['track.layout']} track",
        fontsize=10,
    )
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path
