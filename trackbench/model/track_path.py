"""The track's taut path around the road wheels: where the equilibrium search starts and
what scenario validation checks a track length against (plain numpy: no compiler)."""

import numpy as np


def _lower_hull(points):
    """Lower convex hull, left to right (Andrew's monotone chain)."""
    pts = sorted(map(tuple, points))
    hull = []
    for p in pts:
        while len(hull) >= 2:
            (x1, y1), (x2, y2) = hull[-2], hull[-1]
            if (x2 - x1) * (p[1] - y1) - (y2 - y1) * (p[0] - x1) <= 0.0:
                hull.pop()
            else:
                break
        hull.append(p)
    return np.array(hull)


def initial_track(ends_world, wheel_centres, rho, n_links):
    """Pins spread evenly along the taut path: the lower convex hull of the track ends
    and the wheel circles of radius rho (wheel radius + pad). Pin 0 is the front end."""
    ang = np.linspace(0.0, 2 * np.pi, 361)[:-1]
    circ = [c + rho * np.column_stack([np.cos(ang), np.sin(ang)]) for c in wheel_centres]
    hull = _lower_hull(np.vstack([ends_world] + circ))
    hull = hull[::-1]  # front (largest x) to rear
    seg = np.hypot(*np.diff(hull, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    target = np.linspace(0.0, s[-1], n_links + 1)
    pins = np.column_stack([np.interp(target, s, hull[:, 0]), np.interp(target, s, hull[:, 1])])
    return pins, s[-1], hull
