"""What one run is: vehicle + track + terrain + run settings, validated before anything runs.

A scenario is a nested dict with dotted names (``speed``, ``vehicle.chassis_mass``,
``terrain.height``); ``Scenario.from_dict`` fills every missing value from the
paper's run and raises ``ScenarioError`` (one line, naming the parameter and what is
allowed) on anything wrong. The parameter table is parameters_table.py; the checks per
area are check_*.py.
"""

import copy
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any


class ScenarioError(ValueError):
    """Bad scenario input; the message is one line naming the culprit."""


# below ScenarioError: the check modules import it from this package
from .check_closed import check_closed  # noqa: E402
from .check_run import (  # noqa: E402
    apply_preset,
    apply_sampling,
    apply_tolerance,
    check_extensions,
    check_sampling,
    check_solver,
)
from .check_terrain import check_placed_by_time, validate_terrain  # noqa: E402
from .check_values import check_value, dotted_keys, flatten, merge, set_dotted, unknown  # noqa: E402
from .check_vehicle import check_arm_stops, check_geometry  # noqa: E402
from .parameters_table import (  # noqa: E402
    METHODS,
    OBSTACLE_KINDS,
    OPEN_LOW,
    PER_WHEEL_NAMES,
    PLACEMENT_KEYS,
    RULES,
    SOLVERS,
    TERRAIN_KINDS,
    TERRAIN_RULES,
    UNITS,
    paper_step,
    parameter_names,
)
from .vehicle_model import apply_model, per_wheel_lists, take_model  # noqa: E402

__all__ = [
    "Scenario",
    "ScenarioError",
    "validate",
    "validate_terrain",
    "flatten",
    "set_dotted",
    "paper_step",
    "parameter_names",
    "RULES",
    "UNITS",
    "TERRAIN_RULES",
    "SOLVERS",
    "METHODS",
    "TERRAIN_KINDS",
    "OBSTACLE_KINDS",
    "PLACEMENT_KEYS",
]


@dataclass(frozen=True)
class Scenario:
    """A validated, fully resolved scenario. Build with from_dict or paper().
    explicit: the dotted names set by the user rather than by defaults or a preset; given:
    those its vehicle file (vehicle.model) sets to other than the paper's values; folder:
    where a relative vehicle file is sought (a study file's folder; None: the current one)."""

    data: dict[str, Any]
    explicit: frozenset[str] = frozenset()
    given: frozenset[str] = frozenset()
    folder: str | None = field(default=None, compare=False)

    @classmethod
    def paper(cls, **overrides: Any) -> "Scenario":
        return cls.from_dict(overrides)

    @classmethod
    def from_dict(cls, overrides: Mapping[str, Any] | None = None, base: Mapping[str, Any] | None = None,
                  explicit: frozenset[str] | None = None, given: frozenset[str] = frozenset(),
                  folder: str | None = None) -> "Scenario":
        """Defaults (the paper's run, or ``base``) updated by ``overrides``; keys may be
        nested tables or dotted names. A base given as a plain dict counts as explicit
        throughout (it is a resolved scenario: its preset values stay as they are).
        vehicle.model among the overrides: its file's values become the defaults of the
        vehicle's groups (scenario/vehicle_model.py), relative files sought in ``folder``."""
        d: dict[str, Any] = copy.deepcopy(dict(base) if base is not None else paper_step())
        if explicit is None:
            explicit = frozenset(flatten(d)) if base is not None else frozenset()
        nested: dict[str, Any] = {}
        for k, v in (overrides or {}).items():
            if not isinstance(k, str):
                raise ScenarioError(f"parameter names must be text, got {k!r}")
            if "." in k and not k.startswith("terrain."):
                if k not in RULES:
                    raise unknown(k, parameter_names())
            set_dotted(nested, k, v)
        model = take_model(nested)
        if model is not None:
            given = apply_model(d, model, explicit | dotted_keys(nested), folder)
        merge(d, nested)
        explicit = frozenset(explicit | dotted_keys(nested) | ({"vehicle.model"} if model else set()))
        d["preset"] = check_value("preset", d.get("preset"), RULES["preset"])
        apply_sampling(d, explicit)   # first: the paper preset's step cap follows the output interval
        apply_preset(d, explicit | given)
        apply_tolerance(d, explicit | given)   # last: it reads the preset, layout and ground
        return cls(validate(d, explicit | given), explicit, given, folder)

    def with_overrides(self, overrides: Mapping[str, Any]) -> "Scenario":
        return Scenario.from_dict(overrides, base=self.data, explicit=self.explicit, given=self.given,
                                  folder=self.folder)

    def to_dict(self) -> dict[str, Any]:
        return copy.deepcopy(self.data)

    def __getitem__(self, name: str) -> Any:
        d = self.data
        for p in name.split("."):
            d = d[p]
        return d

    @property
    def name(self) -> str:
        return self.data["name"]


def validate(d: Mapping[str, Any], explicit: frozenset[str] = frozenset()) -> dict[str, Any]:
    """The resolved scenario d checked area by area (values, solver, terrain, sampling,
    geometry, extensions, closed track), as a new dict with values converted and derived ones filled in."""
    out: dict[str, Any] = copy.deepcopy(dict(d))
    flat = flatten({k: v for k, v in d.items() if k != "terrain"})
    for name, value in flat.items():
        if name not in RULES:
            raise unknown(name, parameter_names())
        if name in PER_WHEEL_NAMES and isinstance(value, (list, tuple)):
            continue   # one per wheel: checked once the wheel count is
        set_dotted(out, name, check_value(name, value, RULES[name], name in OPEN_LOW))
    per_wheel_lists(out)
    check_arm_stops(out["vehicle"])
    check_solver(out)
    out["terrain"] = validate_terrain(d["terrain"])
    check_sampling(out)
    check_geometry(out["vehicle"], out["track"])
    check_placed_by_time(out)
    out["vehicle"]["arm_damping"] = [float(a) for a in out["vehicle"]["arm_damping"]]
    check_extensions(out, explicit)
    check_closed(out, explicit)
    return out
