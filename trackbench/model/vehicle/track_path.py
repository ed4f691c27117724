"""The track's taut paths: the open track's under the road wheels (where the equilibrium
search starts, what scenario validation checks a track length against), and the closed
loop around sprocket, idler and road wheels (plain numpy: no compiler)."""

import numpy as np


def _chain(pts):
    """One half of the convex hull of points sorted along x (Andrew's monotone chain): the
    lower half for points in increasing order, the upper for decreasing."""
    out = []
    for p in pts:
        while len(out) >= 2:
            (x1, y1), (x2, y2) = out[-2], out[-1]
            if (x2 - x1) * (p[1] - y1) - (y2 - y1) * (p[0] - x1) <= 0.0:
                out.pop()
            else:
                break
        out.append(p)
    return out


def _lower_hull(points):
    """Lower convex hull, left to right."""
    return np.array(_chain(sorted(map(tuple, points))))


def initial_track(ends_world, wheel_centres, rho, n_links):
    """Pins spread evenly along the taut path: the lower convex hull of the track ends
    and the wheel circles of radius rho (wheel radius + pad: one, or one per wheel). Pin 0 is
    the front end."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    ang = np.linspace(0.0, 2 * np.pi, 361)[:-1]
    rhos = np.broadcast_to(rho, (len(wheel_centres),))
    circ = [c + r * np.column_stack([fm.vcos(ang), fm.vsin(ang)]) for c, r in zip(wheel_centres, rhos)]
    hull = _lower_hull(np.vstack([ends_world] + circ))
    hull = hull[::-1]  # front (largest x) to rear
    seg = fm.vhypot(*np.diff(hull, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    target = np.linspace(0.0, s[-1], n_links + 1)
    pins = np.column_stack([np.interp(target, s, hull[:, 0]), np.interp(target, s, hull[:, 1])])
    return pins, s[-1], hull


def _hull(points):
    """Convex hull, counter-clockwise, no repeated first point."""
    pts = sorted(set(map(tuple, points)))
    return np.array(_chain(pts)[:-1] + _chain(pts[::-1])[:-1])


def closed_loop(circles, samples=2048):
    """The taut closed loop around circles (cx, cy, r): the convex hull of the circles, as a
    closed polygon (counter-clockwise, first point repeated at the end) with each circle
    sampled at `samples` points (the hull's length then errs by about r (pi / samples)^2 / 6
    per unit of wrapped arc), and its length."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    ang = np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
    ring = np.column_stack([fm.vcos(ang), fm.vsin(ang)])
    pts = np.vstack([np.array(c[:2]) + c[2] * ring for c in circles])
    hull = _hull(pts)
    hull = np.vstack([hull, hull[:1]])
    return hull, float(fm.vhypot(*np.diff(hull, axis=0).T).sum())


def _dense(hull, ds):
    """The closed polygon resampled every ~ds of arc length: (points, arc lengths)."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    s = np.concatenate([[0.0], np.cumsum(fm.vhypot(*np.diff(hull, axis=0).T))])
    t = np.linspace(0.0, s[-1], int(np.ceil(s[-1] / ds)) + 1)
    return np.column_stack([np.interp(t, s, hull[:, 0]), np.interp(t, s, hull[:, 1])]), t


def _walk(dense, arc, chord, n):
    """n pins from dense[0] on, each the first point of the loop at distance `chord` beyond
    the last: (pins, arc length at which the n-th step lands, beyond one turn if it does)."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    pins = [dense[0]]
    k = 0
    window = 2 + int(np.ceil(4.0 * chord / (arc[1] - arc[0])))   # a chord spans less arc than this
    for _ in range(n):
        d = fm.vhypot(*(dense[k + 1:k + 1 + window] - pins[-1]).T)
        hit = np.flatnonzero(d >= chord)
        if hit.size == 0:
            return np.array(pins), arc[-1] + chord
        j = k + 1 + hit[0]
        d0 = fm.vhypot(*(dense[j - 1] - pins[-1]))
        f = (chord - d0) / (d[hit[0]] - d0)
        pins.append(dense[j - 1] + f * (dense[j] - dense[j - 1]))
        k = j - 1
    return np.array(pins[:-1]), arc[k] + f * (arc[k + 1] - arc[k])


def closed_track(circles, n_links, ds=2e-4):
    """n_links pins on closed_loop(circles), every link of the same length (the chord, found
    by bisection so that the loop closes), pin 0 at the hull's first point: (pins of shape
    (n_links, 2), link length)."""
    hull, length = closed_loop(circles)
    dense, arc = _dense(hull, ds)
    dense = np.vstack([dense, dense[1:]])        # two turns: the last step may pass the start
    arc = np.concatenate([arc, arc[-1] + arc[1:]])
    lo, hi = 0.5 * length / n_links, length / n_links
    for _ in range(60):
        chord = 0.5 * (lo + hi)
        pins, end = _walk(dense, arc, chord, n_links)
        lo, hi = (chord, hi) if end < length else (lo, chord)
    return pins, chord


def link_count(loop_length, link_length, tension, stiffness):
    """Links of a closed track whose loop, stretched by `tension` (each link by tension /
    stiffness, Eq. 8), is closest to loop_length."""
    return max(3, int(round(loop_length / (link_length + tension / stiffness))))
