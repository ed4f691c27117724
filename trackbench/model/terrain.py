"""Rigid ground: a polyline with x non-decreasing, its first and last segments
extended far, outward normals pointing up/out of the ground, convex corners found
where the polyline turns clockwise (spec, "Ground-track")."""

from dataclasses import dataclass

import numpy as np

FAR = 1000.0  # m: the first and last segments reach x = -FAR and +FAR


@dataclass(frozen=True)
class Ground:
    vertices: np.ndarray   # (n, 2), x non-decreasing, first x = -FAR, last x = +FAR
    segments: np.ndarray   # (n-1, 7): x0, y0, tx, ty, length, nx, ny
    corners: np.ndarray    # (m, 2) convex corners


def ground_from_points(points):
    """Build a Ground from interior points; extends the ends horizontally to +-FAR."""
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    left = [-FAR, pts[0, 1]] if pts[0, 0] > -FAR else None
    right = [FAR, pts[-1, 1]] if pts[-1, 0] < FAR else None
    verts = np.array(([left] if left else []) + pts.tolist() + ([right] if right else []))
    # drop repeated points so every segment has a direction
    keep = np.ones(len(verts), bool)
    keep[1:] = np.any(np.diff(verts, axis=0) != 0.0, axis=1)
    verts = verts[keep]
    d = np.diff(verts, axis=0)
    length = np.hypot(d[:, 0], d[:, 1])
    t = d / length[:, None]
    n = np.column_stack([-t[:, 1], t[:, 0]])
    seg = np.column_stack([verts[:-1], t, length, n])
    cross = t[:-1, 0] * t[1:, 1] - t[:-1, 1] * t[1:, 0]
    corners = verts[1:-1][cross < 0.0]
    return Ground(verts, np.ascontiguousarray(seg), np.ascontiguousarray(corners.reshape(-1, 2)))


def obstacle_points(kind, x, height, length=0.0):
    """Interior vertices of one obstacle starting at x on the base line y = 0."""
    if kind == "step":
        return [[x, 0.0], [x, height]]
    if kind == "ramp":
        return [[x, 0.0], [x + length, height]]
    if kind == "block":
        return [[x, 0.0], [x, height], [x + length, height], [x + length, 0.0]]
    if kind == "bump":  # a trapezoid with 45 deg flanks and a flat top of `length`
        return [[x, 0.0], [x + height, height], [x + height + length, height],
                [x + 2 * height + length, 0.0]]
    raise ValueError(kind)


def flat_ground():
    return ground_from_points([[-FAR, 0.0], [FAR, 0.0]])
