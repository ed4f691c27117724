"""Vehicle geometry checks: do the road wheels, the track ends and the links fit together
(the paper's layout; the closed layout's own geometry: check_closed)."""

import functools
import json
import math

import numpy as np

from ..model.vehicle.parameters import per_wheel, per_wheel_or_none, wheel_centres_with
from . import ScenarioError


def wheel_centres_for_checks(v):
    """The wheel centres at the initial equilibrium, as parameters.wheel_centres_body has them
    but with the C library's cos and sin: a check decides no number of a result, and the
    compiled elementary functions would load numba (about 0.8 s) into every command that only
    validates (`study status`, the coordinator of `study run`)."""
    return wheel_centres_with(v, math.cos, math.sin)


def check_geometry(v, tr):
    """Does the track fit the wheels? Cheap checks on the equilibrium configuration (the
    closed layout's own: check_closed). Once per vehicle and track: a study's runs mostly
    share them, and the taut path's hull took 2 ms a run (2 s of a 1,000-run study's
    validation). A geometry that fails is checked again each time (its error is not kept)."""
    _check_geometry(json.dumps([v, tr], sort_keys=True))


@functools.lru_cache(maxsize=64)
def _check_geometry(key):
    v, tr = json.loads(key)
    wc = wheel_centres_for_checks(v)
    r = per_wheel(v, "wheel_radius")
    _check_wheels_apart(v, wc, r)
    _check_stands(v, wc)
    rho = r + tr["pad_wheel"]
    ends = _track_ends(v, tr, wc, rho)
    if tr["link_length"] <= 2 * tr["pad_ground"]:
        raise ScenarioError("track.link_length must exceed 2 * track.pad_ground")
    if tr["layout"] == "closed":
        return
    _check_track_length(ends, wc, rho, tr)


def _check_wheels_apart(v, wc, r):
    """Neighbouring road wheels must not overlap (nor swap places) at the initial equilibrium."""
    spacing = v["pivot_spacing"]
    if not isinstance(spacing, list) and all(not isinstance(v[k], list) for k in (
            "wheel_radius", "arm_length", "arm_angle", "pivot_y")) and spacing <= 2 * r[0]:
        raise ScenarioError(
            f"vehicle.pivot_spacing = {spacing} m makes neighbouring road wheels overlap: "
            f"it must exceed 2 * wheel_radius = {2 * r[0]} m"
        )
    d = np.hypot(*np.diff(wc, axis=0).T)
    for i in range(len(d)):
        if wc[i + 1, 0] >= wc[i, 0] or d[i] <= r[i] + r[i + 1]:
            raise ScenarioError(
                f"road wheels {i + 1} and {i + 2} overlap: their centres lie {d[i]:.4g} m apart, within "
                f"their radii's sum {r[i] + r[i + 1]:.4g} m (wheel {i + 2} must lie behind wheel {i + 1}); "
                "allowed: vehicle.pivot_spacing, arm_length, arm_angle and wheel_radius that keep them apart"
            )


def _check_stands(v, wc):
    """The chassis' mass centre (x = 0 of the body frame) must lie over the wheels' span, or
    the vehicle tips over at rest: no static equilibrium on level ground."""
    lo, hi = float(wc[:, 0].min()), float(wc[:, 0].max())
    if not lo < 0.0 < hi:
        raise ScenarioError(
            f"the vehicle does not stand: its mass centre (x = 0) lies outside the road wheels' span "
            f"[{lo:.3g}, {hi:.3g}] m; allowed: vehicle.first_pivot_x and pivot_spacing that put wheels "
            "ahead of and behind it"
        )


