"""A study's [search]: the highest value of one parameter at which a summary quantity stays
within a limit, for every point of the rest of the grid. The logic only: no runs, no files.

    [search]
    parameter = "speed"          # a numeric parameter, not also varied by [grid], [[zip]], [[runs]]
    low = 2.0
    high = 20.0
    tolerance = 0.25             # in the parameter's unit
    quantity = "peak_wheel1_force_y"   # a summary column
    limit = 1.2e5                # the highest value the quantity may take

The algorithm, for every grid point at once (search_limits):

1. Scan: SCAN_POINTS values evenly spaced from low to high, both ends included (the values a
   grid range {start = low, stop = high, num = SCAN_POINTS} gives).
2. Decide from the scan: within the limit everywhere -> limit_not_reached (search_value =
   high); over it at low -> limit_exceeded_at_low (no value); else the first (lowest) scan
   interval whose lower end is within and whose upper end is over brackets the limit, and
   when the scan crosses the limit more than once the point is marked non_monotone.
3. Bisect the bracket, one midpoint per grid point per round, until it is no wider than the
   tolerance; search_value is the bracket's lower end (the highest value evaluated within
   the limit below the first crossing). Status found, or non_monotone.

Evaluations per grid point: SCAN_POINTS for the scan, plus bisection_rounds() when the scan
brackets a crossing (at most 1 + bisection_rounds() waves of runs in all). A run that fails, or
gives no number for the quantity, ends its point's search as failed (no value), unless the
scan crossed the limit below it: the limit is decided below the first such run (a run over an
obstacle too fast for the model to finish lies beyond the limit it is searched for, as it
does in the shipped obstacle study), or its quantity is one a stopped run bounds from below
and that bound is over the limit (study/read/limits.py: a peak, a ride figure). A value the
callback cannot give yet (PENDING) leaves the point pending.
"""

import difflib
import math
from dataclasses import asdict, dataclass, field

from trackbench.study.spec.rules import StudyError, check_name, clean, expand_range, is_number, unknown

SCAN_POINTS = 5
KEYS = ("parameter", "low", "high", "tolerance", "quantity", "limit")
FOUND, NOT_REACHED, EXCEEDED_AT_LOW, NON_MONOTONE = (
    "found", "limit_not_reached", "limit_exceeded_at_low", "non_monotone")
FAILED, PENDING_STATUS = "failed", "pending"
FINAL = (FOUND, NOT_REACHED, EXCEEDED_AT_LOW, NON_MONOTONE, FAILED)
PENDING = object()   # what evaluate returns for a value it cannot give (yet): a run not done
_SLACK = 1e-9        # relative: a bracket that rounding leaves a hair over the tolerance is done


@dataclass(frozen=True)
class SearchSpec:
    parameter: str
    low: float
    high: float
    tolerance: float
    quantity: str
    limit: float

    def scan_values(self):
        return expand_range("[search]", {"start": self.low, "stop": self.high, "num": SCAN_POINTS})

    def narrow_enough(self, lo, hi):
        return hi - lo <= self.tolerance * (1.0 + _SLACK)

    def as_dict(self):
        return asdict(self)


def midpoint(lo, hi):
    """The bisection's next value, rounded like a grid range's values (12 significant digits)."""
    return clean(0.5 * (lo + hi))


def bisection_rounds(spec):
    """How many rounds of bisection a bracketed point takes: the scan's spacing halved until
    it is within the tolerance."""
    width, n = (spec.high - spec.low) / (SCAN_POINTS - 1), 0
    while not spec.narrow_enough(0.0, width):
        width, n = 0.5 * width, n + 1
    return n


def max_evaluations(spec):
    """Runs one grid point takes at most: the scan and every round of bisection."""
    return SCAN_POINTS + bisection_rounds(spec)


@dataclass
class PointSearch:
    """The search of one grid point: every value evaluated (value -> quantity, None for a run
    that failed or gave no number), the bracket [lo, hi] while bisecting, the outcome."""
    point: object
    values: dict = field(default_factory=dict)
    status: str = "scan"          # "scan", "bisect", PENDING_STATUS or one of FINAL
    lo: float = None              # within the limit
    hi: float = None              # over the limit
    non_monotone: bool = False

    @property
    def runs(self):
        """Values evaluated (a run each), those not known yet left out."""
        return sum(q is not PENDING for q in self.values.values())

    @property
    def done(self):
        return self.status in FINAL

    @property
    def search_value(self):
        if self.status in (FOUND, NON_MONOTONE):
            return self.lo
        return self.hi if self.status == NOT_REACHED else None


