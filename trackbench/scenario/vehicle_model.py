"""A scenario's vehicle.model: the named vehicle file's values (trackbench/vehicles/) become the
scenario's defaults for the vehicle's groups; values the scenario sets itself still win.

A file's values are checked on their own first (over the paper's run), so that its mistakes
name the file; then the scenario with the user's values on top is checked as any other. The
names a file sets to other than the paper's values count as given: presets and the closed
track's derived values leave them as they are (Scenario.given)."""

import copy

from trackbench.vehicles import VehicleError, read

from . import ScenarioError
from .check_values import flatten, set_dotted
from .parameters_table import OPTIONAL, PER_WHEEL_NAMES, VEHICLE_GROUPS, paper_step


def take_model(nested):
    """vehicle.model popped from the nested overrides (None when not given)."""
    vehicle = nested.get("vehicle")
    if isinstance(vehicle, dict) and "model" in vehicle:
        return vehicle.pop("model")
    return None


def vehicle_defaults():
    """{dotted name: the paper's value} of every name a vehicle file may set (an optional one,
    parameters_table.OPTIONAL: None, the paper has none)."""
    d = paper_step()
    out = flatten({g: d[g] for g in VEHICLE_GROUPS})
    out.update({name: None for name in OPTIONAL if name.split(".", 1)[0] in VEHICLE_GROUPS})
    return out


def apply_model(d, model, explicit, folder=None):
    """The vehicle file's values into d (resolved scenario tables) for every name of its
    groups not in explicit (a name the file leaves out: the paper's value); returns the names
    the file gives values other than the paper's. A scenario that sets every such name itself
    (a resolved one: a study's resolved copy, a run's scenario) keeps the name as a label and
    reads no file."""
    defaults = vehicle_defaults()
    if all(name in explicit for name, default in defaults.items() if default is not None):
        d["vehicle"]["model"] = model
        return frozenset()
    try:
        vf = read(model, folder)
    except VehicleError as e:
        raise ScenarioError(str(e)) from None
    _check_alone(vf)
    for name, default in defaults.items():
        if name not in explicit and (default is not None or name in vf.values):   # optional: only given
            set_dotted(d, name, copy.deepcopy(vf.values.get(name, default)))
    d["vehicle"]["model"] = model
    return frozenset(n for n, v in vf.values.items() if v != defaults[n])


_CHECKED = {}   # path -> the VehicleFile last checked (vehicles.read returns one object per file version)


def _check_alone(vf):
    """The file's values over the paper's run, validated as a scenario: its mistakes (values,
    list lengths, geometry, the closed track's fit) name the file. Once per file version."""
    from . import apply_preset, validate

    key = vf.path.as_posix()
    if _CHECKED.get(key) is vf:
        return
    d = paper_step()
    for name, value in vf.values.items():
        set_dotted(d, name, copy.deepcopy(value))
    defaults = vehicle_defaults()
    given = frozenset(n for n, v in vf.values.items() if v != defaults[n])
    try:
        apply_preset(d, given)
        validate(d, given)
    except ScenarioError as e:
        raise ScenarioError(f"{vf.label}: {e}") from None
    _CHECKED[key] = vf


def per_wheel_lists(out):
    """Per-wheel values given as lists: each value checked by its rule, one per road wheel
    (pivot_spacing: one per gap), floats; a number stays a number (the default's keys and
    values, so run ids, are as they were)."""
    from .check_values import check_value
    from .parameters_table import OPEN_LOW, RULES

    n = out["vehicle"]["n_wheels"]
    for name in PER_WHEEL_NAMES:
        key = name.split(".", 1)[1]
        value = out["vehicle"].get(key)   # an optional one (parameters.ARM_OPTIONS) may be absent
        if not isinstance(value, (list, tuple)):
            continue
        want = n - 1 if key == "pivot_spacing" else n
        if len(value) != want:
            each = f"{want} gaps between {n} road wheels" if key == "pivot_spacing" else f"{n} road wheels"
            raise ScenarioError(f"{name} has {len(value)} values for {each}: give {want}, front to rear, "
                                "or one number for every wheel")
        rule = RULES[name]
        out["vehicle"][key] = [check_value(f"{name}[{i}]", v, rule[:3] + (rule[3].split(",")[0],),
                                           name in OPEN_LOW) for i, v in enumerate(value)]
