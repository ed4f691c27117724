"""Closed track checks: what the closed layout supports, its sprocket, idler, rollers,
drive and drawbar values, its geometry, and the values it derives."""

import math

import numpy as np

from ..model.contact.laws import DAMPING_LAWS
from ..model.vehicle.parameters import closed_defaults, paper_track
from . import ScenarioError
from .check_values import flatten, set_dotted
from .parameters_table import CLOSED_GROUPS


def check_closed(out, explicit):
    """The closed layout: what it supports, its geometry (model/vehicle/closed_track.py), and
    the values it derives written into the scenario unless given."""
    if out["track"]["layout"] != "closed":
        _check_paper_layout(out, explicit)
        return
    from ..model.core.indices import LP_CURVE_POINTS
    from ..model.vehicle.closed_track import ClosedLayoutError, closed_geometry
    from ..solvers.registry import SOLVERS

    if not SOLVERS[out["solver"]].closed_track:
        able = ", ".join(f"solver = '{e.name}'" for e in SOLVERS.values() if e.closed_track)
        raise ScenarioError(
            f"solver = '{out['solver']}' runs the paper's track layout only; use {able} with "
            "track.layout = 'closed'"
        )
    # the sprocket teeth keep no approach speeds: they take the viscous law's dashpot where
    # contact.damping = 'viscous', else none (model/dynamics/closed_track_jit.py _teeth)
    damping = out["contact"]["damping"]
    if DAMPING_LAWS[damping].needs_approach_speed:
        raise ScenarioError(
            f"contact.damping = '{damping}' does not apply to the closed track's sprocket teeth; allowed "
            f"with track.layout = 'closed': {', '.join(DAMPING_LAWS.names(needs_approach_speed=False))}"
        )
    out["rollers"]["positions"] = _pairs("rollers.positions", out["rollers"]["positions"])
    out["drive"]["curve"] = _pairs("drive.curve", out["drive"]["curve"], True, LP_CURVE_POINTS)
    if out["drive"]["kind"] == "torque" and "drive.torque" not in explicit and not out["drive"]["curve"]:
        raise ScenarioError("drive.kind = 'torque' needs drive.torque (N m) or drive.curve")
    _check_drawbar(out)
    try:
        g = closed_geometry(
            out["vehicle"], out["track"], out["sprocket"], out["idler"], out["rollers"], frozenset(explicit)
        )
    except ClosedLayoutError as e:
        raise ScenarioError(str(e)) from None
    # the speed drive holds the start speed; the contact geometry without force jumps: the
    # rolling loop crosses the paper's switches at the pin-passing frequency, and at a
    # switch a static equilibrium may not exist (docs/model.md)
    resolved = {**g.resolved(), "drive.target": out["speed"], "contact.geometry": "continuous"}
    if out["vehicle"].get("torsion_free_angle") is not None:
        # the arms rest where the torsion bars carry the wheels, found with the equilibrium: the
        # preload that holds the loop at track.tension is derived round the wheels there
        # (run/assemble.resting_vehicle), not round arm_angle, the design position
        del resolved["idler.preload"]
    for name, value in resolved.items():
        if name not in explicit:
            set_dotted(out, name, value)


def _check_paper_layout(out, explicit):
    """A closed-track value set to anything but its default on the paper's layout (a
    resolved scenario counts every value as given)."""
    defaults = flatten({**closed_defaults(), "track": {"tension": paper_track()["tension"]}})
    flat = flatten({k: out[k] for k in (*CLOSED_GROUPS, "track")})
    given = sorted(k for k in explicit if k in defaults and flat[k] != defaults[k])
    if given:
        raise ScenarioError(f"{given[0]} applies to the closed track only; set track.layout = 'closed'")


def _pairs(name, value, increasing=False, limit=None):
    arr = np.asarray(value, dtype=float) if value else np.zeros((0, 2))
    if arr.ndim != 2 or arr.shape[1] != 2 or not np.all(np.isfinite(arr)):
        raise ScenarioError(f"{name} must be a list of [a, b] pairs of finite numbers, or []")
    if increasing and np.any(np.diff(arr[:, 0]) <= 0):
        raise ScenarioError(f"{name}: the speeds must increase from pair to pair")
    if limit is not None and len(arr) > limit:
        raise ScenarioError(f"{name} has {len(arr)} pairs; allowed: at most {limit}")
    return arr.tolist()


def _check_drawbar(out):
    hitch = out["drawbar"]["hitch"]
    if len(hitch) != 2 or not all(
        isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in hitch
    ):
        raise ScenarioError(
            f"drawbar.hitch = {hitch!r} is not allowed: expected a pair [x, y] of finite numbers "
            "(m, body point)"
        )
    out["drawbar"]["hitch"] = [float(x) for x in hitch]
    if out["drawbar"]["slip"] > 0.0 and out["drive"]["kind"] != "speed":
        raise ScenarioError(
            f"drawbar.slip = {out['drawbar']['slip']} needs drive.kind = 'speed' (the drive holds "
            f"the sprocket at the rig's slip), not '{out['drive']['kind']}'"
        )