def _within(spec, q):
    return q <= spec.limit


def _decide_scan(spec, ps, xs, qs):
    """The point's state after its scan (module docstring, step 2)."""
    ps.values.update(zip(xs, qs))
    if any(q is PENDING for q in qs):
        ps.status = PENDING_STATUS
        return
    if None in qs:
        first_failed = qs.index(None)
        if all(_within(spec, q) for q in qs[:first_failed]):   # no crossing below it: unknown
            ps.status = FAILED
            return
        xs, qs = xs[:first_failed], qs[:first_failed]
    ok = [_within(spec, q) for q in qs]
    if not ok[0]:
        ps.status = EXCEEDED_AT_LOW
        return
    if all(ok):
        ps.status, ps.hi = NOT_REACHED, xs[-1]
        return
    first = ok.index(False)
    ps.lo, ps.hi = xs[first - 1], xs[first]
    ps.non_monotone = sum(a != b for a, b in zip(ok, ok[1:])) > 1
    _next(spec, ps)


def _next(spec, ps):
    """Bisect on while the bracket is wider than the tolerance."""
    if spec.narrow_enough(ps.lo, ps.hi):
        ps.status = NON_MONOTONE if ps.non_monotone else FOUND
    else:
        ps.status = "bisect"


def _bisected(spec, ps, x, q):
    ps.values[x] = q
    if q is PENDING:
        ps.status = PENDING_STATUS
    elif q is None:
        ps.status = FAILED
    else:
        if _within(spec, q):
            ps.lo = x
        else:
            ps.hi = x
        _next(spec, ps)


def search_limits(spec, points, evaluate, on_round=None):
    """Search every grid point of ``points`` (any objects: they are handed back to evaluate as
    they are). ``evaluate(list of (point, value)) -> list of quantities`` (a number, None for a
    failed run, PENDING for one not known) is called once for the scan of all points, then once
    per round of bisection with one value of every point still bisecting. ``on_round(searches,
    round, rounds, asking)`` hears before each call (round 1 is the scan, ``rounds`` the most
    there can be, ``asking`` the values this call asks for). Returns a PointSearch per point,
    in order."""
    searches = [PointSearch(p) for p in points]
    xs = spec.scan_values()
    rounds = 1 + bisection_rounds(spec)
    asks = [(ps.point, x) for ps in searches for x in xs]
    if on_round:
        on_round(searches, 1, rounds, len(asks))
    qs = _evaluate(evaluate, asks)
    for k, ps in enumerate(searches):
        _decide_scan(spec, ps, xs, qs[k * len(xs):(k + 1) * len(xs)])
    r = 1
    while active := [ps for ps in searches if ps.status == "bisect"]:
        r += 1
        asks = [(ps.point, midpoint(ps.lo, ps.hi)) for ps in active]
        if on_round:
            on_round(searches, r, rounds, len(asks))
        for ps, (_, x), q in zip(active, asks, _evaluate(evaluate, asks)):
            _bisected(spec, ps, x, q)
    return searches


def _evaluate(evaluate, asks):
    qs = list(evaluate(asks)) if asks else []
    if len(qs) != len(asks):
        raise ValueError(f"evaluate returned {len(qs)} values for {len(asks)} points")
    return [q if q is PENDING or q is None or not math.isnan(q) else None for q in qs]


def progress_line(searches, round_, rounds, asking=0):
    """'search: 3/8 points done, round 2 of at most 6, 41 runs' (the runs of the search so far,
    the ``asking`` of this round included)."""
    done = sum(ps.done for ps in searches)
    runs = sum(ps.runs for ps in searches) + asking
    return f"search: {done}/{len(searches)} points done, round {round_} of at most {rounds}, {runs} runs"


def state_line(spec, searches):
    """The search's state in one line (`study status`): how many points have which status."""
    counts = {}
    for ps in searches:
        counts[ps.status] = counts.get(ps.status, 0) + 1
    done = sum(ps.done for ps in searches)
    open_ = len(searches) - done
    parts = [f"{n} {s}" for s, n in counts.items() if s in FINAL]
    if open_:
        parts.append(f"{open_} not finished")
    runs = sum(ps.runs for ps in searches)
    return (f"search of {spec.parameter} in [{spec.low:g}, {spec.high:g}] for {spec.quantity} <= "
            f"{spec.limit:g}: {done}/{len(searches)} points done ({', '.join(parts)}), {runs} runs")


# --- the [search] table ----------------------------------------------------------------


