"""The closed layout's geometry, derived from the paper's vehicle (plain numpy: scenario
validation runs it before anything compiles).

The sprocket turns where the paper fixes one track end (``sprocket.position``), the idler
sits where it fixes the other, on a guide pointing outwards. The track's centre line is the
taut loop around the road wheels (radius + pad h_w), the idler (radius + h_w), the rollers
(radius + h_w) and the sprocket's pitch circle. Derived where not given:

- link pitch under the static tension T (``track.tension``): p = L0 + T / k_tau (Eq. 8);
- sprocket pitch radius r_p = p / (2 sin(pi / N)), tip radius r_p + r_pin (the teeth as
  high as a seated pin);
- link count: the loop's length at slide 0 over p, rounded;
- the idler's slide s0 where the loop is n_links x p long, and the preload that holds the
  loop at T there: T (cos a1 + cos a2) + k_t s0, a1, a2 the angles of the two spans that
  leave the idler to its guide.
"""

import math
from dataclasses import dataclass

import numpy as np

from ..core import indices as L
from .parameters import per_wheel, wheel_centres_body
from .teeth import pitch_radius as _pitch_radius
from .track_path import closed_loop, closed_track, link_count

TOOTH_PITCH_TOLERANCE = 0.02   # the sprocket's tooth pitch within 2 % of the link pitch under tension
SEARCH_SAMPLES = 256           # points per circle of the loops the slide search measures


class ClosedLayoutError(ValueError):
    """The closed layout does not fit; the message is one line naming the culprit."""


@dataclass
class ClosedGeometry:
    n_links: int
    link_pitch: float          # link length under the static tension (m)
    pitch_radius: float
    tip_radius: float
    preload: float
    slide: float               # the idler's slide where the loop fits (m)
    sprocket: np.ndarray       # body point of the sprocket axis
    idler: np.ndarray          # body point of the idler centre at slide 0
    guide: np.ndarray          # unit direction of the guide (body frame)
    span_angles: tuple         # angles of the spans leaving the idler to its guide (rad)
    teeth: int
    pin_radius: float
    circles: list              # (x, y, radius) of the loop's centre line around every wheel, at the slide

    def resolved(self):
        """The derived values as scenario parameters."""
        return {"track.n_links": self.n_links, "sprocket.pitch_radius": self.pitch_radius,
                "sprocket.tip_radius": self.tip_radius, "idler.preload": self.preload}


def _ends(v, spr):
    front, rear = np.array(v["front_track_end"], float), np.array(v["rear_track_end"], float)
    return (rear, front) if spr["position"] == "rear" else (front, rear)


def _guide(idl, outward):
    from ..core import fixed_math as fm  # numba: loaded when first needed
    a = math.radians(idl["guide_angle"])
    return np.array([outward * fm.cos(a), fm.sin(a)])


def _circles(v, tr, idl, rol, sprocket, rp, idler_at):
    """The circles the pins wrap: the sprocket's pitch circle; round a wheel of radius r,
    the circle on which a link of length L0 touches the pad surface (r + h_w) at its
    middle, sqrt((r + h_w)^2 + (L0 / 2)^2)."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    hw = tr["pad_wheel"]

    def wrap(r):
        return fm.hypot(r + hw, 0.5 * tr["link_length"])

    c = [(x, y, wrap(r)) for (x, y), r in zip(wheel_centres_body(v), per_wheel(v, "wheel_radius"))]
    c.append((sprocket[0], sprocket[1], rp))
    c.append((idler_at[0], idler_at[1], wrap(idl["radius"])))
    c += [(x, y, wrap(rol["radius"])) for x, y in rol["positions"]]
    return c


def _slide_for(length_at, target, travel):
    """The slide in [-travel, travel] where the loop is `target` long (the Illinois
    variant of regula falsi: the length is nearly linear in the slide), or None."""
    lo, hi = -travel, travel
    f_lo, f_hi = length_at(lo) - target, length_at(hi) - target
    if f_lo > 0.0 or f_hi < 0.0:
        return None, f_lo, f_hi
    a, b, fa, fb, side = lo, hi, f_lo, f_hi, 0
    for _ in range(40):
        c = (a * fb - b * fa) / (fb - fa)
        fc = length_at(c) - target
        if abs(fc) < 1e-10 * target:
            return c, f_lo, f_hi
        if fc * fb > 0.0:
            b, fb = c, fc
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            a, fa = c, fc
            if side == 1:
                fb *= 0.5
            side = 1
    return c, f_lo, f_hi


def _span_angles(hull, idler_at, reach, guide):
    """Angles to the guide of the two spans that leave the idler: the loop's edges from
    the ends of its arc on the idler, each way round."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    pts = hull[:-1]
    on = np.abs(fm.vhypot(*(pts - idler_at).T) - reach) < 1e-9 + 1e-7 * reach
    idx = np.flatnonzero(on)
    n = len(pts)
    if idx.size == 0 or idx.size == n:
        return 0.0, 0.0
    angles = []
    for step in (1, -1):
        b = idx[0]
        while on[(b + step) % n]:
            b = (b + step) % n
        d = pts[(b + step) % n] - pts[b]
        angles.append(fm.acos(np.clip(-(d[0] * guide[0] + d[1] * guide[1]) / fm.vhypot(*d), -1.0, 1.0)))
    return tuple(angles)


