"""What the side view draws of soft soil: the rut cells and the surface lowered by the ruts
so far."""

import numpy as np

from trackbench.outputs.geometry import ground_polyline, ground_vertices, scenario_of


def is_soil(ds):
    """True for a soft-soil run (terrain.soil not "rigid"): its Dataset holds the rut."""
    return "rut_depth" in ds.variables and "sinkage" in ds.variables


def _rut_cells(ds):
    """The soil's memory cells: centres rut_x (k,), their edges (k + 1,), rut_depth (k,)."""
    rx = np.asarray(ds.variables["rut_x"].values, dtype=float)
    depth = np.asarray(ds.variables["rut_depth"].values, dtype=float)
    dx = float(rx[1] - rx[0]) if rx.size > 1 else 0.01
    edges = rx[0] - 0.5 * dx + dx * np.arange(rx.size + 1) if rx.size else np.zeros(0)
    return rx, edges, depth


def running_sinkage(ds, idx, edges):
    """Deepest sinkage so far along the rut: (len(idx), k) at the frames idx (sorted), and
    (k,) after the last sample of the run, at the centres of the cells between edges. The
    soil's own rule raises its memory (model.soil_force.raise_memory: nodes at the cell
    centres, raised under each sunk pin's shoe); here it is replayed on the pins'
    output samples instead of after every step."""
    from trackbench.model.ground.soil_jit import replay_memory

    k = len(edges) - 1
    idx = np.asarray(idx, dtype=np.intp)
    out = np.zeros((len(idx), max(k, 0)))
    if k <= 0:
        return out, np.zeros(0)
    px = np.ascontiguousarray(ds.variables["pin_x"].values, dtype=float)
    sink = np.ascontiguousarray(ds.variables["sinkage"].values, dtype=float)
    dx = float(edges[1] - edges[0])
    shoe = float(scenario_of(ds)["track"]["link_length"])
    last = replay_memory(px, sink, float(edges[0]), dx, shoe, idx, out)
    return out, last


def soil_surface(ds, idx, x_range=None):
    """The deformed soil surface at the frames idx: the ground polyline (clipped to x_range,
    default the covered range) lowered by the rut made up to each frame.

    Returns (base (m, 2), drop (len(idx), m)): the surface of frame j is base with y - drop[j].
    base holds the ground's vertices and the centres of the rut cells that hold a rut or
    border one (the rut is drawn from cell centre to cell centre; it tapers to nothing over
    the half-cell beyond its first and last cells).

    The rut up to time t at a cell centre is rebuilt from the outputs: the soil's memory
    replayed on the pin samples <= t (running_sinkage), scaled per cell by
    rut_depth / (that memory after the run's last sample). Chosen over the bare "deepest
    sinkage so far" so that the last frame draws exactly the Dataset's rut_depth: the soil
    keeps only the plastic part (it springs back by the elastic part, a few per cent), and
    the pins are sampled at output times only, so the replayed memory can miss or overshoot
    the true one by a sample's travel. Cells the replay never reached (a pin passed over
    one between two output samples) take the history of the nearest cell it reached,
    scaled to their own rut_depth. The drop is vertical, by depth / cos(slope) of
    the ground segment under the point: the soil's sinkage is along the segment's normal."""
    ground = ground_polyline(ds, x_range)
    idx = np.asarray(idx, dtype=np.intp)
    rx, edges, depth = _rut_cells(ds)
    if rx.size:
        near = np.convolve((depth > 0.0).astype(float), np.ones(3), mode="same") > 0.0  # a rut or next to one
        near &= (rx > ground[0, 0]) & (rx < ground[-1, 0])
    else:
        near = np.zeros(0, dtype=bool)
    if not near.any():
        return ground, np.zeros((len(idx), len(ground)))
    hist, last = running_sinkage(ds, idx, edges)
    seen = np.flatnonzero(last > 0.0)
    cells = np.flatnonzero(near)
    if seen.size:
        # the nearest cell a pin was seen in (itself when seen)
        j = np.clip(np.searchsorted(seen, cells), 1, max(seen.size - 1, 1))
        lo_, hi_ = seen[j - 1], seen[np.minimum(j, seen.size - 1)]
        src = np.where(np.abs(cells - lo_) <= np.abs(hi_ - cells), lo_, hi_)
        rut = hist[:, src] * (depth[cells] / last[src])
    else:  # no pin sample in the soil at all: the rut appears at the last frame only
        rut = np.zeros((len(idx), cells.size))
        rut[idx == ds.sizes["time"] - 1] = depth[cells]
    # the points drawn: the cells' centres, and the outer edges of the first and last cell
    # (no rut there: the rut tapers to nothing over the half cell beyond it)
    cx = np.concatenate([[edges[0]], rx[cells], [edges[-1]]])
    rut = np.pad(rut, ((0, 0), (1, 1)))
    keep = (cx > ground[0, 0]) & (cx < ground[-1, 0])
    cx, rut = cx[keep], rut[:, keep]
    # the ground's vertices inside the rut region sink with the rut interpolated between the
    # drawn points beside them (linear weights, the same for every frame)
    gx = ground[:, 0]
    j = np.clip(np.searchsorted(cx, gx), 1, cx.size - 1)
    w = np.clip((gx - cx[j - 1]) / np.maximum(cx[j] - cx[j - 1], 1e-12), 0.0, 1.0)
    inside = (gx > cx[0]) & (gx < cx[-1])
    rut_v = np.where(inside, rut[:, j - 1] * (1.0 - w) + rut[:, j] * w, 0.0)
    # merge the cell points into the ground's vertices (stable: vertical faces keep their order)
    xs = np.concatenate([gx, cx])
    v = ground_vertices(ds)
    seg = np.clip(np.searchsorted(v[:, 0], xs, side="right") - 1, 0, len(v) - 2)
    dxs, dys = v[seg + 1, 0] - v[seg, 0], v[seg + 1, 1] - v[seg, 1]
    flat = dxs > 0.0
    u = np.where(flat, (xs - v[seg, 0]) / np.where(flat, dxs, 1.0), 0.0)
    ys = np.concatenate([ground[:, 1], (v[seg, 1] + u * dys)[len(gx) :]])
    cos = np.where(flat, np.abs(dxs) / np.hypot(dxs, np.where(flat, dys, 0.0)), 1.0)
    order = np.argsort(xs, kind="stable")
    base = np.stack([xs, ys], axis=-1)[order]
    drop = (np.concatenate([rut_v, rut], axis=1) / cos)[:, order]
    return base, drop
