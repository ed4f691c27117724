"""Run-wide checks: presets filled in, the output sampling against the duration, the solver
and method (solvers/registry.py), and the models beyond the paper (coefficients that belong
together, what the solver runs)."""

import copy
import math

from trackbench.model.contact.laws import DAMPING_LAWS
from trackbench.scenario.presets import PRESETS, preset_values
from trackbench.solvers.registry import SOLVERS, all_methods, pin_tolerance_methods

from . import ScenarioError
from .check_values import flatten, set_dotted
from .parameters_table import (
    CLOSED_TOLERANCE,
    CLOSED_TOLERANCE_METHOD,
    RIDE_KINDS,
    RIDE_OUTPUT_INTERVAL,
    paper_step,
)


def apply_preset(d, explicit):
    """Every parameter a preset may set takes the scenario's preset value (or the paper's
    where this preset leaves it), unless it was given explicitly."""
    paper = flatten(paper_step())
    values = preset_values(d["preset"], d)
    controlled = set()
    for name in PRESETS:
        controlled |= set(preset_values(name, d))
    for name in controlled - set(explicit):
        set_dotted(d, name, copy.deepcopy(values.get(name, paper[name])))


def apply_sampling(d, explicit):
    """On ride ground (parameters_table.RIDE_KINDS) the samples and the recording's frames
    default to the ride's rates; on obstacles to the paper's. Explicit values win."""
    terrain = d.get("terrain")
    ride = isinstance(terrain, dict) and terrain.get("kind") in RIDE_KINDS
    paper = paper_step()
    if "output_interval" not in explicit:
        d["output_interval"] = RIDE_OUTPUT_INTERVAL if ride else paper["output_interval"]
    if "record.every" not in explicit and isinstance(d.get("record"), dict):
        d["record"]["every"] = 0 if ride else paper["record"]["every"]


def closed_default(d):
    """Whether the closed track's default tolerance is a scenario dict's when it sets none:
    the closed layout, the damped preset, dopri5."""
    track = d.get("track") if isinstance(d.get("track"), dict) else {}
    return (track.get("layout") == "closed" and d.get("preset") == "damped"
            and d.get("method") == CLOSED_TOLERANCE_METHOD)


def apply_tolerance(d, explicit):
    """The closed track's default tolerance (parameters_table.CLOSED_TOLERANCE) where the
    scenario sets none and closed_default says so; else the paper's."""
    if "tolerance" in explicit:
        return
    d["tolerance"] = CLOSED_TOLERANCE if closed_default(d) else paper_step()["tolerance"]


def check_sampling(out):
    """The output interval fits the duration, and the run keeps at most 2,000,000 samples."""
    if out["output_interval"] > out["duration"]:
        raise ScenarioError(
            f"output_interval = {out['output_interval']} s is longer than duration = "
            f"{out['duration']} s; allowed: (0, duration]"
        )
    if out["duration"] / out["output_interval"] > 2_000_000:
        raise ScenarioError(
            "output_interval is too small for this duration: at most 2,000,000 output samples"
        )


def check_solver(d):
    """solver names an entry of the registry as it is now (a solver registered at run time
    validates too), and method one of its methods (of any solver's where it has no choice);
    tolerance_pin_velocity only with a method that honours it (its entry's pin_tolerance_methods)."""
    if d["solver"] not in SOLVERS:
        raise ScenarioError(f"solver = {d['solver']!r} is not allowed: expected one of {', '.join(SOLVERS)}")
    entry = SOLVERS[d["solver"]]
    methods = entry.methods or all_methods()
    if d["method"] not in methods:
        allowed = ", ".join(sorted(methods))
        raise ScenarioError(f"method = {d['method']!r} is not allowed: expected one of {allowed}")
    method = entry.method_of(d["method"])
    if "tolerance_pin_velocity" in d and method not in entry.pin_tolerance_methods:
        honour = ", ".join(repr(m) for m in pin_tolerance_methods()) or "no method"
        raise ScenarioError(
            f"tolerance_pin_velocity is honoured only by method = {honour}; solver = {d['solver']!r} "
            f"with method {method!r} ignores it: remove it or choose such a method"
        )


def check_extensions(d, explicit):
    """The models beyond the paper: coefficients that belong together, sizes that must
    match, and whether the solver runs them (its registry entry's extended_models)."""
    _check_contact_damping(d["contact"], explicit)
    _check_arm_damping(d["vehicle"])
    if not SOLVERS[d["solver"]].extended_models:
        _check_paper_model(d)


def _check_contact_damping(c, explicit):
    """The value a damping law's coefficient comes from (its row's parameter) is set."""
    parameter = DAMPING_LAWS[c["damping"]].parameter
    if parameter == "contact.damping_ratio" and c["damping_ratio"] <= 0.0:
        raise ScenarioError(
            f"contact.damping = '{c['damping']}' needs contact.damping_ratio > 0 (e.g. 0.1); "
            "or contact.damping = 'none'"
        )
    if parameter == "contact.restitution" and "contact.restitution" not in explicit:
        raise ScenarioError(
            f"contact.damping = '{c['damping']}' needs contact.restitution, a number in (0, 1] (e.g. 0.75)"
        )


def _check_arm_damping(v):
    arms = v["arm_damping"]
    n = v["n_wheels"]
    if arms and len(arms) != n:
        raise ScenarioError(
            f"vehicle.arm_damping has {len(arms)} values for {n} road wheels: give one per wheel "
            "(0 = no shock absorber), or [] for none"
        )
    for i, a in enumerate(arms):
        if isinstance(a, bool) or not isinstance(a, (int, float)) or not (math.isfinite(a) and a >= 0.0):
            raise ScenarioError(
                f"vehicle.arm_damping[{i}] = {a!r} is not allowed: expected a number >= 0 (N m s/rad)"
            )


def _check_paper_model(d):
    """A solver that runs the paper's model only: the first extension set is named."""
    c = d["contact"]
    ext = [
        name
        for name, on in (
            ("contact.law", c["law"] != "linear"),
            ("contact.damping", c["damping"] != "none"),
            ("contact.geometry", c["geometry"] != "paper"),
            ("contact.friction", c["friction"] > 0),
            ("track.link_damping", d["track"]["link_damping"] > 0),
            ("terrain.soil", d["terrain"].get("soil", "rigid") != "rigid"),
            ("vehicle.arm_damping", any(a > 0 for a in d["vehicle"]["arm_damping"])),
        )
        if on
    ]
    if ext:
        able = " or ".join(f"solver = '{e.name}'" for e in SOLVERS.values() if e.extended_models)
        raise ScenarioError(
            f"solver = '{d['solver']}' runs the paper's model only, but {ext[0]} is set; "
            f"use {able} for the models beyond the paper"
        )