def closed_geometry(v, tr, spr, idl, rol, explicit=frozenset()):
    """Everything the closed layout derives (ClosedGeometry), or ClosedLayoutError."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    n_teeth = int(spr["teeth"])
    k = tr["link_stiffness"]
    pitch = tr["link_length"] + tr["tension"] / k
    rp = spr["pitch_radius"] or _pitch_radius(pitch, n_teeth)
    tooth_pitch = 2.0 * rp * fm.sin(math.pi / n_teeth)
    if abs(tooth_pitch / pitch - 1.0) > TOOTH_PITCH_TOLERANCE:
        raise ClosedLayoutError(
            f"sprocket.teeth = {n_teeth} with pitch_radius {rp:.4g} m spaces the seats "
            f"{tooth_pitch:.4g} m apart, but "
            f"a link under track.tension is {pitch:.4g} m long; allowed: within 2 % (pitch_radius "
            f"{_pitch_radius(pitch, n_teeth):.4g} m for {n_teeth} teeth)"
        )
    rg, rpin = spr["seat_radius"], spr["pin_radius"]
    if not rpin < rg:
        raise ClosedLayoutError(
            f"sprocket.pin_radius = {rpin} m must be smaller than sprocket.seat_radius = {rg} m"
        )
    rs = rp + rg - rpin
    if 2.0 * rg >= 2.0 * rs * fm.sin(math.pi / n_teeth):
        raise ClosedLayoutError(
            f"sprocket.seat_radius = {rg} m leaves no teeth between {n_teeth} seats; allowed: "
            f"below {rs * fm.sin(math.pi / n_teeth):.4g} m"
        )
    tip = spr["tip_radius"] or rp + rpin
    if not fm.hypot(rs, rg) < tip < rp + 3.0 * rpin:
        raise ClosedLayoutError(
            f"sprocket.tip_radius = {tip:.4g} m must lie between {fm.hypot(rs, rg):.4g} m (the "
            f"seats' rims) and {rp + 3.0 * rpin:.4g} m (pitch radius + 3 pin radii)"
        )
    sprocket, idler = _ends(v, spr)
    guide = _guide(idl, 1.0 if idler[0] > sprocket[0] else -1.0)
    travel = idl["travel"]

    def length_at(s):
        return closed_loop(_circles(v, tr, idl, rol, sprocket, rp, idler + s * guide), SEARCH_SAMPLES)[1]

    n = int(tr["n_links"]) if "track.n_links" in explicit else link_count(length_at(0.0), tr["link_length"],
                                                                        tr["tension"], k)
    slide, f_lo, f_hi = _slide_for(length_at, n * pitch, travel)
    if slide is None:
        short = f_lo > 0.0
        raise ClosedLayoutError(
            f"track.n_links = {n} makes a loop {n * pitch:.4g} m long under track.tension, but the path "
            f"around sprocket, wheels and idler is {length_at(0.0):.4g} m with the idler at its guide's "
            f"middle: the idler would leave its guide (idler.travel = {travel} m); allowed: "
            f"{'more' if short else 'fewer'} links "
            f"or a longer idler.travel"
        )
    circles = _circles(v, tr, idl, rol, sprocket, rp, idler + slide * guide)
    hull, _ = closed_loop(circles, SEARCH_SAMPLES)
    reach_i = fm.hypot(idl["radius"] + tr["pad_wheel"], 0.5 * tr["link_length"])
    a1, a2 = _span_angles(hull, idler + slide * guide, reach_i, guide)
    preload = idl["preload"] or tr["tension"] * (fm.cos(a1) + fm.cos(a2)) + idl["stiffness"] * slide
    _check_rollers(tr, rol, circles)
    return ClosedGeometry(n, pitch, rp, tip, preload, slide, sprocket, idler, guide, (a1, a2), n_teeth, rpin,
                          circles)


def closed_pins(g):
    """n_links pins on the taut loop (body frame), clockwise (front to rear along the
    ground, as the paper's track), and the sprocket angle that seats one of them."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    pins, _ = closed_track(g.circles, g.n_links)
    pins = pins[::-1].copy()
    d = pins - g.sprocket
    r = fm.vhypot(*d.T)
    b = int(np.argmin(np.abs(r - g.pitch_radius) + 1e-3 * np.abs(pins[:, 0] - g.sprocket[0])))
    angle = fm.atan2(d[b, 1], d[b, 0])
    # every pin near the teeth into its seat: the taut loop leaves the pitch circle along
    # its tangents, which would put the next pins on the teeth's flanks
    pitch = 2.0 * math.pi / g.teeth
    near = r < g.tip_radius + g.pin_radius
    k = np.round((fm.vatan2(d[near, 1], d[near, 0]) - angle) / pitch)
    seat = angle + k * pitch
    pins[near] = g.sprocket + g.pitch_radius * np.column_stack([fm.vcos(seat), fm.vsin(seat)])
    return pins, angle


def _check_rollers(tr, rol, circles):
    """Each support roller must touch the loop that sprocket, road wheels and idler span."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    n_rollers = len(rol["positions"])
    hull, _ = closed_loop(circles[:len(circles) - n_rollers], SEARCH_SAMPLES)
    a, d = hull[:-1], np.diff(hull, axis=0)
    for j, (x, y) in enumerate(rol["positions"]):
        p = np.array([x, y])
        t = np.clip(((p - a) * d).sum(1) / (d * d).sum(1), 0.0, 1.0)
        gap = fm.vhypot(*(a + t[:, None] * d - p).T).min() - (rol["radius"] + tr["pad_wheel"])
        if abs(gap) > tr["link_length"]:
            raise ClosedLayoutError(
                f"rollers.positions[{j}] = [{x}, {y}] puts the roller {gap:+.3g} m from the track "
                "(+ outside, - inside the loop): a support roller must touch the return run "
                f"(within track.link_length = {tr['link_length']} m)"
            )


def closed_vector(g, spr, idl, drive, contact_c, drawbar=None):
    """The LP_* vector of the kernels. contact_c: the viscous coefficient of pin-tooth
    contacts (N s/m; 0 = none); drawbar: the drawbar group (None: no drawbar)."""
    lp = np.zeros(L.N_LOOP)
    lp[L.LP_SPROCKET_X], lp[L.LP_SPROCKET_Y] = g.sprocket
    lp[L.LP_SPROCKET_INERTIA] = spr["inertia"]
    lp[L.LP_TEETH] = spr["teeth"]
    lp[L.LP_PITCH_RADIUS] = g.pitch_radius
    lp[L.LP_SEAT_RADIUS] = spr["seat_radius"]
    lp[L.LP_TIP_RADIUS] = g.tip_radius
    lp[L.LP_PIN_RADIUS] = spr["pin_radius"]
    lp[L.LP_FLANK_ANGLE] = math.radians(spr["flank_angle"])
    lp[L.LP_TOOTH_STIFFNESS] = spr["stiffness"]
    lp[L.LP_TOOTH_DAMPING] = contact_c
    lp[L.LP_GUIDE_X], lp[L.LP_GUIDE_Y] = g.guide
    lp[L.LP_IDLER_MASS] = idl["mass"]
    lp[L.LP_PRELOAD] = g.preload
    lp[L.LP_TENSIONER_STIFFNESS] = idl["stiffness"]
    lp[L.LP_TENSIONER_DAMPING] = idl["damping"]
    lp[L.LP_TRAVEL] = idl["travel"]
    lp[L.LP_DRIVE_KIND] = L.DRIVES[drive["kind"]]
    lp[L.LP_DRIVE_TORQUE] = drive["torque"]
    lp[L.LP_TARGET] = drive["target"]
    lp[L.LP_GAIN_P] = drive["gain_p"]
    lp[L.LP_GAIN_I] = drive["gain_i"]
    lp[L.LP_TORQUE_LIMIT] = drive["torque_limit"]
    curve = np.asarray(drive["curve"], float).reshape(-1, 2)
    lp[L.LP_CURVE] = len(curve)
    lp[L.LP_CURVE + 1:L.LP_CURVE + 1 + curve.size] = curve.ravel()
    if drawbar:
        lp[L.LP_DRAWBAR_LOAD] = drawbar["load"]
        lp[L.LP_HITCH_X], lp[L.LP_HITCH_Y] = drawbar["hitch"]
        lp[L.LP_RIG_SLIP] = drawbar["slip"]
        lp[L.LP_RIG_DAMPING] = drawbar["rig_damping"]
    from .teeth_jit import tooth_shape  # numba: loaded when first needed

    lp[L.LP_SHAPE:L.LP_SHAPE + L.N_SHAPE] = tooth_shape(lp)
    return lp


def without_drawbar(lp):
    """A copy of the LP_* vector with no drawbar: the vehicle at rest, before anything pulls."""
    out = lp.copy()
    out[L.LP_DRAWBAR_LOAD] = 0.0
    out[L.LP_RIG_SLIP] = 0.0
    return out


def guide_table(g, tr, idl, rol):
    """The G_* table: the idler (at slide 0), then the rollers."""
    rows = [(g.idler[0], g.idler[1], idl["radius"] + tr["pad_wheel"])]
    rows += [(x, y, rol["radius"] + tr["pad_wheel"]) for x, y in rol["positions"]]
    return np.array(rows, dtype=float).reshape(-1, L.N_G_COLS)