def parse_search(where, table, varied):
    """The [search] table as a SearchSpec; StudyError (one line) naming the culprit and what is
    allowed. ``varied``: the names the rest of the study varies. The quantity is checked once
    the runs are known (check_quantity)."""
    where = f"{where}: [search]"
    if not isinstance(table, dict):
        raise StudyError(f"{where} must be a table of {', '.join(KEYS)}")
    for k in table:
        if k not in KEYS:
            raise unknown(where, k, list(KEYS))
    missing = [k for k in KEYS if k not in table]
    if missing:
        raise StudyError(f"{where} lacks {', '.join(missing)}: it needs {', '.join(KEYS)}")
    name = table["parameter"]
    if not isinstance(name, str):
        raise StudyError(f"{where} parameter = {name!r} is not allowed: expected a parameter name (text)")
    check_name(where, name)
    rule = _numeric_rule(where, name)
    if name in varied:
        raise StudyError(f"{where} parameter '{name}' is also varied by [grid], [[zip]] or [[runs]]: "
                         "search it or vary it, not both")
    nums = {k: _number(where, k, table[k]) for k in ("low", "high", "tolerance", "limit")}
    for k in ("low", "high"):
        if not rule[1] <= nums[k] <= rule[2]:
            raise StudyError(f"{where} {k} = {nums[k]!r} is not allowed: {name} takes {rule[3]}")
    if nums["low"] >= nums["high"]:
        raise StudyError(f"{where} low = {nums['low']!r} is not allowed: expected a number below "
                         f"high = {nums['high']!r}")
    span = nums["high"] - nums["low"]
    if not 0.0 < nums["tolerance"] < span:
        raise StudyError(f"{where} tolerance = {nums['tolerance']!r} is not allowed: expected a number in "
                         f"(0, high - low = {span:g})")
    if not isinstance(table["quantity"], str):
        raise StudyError(f"{where} quantity = {table['quantity']!r} is not allowed: expected a summary "
                         "column name (text), e.g. peak_wheel1_force_y")
    return SearchSpec(parameter=name, quantity=table["quantity"], **nums)


def check_held_speed(where, spec, scenarios):
    """A search of the speed needs every run to hold its speed: the closed track's speed drive.
    The paper's bolted track coasts (on friction it brakes like a sled), another drive lets the
    speed go where the torque takes it: a limit speed found on them would be no speed at all."""
    if spec.parameter != "speed":
        return
    for sc in scenarios:
        layout, drive = sc["track"]["layout"], sc["drive"]["kind"]
        if layout != "closed" or drive != "speed":
            what = "the paper's bolted track coasts" if layout != "closed" else f"drive.kind = {drive!r}"
            raise StudyError(f"{where}: [search] parameter = speed needs the speed held, but {what}; "
                             'allowed: track.layout = "closed" with drive.kind = "speed"')


def _number(where, key, v):
    if not is_number(v) or not math.isfinite(v):
        raise StudyError(f"{where} {key} = {v!r} is not allowed: expected a finite number")
    return float(v)


def _numeric_rule(where, name):
    """The parameter table's rule (type, low, high, text) of a parameter that takes any number
    in a range; StudyError otherwise (texts, tables, integers: bisection needs every value)."""
    from trackbench.scenario.parameters_table import RULES, TERRAIN_RULES
    rule = TERRAIN_RULES.get(name[len("terrain."):]) if name.startswith("terrain.") else RULES.get(name)
    if rule is None or rule[0] is not float:
        what = rule[3] if rule else "a table"
        raise StudyError(f"{where} parameter = '{name}' is not allowed: expected a parameter that takes "
                         f"any number in a range ('{name}' takes {what})")
    return rule


def check_quantity(where, spec, columns):
    """StudyError unless the quantity is one of the study's summary ``columns``."""
    if spec.quantity in columns:
        return
    from trackbench.outputs.quantities import quantity_of
    known = quantity_of(spec.quantity)
    if known and known[0].needs:
        model = {"closed": "the closed track", "soil": "soft soil"}[known[0].needs]
        raise StudyError(f"{where}: [search] quantity = '{spec.quantity}' is a quantity of runs with {model} "
                         "only, and no run of this study has it")
    close = difflib.get_close_matches(spec.quantity, columns, n=3, cutoff=0.5)
    names = [c for c in columns if c[:-len("_time")] not in columns]
    hint = f"did you mean {', '.join(close)}?" if close else (f"allowed: {', '.join(names)} (and each "
                                                              "peak's time, <name>_time)")
    raise StudyError(f"{where}: [search] quantity = '{spec.quantity}' is not a summary quantity of this "
                     f"study; {hint}")
