"""The checks a study file's tables share ([grid], [[zip]], [[runs]], [search]): unknown keys,
numbers, ranges, parameter names. Each raises a StudyError with one line naming the culprit."""

import difflib
import math

from trackbench.scenario import parameter_names
from trackbench.solvers.registry import settings_tables

RANGE_KEYS = ("start", "stop", "step", "num")
MAX_RUNS = 100_000


class StudyError(ValueError):
    """Bad study input; the message is one line."""


def unknown(where, name, valid):
    close = difflib.get_close_matches(name, valid, n=3, cutoff=0.5)
    hint = f"; did you mean {', '.join(close)}?" if close else f"; allowed: {', '.join(valid)}"
    return StudyError(f"{where}: unknown key '{name}'{hint}")


def is_number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def clean(x):
    """Round float noise of ranges (0.1 + 0.2) away."""
    return float(f"{x:.12g}")


def expand_range(where, spec):
    """{start, stop, step} (stop included when reached) or {start, stop, num} (linspace)."""
    for k in spec:
        if k not in RANGE_KEYS:
            raise unknown(where, k, list(RANGE_KEYS))
    if "start" not in spec or "stop" not in spec or ("step" in spec) == ("num" in spec):
        raise StudyError(
            f"{where}: a range needs start, stop and one of step or num, "
            f"e.g. {{start = 5.0, stop = 15.0, step = 2.5}} or {{start = 5.0, stop = 15.0, num = 5}}"
        )
    start, stop = spec["start"], spec["stop"]
    if not (is_number(start) and is_number(stop) and math.isfinite(start) and math.isfinite(stop)):
        raise StudyError(f"{where}: start and stop must be finite numbers")
    if "num" in spec:
        num = spec["num"]
        if not isinstance(num, int) or isinstance(num, bool) or not 1 <= num <= MAX_RUNS:
            raise StudyError(f"{where}.num = {num!r} is not allowed: expected an integer in [1, {MAX_RUNS}]")
        if num == 1:
            return [start]
        vals = [clean(start + (stop - start) * i / (num - 1)) for i in range(num)]
    else:
        step = spec["step"]
        if not is_number(step) or step == 0 or not math.isfinite(step) or (stop - start) * step < 0:
            raise StudyError(f"{where}.step = {step!r} is not allowed: expected a non-zero number "
                             "that leads from start to stop")
        n = int(math.floor((stop - start) / step + 1e-9)) + 1
        if n > MAX_RUNS:
            raise StudyError(f"{where}: the range has {n} values; at most {MAX_RUNS}")
        vals = [clean(start + i * step) for i in range(n)]
    if all(isinstance(v, int) for v in (start, stop, spec.get("step", 0))) and "num" not in spec:
        vals = [int(v) for v in vals]
    return vals


def check_name(where, name):
    if name == "terrain" or name.startswith("terrain.") or name in parameter_names():
        return
    if name in ("vehicle", "track", "record") or name in settings_tables():   # a table of them
        return
    close = difflib.get_close_matches(name, parameter_names(), n=3, cutoff=0.5)
    hint = f"; did you mean {', '.join(close)}?" if close else "; see `trackbench params` for the list"
    raise StudyError(f"{where}: unknown parameter '{name}'{hint}")