def _track_ends(v, tr, wc, rho):
    """The front and rear track ends as an array, once they lie outside the wheels."""
    for key in ("front_track_end", "rear_track_end"):
        e = v[key]
        if len(e) != 2 or not all(isinstance(x, (int, float)) and math.isfinite(x) for x in e):
            raise ScenarioError(f"vehicle.{key} must be a pair [x, y] of finite numbers (m)")
    ends = np.array([v["front_track_end"], v["rear_track_end"]], float)
    if not (ends[0, 0] > (wc[:, 0] + rho).max() and ends[1, 0] < (wc[:, 0] - rho).min()):
        raise ScenarioError(
            "vehicle.front_track_end / rear_track_end must lie ahead of the first and behind the "
            "last road wheel (wheel radius and pad included)"
        )
    if np.any(ends[:, 1] <= (wc[:, 1] - rho).min() + tr["pad_ground"]):
        raise ScenarioError(
            "vehicle.front_track_end / rear_track_end must lie above the bottom of the road wheels"
        )
    return ends


def _check_track_length(ends, wc, rho, tr):
    """The links, laid around the wheels, must be stretched a little (at most 10 %)."""
    path = _taut_length(ends, wc, rho)
    free = tr["n_links"] * tr["link_length"]
    strain = path / free - 1.0
    if strain <= 0.0:
        raise ScenarioError(
            f"the track is too long for the wheels: n_links * link_length = {free:.4g} m but the path "
            f"around the wheels is {path:.4g} m; allowed: a total link length below {path:.4g} m"
        )
    if strain > 0.1:
        raise ScenarioError(
            f"the track is too short for the wheels: the links would stretch {100 * strain:.3g} % "
            f"(n_links * link_length = {free:.4g} m, path {path:.4g} m); allowed: at most 10 %"
        )


def _taut_length(ends, wc, rho):
    """The length of the taut path track_path.initial_track lays the pins on (the lower convex
    hull of the track ends and the wheel circles), with numpy's elementary functions: a check's
    figure (see wheel_centres_for_checks)."""
    from ..model.vehicle.track_path import _lower_hull  # plain numpy; no compiled code

    ang = np.linspace(0.0, 2 * np.pi, 361)[:-1]
    ring = np.column_stack([np.cos(ang), np.sin(ang)])
    circ = [c + r * ring for c, r in zip(wc, np.broadcast_to(rho, (len(wc),)))]
    hull = _lower_hull(np.vstack([ends] + circ))
    return float(np.hypot(*np.diff(hull, axis=0).T).sum())


def check_arm_stops(v):
    """The bump stops around the arms' rest angle (arm_angle: with torsion_free_angle, the design
    position): jounce stop < arm_angle < rebound stop, wheel by wheel, where stops are given;
    a stop stiffness needs a stop angle."""
    rest = per_wheel(v, "arm_angle")
    jounce = per_wheel_or_none(v, "jounce_stop_angle")
    rebound = per_wheel_or_none(v, "rebound_stop_angle")
    k = per_wheel_or_none(v, "bump_stop_stiffness")
    if k is not None and np.any(k > 0.0) and jounce is None and rebound is None:
        raise ScenarioError(
            "vehicle.bump_stop_stiffness is set but no stop: allowed: vehicle.jounce_stop_angle and/or "
            "rebound_stop_angle (deg below the chassis x axis, as arm_angle), or no bump_stop_stiffness"
        )
    for i in range(len(rest)):
        if jounce is not None and not jounce[i] < rest[i]:
            raise ScenarioError(
                f"vehicle.jounce_stop_angle = {jounce[i]:g} deg (wheel {i + 1}) must lie below "
                f"vehicle.arm_angle = {rest[i]:g} deg: jounce lifts the wheel, a smaller angle below the "
                "chassis x axis; allowed: jounce_stop_angle < arm_angle < rebound_stop_angle"
            )
        if rebound is not None and not rest[i] < rebound[i]:
            raise ScenarioError(
                f"vehicle.rebound_stop_angle = {rebound[i]:g} deg (wheel {i + 1}) must lie above "
                f"vehicle.arm_angle = {rest[i]:g} deg: rebound drops the wheel, a larger angle below the "
                "chassis x axis; allowed: jounce_stop_angle < arm_angle < rebound_stop_angle"
            )
