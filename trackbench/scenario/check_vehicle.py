"""Vehicle geometry checks: do the road wheels, the track ends and the links fit together
(the paper's layout; the closed layout's own geometry: check_closed)."""

import functools
import json
import math

import numpy as np

from ..model.vehicle.parameters import equilibrium_arm_angle, pivots
from . import ScenarioError


def wheel_centres_for_checks(v):
    """The wheel centres at the initial equilibrium, as parameters.wheel_centres_body has them
    but with the C library's cos and sin: a check decides no number of a result, and the
    compiled elementary functions would load numba (about 0.8 s) into every command that only
    validates (`study status`, the coordinator of `study run`)."""
    phi = equilibrium_arm_angle(v)
    return pivots(v) + v["arm_length"] * np.array([math.cos(phi), math.sin(phi)])


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
    r = v["wheel_radius"]
    rho = r + tr["pad_wheel"]
    if v["n_wheels"] > 1 and v["pivot_spacing"] <= 2 * r:
        raise ScenarioError(
            f"vehicle.pivot_spacing = {v['pivot_spacing']} m makes neighbouring road wheels overlap: "
            f"it must exceed 2 * wheel_radius = {2 * r} m"
        )
    ends = _track_ends(v, tr, wc, rho)
    if tr["link_length"] <= 2 * tr["pad_ground"]:
        raise ScenarioError("track.link_length must exceed 2 * track.pad_ground")
    if tr["layout"] == "closed":
        return
    _check_track_length(ends, wc, rho, tr)


def _track_ends(v, tr, wc, rho):
    """The front and rear track ends as an array, once they lie outside the wheels."""
    for key in ("front_track_end", "rear_track_end"):
        e = v[key]
        if len(e) != 2 or not all(isinstance(x, (int, float)) and math.isfinite(x) for x in e):
            raise ScenarioError(f"vehicle.{key} must be a pair [x, y] of finite numbers (m)")
    ends = np.array([v["front_track_end"], v["rear_track_end"]], float)
    if not (ends[0, 0] > wc[:, 0].max() + rho and ends[1, 0] < wc[:, 0].min() - rho):
        raise ScenarioError(
            "vehicle.front_track_end / rear_track_end must lie ahead of the first and behind the "
            "last road wheel (wheel radius and pad included)"
        )
    if np.any(ends[:, 1] <= wc[:, 1].min() - rho + tr["pad_ground"]):
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
    circ = [c + rho * np.column_stack([np.cos(ang), np.sin(ang)]) for c in wc]
    hull = _lower_hull(np.vstack([ends] + circ))
    return float(np.hypot(*np.diff(hull, axis=0).T).sum())
