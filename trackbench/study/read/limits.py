"""A study's [search] read back from its results folder: each value asked for is read from
its run (the run id a grid with that value gives), so the search replays as far as the runs
go; limits.csv and the search's state in one line.

    <output>/limits.csv   one row per grid point: its parameters, search_value, status, runs,
                          limit_run (the run id at search_value, to replay)
"""

from pathlib import Path

from trackbench.study import store
from trackbench.study.spec import search as S
from trackbench.study.spec.study_file import search_run

LIMIT_COLUMNS = ["search_value", "status", "runs", "limit_run"]
LIMITS_FILE = "limits.csv"


def _bounded_below(name):
    """A quantity that a run which stopped early gives as the least the whole run's could be:
    a largest value over the run (it can only grow as the run goes) or a ride figure."""
    from trackbench.outputs.metrics.ride import SECOND_HALF

    return name.startswith(("peak_", "max_")) or name in SECOND_HALF


def failed_over_limit(frame, quantity, limit):
    """The rows of a summary whose run failed with a quantity bounded below (_bounded_below)
    already over the limit: runs quantity_of counts as over it (a boolean Series; all False for
    another quantity, or one not in the summary)."""
    import pandas as pd

    if quantity not in frame or "status" not in frame or not _bounded_below(quantity):
        return pd.Series(False, index=frame.index)
    return (frame["status"].astype(str) == "failed") & (frame[quantity] > limit)


def quantity_of(study, run):
    """The searched quantity of a run as the results folder has it: a number, None (the run
    failed, or gave no number) or search.PENDING (not run, or not finished). A failed run
    whose quantity is bounded below (_bounded_below) and already over the limit counts with
    that value: the rest of the run could only have raised it (a step too high at that speed
    throws the idler off its guide after the seat has seen its 2.5 g; a track thrown on rough
    ground after the seat has absorbed more than its 6 W over the half it was to average)."""
    if run is None:
        return S.PENDING
    rec = store.read_run(study.output, run.run_id)
    if rec is None:
        return S.PENDING
    value = (rec.get("results") or {}).get(study.search.quantity)
    value = None if value is None else float(value)
    if rec.get("status") == "failed":
        over = value is not None and _bounded_below(study.search.quantity) and value > study.search.limit
        return value if over else None
    if not store.is_completed(study.output, run.run_id):
        return S.PENDING
    return value


def replay(study):
    """The search as far as the results folder has it: every value asked for is read from its
    run, nothing runs. The runs asked for that a study file makes are added to study.runs (the
    ones to run next are pending); a study read from its folder knows only the runs it recorded."""
    def evaluate(asks):
        return [quantity_of(study, search_run(study, i, x)) for i, x in asks]

    return S.search_limits(study.search, range(len(study.points)), evaluate)


def search_state(study):
    """The search's state in one line (replays it)."""
    return S.state_line(study.search, replay(study))


def limits_frame(study, searches):
    """One row per grid point: the grid's parameters, search_value, status, runs, limit_run."""
    import pandas as pd

    from trackbench.study.spec.study_file import _param_value
    names = [n for n in study.param_names if n != study.search.parameter]
    rows = []
    for ps in searches:
        row = {n: _param_value(study.points[ps.point][n]) if n in study.points[ps.point] else None
               for n in names}
        at = search_run(study, ps.point, ps.search_value) if ps.search_value is not None else None
        row.update(search_value=ps.search_value, status=ps.status, runs=ps.runs,
                   limit_run=at.run_id if at is not None else None)
        rows.append(row)
    df = pd.DataFrame(rows, columns=names + LIMIT_COLUMNS)
    df["search_value"] = df["search_value"].astype(float)
    df.attrs.update(study=study.name, study_dir=str(study.output))
    return df


def write_limits(study):
    """Replay the search, write limits.csv (atomically); returns (its DataFrame, the state line)."""
    searches = replay(study)
    df = limits_frame(study, searches)
    with store.atomic_path(Path(study.output) / LIMITS_FILE) as tmp:
        df.to_csv(tmp, index=False)
    return df, S.state_line(study.search, searches)


def over_seeds(limits, seed="terrain.seed"):
    """A search over several seeds of a random ground, one limit per grid point but the seed:
    the median of the seeds' limits with their min and max and how many were found (a pandas
    DataFrame; a point whose limit was not found counts out of the median, its status counted
    in ``found``). The seeds' own limits stay in limits.csv."""
    axes = [c for c in limits.columns if c not in (seed, *LIMIT_COLUMNS)]
    found = limits[limits["status"].isin(["found", "non_monotone"])]
    by = (found.groupby(axes, sort=True) if axes else found.groupby(lambda _: 0))["search_value"]
    out = by.agg(median="median", min="min", max="max", found="count").reset_index()
    seeds = limits.groupby(axes, sort=True)[seed].count().reset_index(name="seeds") if axes else None
    return out.merge(seeds, on=axes, how="right") if axes else out.assign(seeds=len(limits))
