"""Dotted names and single values: flatten, set and merge nested scenario tables, check
one value against its rule, and name an unknown parameter with its close matches."""

import copy
import difflib
import math

import numpy as np

from . import ScenarioError
from .parameters_table import OPTIONAL, PLACEMENT_KEYS, parameter_names


def unknown(name, valid):
    """The error for a name not in valid, suggesting the closest names."""
    close = difflib.get_close_matches(name, valid, n=3, cutoff=0.5)
    hint = f"; did you mean {', '.join(close)}?" if close else "; see `trackbench params` for the list"
    return ScenarioError(f"unknown parameter '{name}'{hint}")


def check_value(name, value, rule, open_low=False):
    """value converted to the rule's type, or ScenarioError naming name and what is allowed."""
    typ, lo, hi, allowed = rule
    bad = ScenarioError(f"{name} = {value!r} is not allowed: expected {allowed}")
    if typ is bool:
        if not isinstance(value, bool):
            raise bad
        return value
    if typ is str:
        if not isinstance(value, str) or (lo is not None and value not in lo):
            raise bad
        return value
    if typ is list:
        if not isinstance(value, (list, tuple)):
            raise bad
        return [list(v) if isinstance(v, (list, tuple)) else v for v in value]
    return _check_number(value, typ, lo, hi, open_low, bad)


def _check_number(value, typ, lo, hi, open_low, bad):
    # bool is an int to Python, but true/false is never meant as a number here
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise bad
    if typ is int:
        if float(value) != int(value):
            raise bad
        value = int(value)
    else:
        value = float(value)
    if not math.isfinite(value) and not (math.isinf(value) and math.isinf(hi)):
        raise bad
    if not (lo <= value <= hi) or (open_low and value <= lo):
        raise bad
    return value


def set_dotted(d, name, value):
    """Set d['a']['b'] for name 'a.b', creating tables on the way."""
    parts = name.split(".")
    for p in parts[:-1]:
        d = d.setdefault(p, {})
    d[parts[-1]] = value


def flatten(d, prefix=""):
    """{dotted name: value}; the terrain table stays one value (its keys depend on its kind)."""
    out = {}
    for k, v in d.items():
        if isinstance(v, dict) and not (prefix + k).startswith("terrain"):
            out.update(flatten(v, prefix + k + "."))
        else:
            out[prefix + k] = v
    return out


def dotted_keys(d, prefix=""):
    """The dotted parameter names set in a (possibly nested) overrides dict."""
    out = set()
    for k, v in d.items():
        name = prefix + k
        if isinstance(v, dict) and name != "terrain" and not name.startswith("terrain."):
            out |= dotted_keys(v, name + ".")
        else:
            out.add(name)
    return out


def merge(base, over, prefix=""):
    """Update the nested table base by over in place; unknown names and a value given for a
    group raise ScenarioError."""
    for k, v in over.items():
        name = prefix + k
        if k not in base and name not in OPTIONAL and not name.startswith("terrain"):
            raise unknown(name, parameter_names())
        if name == "terrain":
            _merge_terrain(base, v)
        elif isinstance(base.get(k), dict):
            if not isinstance(v, dict):
                raise ScenarioError(
                    f"{name} is a group of parameters, not a value; set e.g. {name}.{next(iter(base[k]))}"
                )
            merge(base[k], v, name + ".")
        else:
            base[k] = copy.deepcopy(v)


def _merge_terrain(base, v):
    if not isinstance(v, dict):
        raise ScenarioError('terrain must be a table, e.g. {kind = "step", height = 0.1}')
    if "kind" in v and v["kind"] != base["terrain"].get("kind"):
        base["terrain"] = {}  # a new kind starts from nothing
    if any(p in v for p in PLACEMENT_KEYS):
        for p in PLACEMENT_KEYS:  # the user's placement replaces the default's
            base["terrain"].pop(p, None)
    base["terrain"].update(copy.deepcopy(v))
