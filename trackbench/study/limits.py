"""A study's [search] with runs: every value search.py asks for is a run of the study (the run id
a grid with that value gives), run in waves on the study's executor; limits.csv, open_limits
and the search's state read back from the results folder.

    <output>/limits.csv   one row per grid point: its parameters, search_value, status, runs,
                          limit_run (the run id at search_value, to replay)
"""

from pathlib import Path

from . import search as S
from . import store
from .spec import StudyError, search_run

LIMIT_COLUMNS = ["search_value", "status", "runs", "limit_run"]
LIMITS_FILE = "limits.csv"


def _is_maximum(name):
    """A quantity that is the largest value over the run (it can only grow as the run goes)."""
    return name.startswith(("peak_", "max_"))


def failed_over_limit(frame, quantity, limit):
    """The rows of a summary whose run failed with a maximum already over the limit: runs
    quantity_of counts as over it (a boolean Series; all False for a quantity that is no
    maximum, or not in the summary)."""
    import pandas as pd

    if quantity not in frame or "status" not in frame or not _is_maximum(quantity):
        return pd.Series(False, index=frame.index)
    return (frame["status"].astype(str) == "failed") & (frame[quantity] > limit)


def quantity_of(study, run):
    """The searched quantity of a run as the results folder has it: a number, None (the run
    failed, or gave no number) or search.PENDING (not run, or not finished). A failed run
    whose quantity is a maximum already over the limit when it stopped counts with that
    value: the rest of the run could only have raised it (a step too high at that speed
    throws the idler off its guide after the seat has seen its 2.5 g)."""
    if run is None:
        return S.PENDING
    rec = store.read_run(study.output, run.run_id)
    if rec is None:
        return S.PENDING
    value = (rec.get("results") or {}).get(study.search.quantity)
    value = None if value is None else float(value)
    if rec.get("status") == "failed":
        over = value is not None and _is_maximum(study.search.quantity) and value > study.search.limit
        return value if over else None
    if not store.is_completed(study.output, run.run_id):
        return S.PENDING
    return value


def run_search(study, wave, say):
    """Search every grid point of the study: ``wave(runs)`` runs those of ``runs`` not completed
    (the scan of all points in one wave, then one wave per round of bisection); ``say(text)``
    hears how far the search is. Returns the search.PointSearch of every point."""
    def evaluate(asks):
        runs = [search_run(study, i, x) for i, x in asks]
        wave(runs)
        return [quantity_of(study, r) for r in runs]

    def on_round(searches, round_, rounds, asking):
        say(S.progress_line(searches, round_, rounds, asking))

    searches = S.search_limits(study.search, range(len(study.points)), evaluate, on_round)
    say(S.state_line(study.search, searches))
    return searches


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

    from .spec import _param_value
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


def open_limits(path):
    """limits.csv of a study with [search] (a study file or its results folder) as a pandas
    DataFrame: one row per grid point, its parameters, search_value, status, runs."""
    import pandas as pd

    from .summary import study_folder
    study, folder = study_folder(path)
    if study.search is None:
        raise StudyError(f"study {study.name} has no [search] table, so no {LIMITS_FILE}")
    p = Path(folder) / LIMITS_FILE
    if not p.is_file():
        raise FileNotFoundError(f"{p} does not exist: run `trackbench study run` on the study first")
    df = pd.read_csv(p, dtype={"status": str})
    df.attrs.update(study=study.name, study_dir=str(folder))
    return df
