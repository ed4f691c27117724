"""Reading a study: the pandas summary, replicate statistics, open_study / open_study_dataset.
pandas loads in the functions that build frames: finding a study's folder (`study status`)
does without it."""

import importlib.util
import os
from pathlib import Path

import numpy as np

from .. import quantities as Q
from . import store
from .search import SearchSpec
from .spec import Run, Study, StudyError, load_study

SPREAD_LIMIT = 0.05  # replicates: flag a quantity whose (max - min) / |median| exceeds this
# the results in the study table on screen, in its column order (vertical acceleration as min, max)
SCREEN = (
    "peak_wheel_force_y",
    "peak_ground_force_y",
    "peak_link_tension",
    "min_chassis_ay",
    "peak_chassis_ay",
    "min_chassis_vx",
    "peak_seat_acceleration_g",
    "absorbed_power",
    "first_compression_time",
    "peak_sprocket_torque",
    "peak_idler_force",
    "peak_sinkage",
    "mean_drawbar_pull",
    "mean_slip",
)


def peak_columns(study):
    """The summary's peak and mean columns, in summary order (replicate statistics cover these)."""
    return Q.peak_columns(*Q.shape_of(r.scenario for r in study.runs))


def summary_frame(study):
    """One row per run of the study (pending when it has not run), from the runs' run.json."""
    import pandas as pd
    wheels, features = Q.shape_of(r.scenario for r in study.runs)
    results = Q.summary_columns(wheels, features=features)
    rows = []
    for run in study.runs:
        rec = store.read_run(study.output, run.run_id) or {"status": "pending", "status_message": ""}
        res = rec.get("results") or {}
        row = {"run_id": run.run_id, "status": rec["status"], "status_message": rec.get("status_message", ""),
               "variant": run.variant, "replicate": run.replicate}
        row.update({n: run.params.get(n) for n in study.param_names})
        row.update({k: res.get(k) for k in results})
        for k in ("steps", "rejected_steps", "t_final", "wall_time", "solve_time"):
            row[k] = rec.get(k)
        rows.append(row)
    df = pd.DataFrame(rows)
    num = results + ["t_final", "wall_time", "solve_time"]
    df[num] = df[num].astype(float)
    for k in ("steps", "rejected_steps"):
        df[k] = df[k].astype("Int64")
    df.attrs.update(study=study.name, study_dir=str(study.output))
    return df


def replicate_frame(study, df):
    """One row per variant: median, min, max and relative spread of every peak over its completed
    replicates; ``sensitive`` lists the quantities whose spread exceeds 5 %."""
    import pandas as pd
    params = [p for p in study.param_names if p != "seed"]
    rows = []
    for v, g in df.groupby("variant", sort=True):
        ok = g[g.status == "completed"]
        row = {"variant": v, **{p: g[p].iloc[0] for p in params},
               "replicates": len(g), "completed": len(ok)}
        flagged = []
        for q in peak_columns(study):
            x = ok[q].dropna()
            med = float(x.median()) if len(x) else np.nan
            lo, hi = (float(x.min()), float(x.max())) if len(x) else (np.nan, np.nan)
            spread = (hi - lo) / abs(med) if len(x) and med != 0 else np.nan
            row.update({f"{q}_median": med, f"{q}_min": lo, f"{q}_max": hi, f"{q}_spread": spread})
            if spread > SPREAD_LIMIT:
                flagged.append(q)
        row["sensitive"] = " ".join(flagged)
        rows.append(row)
    return pd.DataFrame(rows)


def write_summary(study):
    """Rebuild and write summary.csv (.parquet) (and replicates.csv); returns the frames."""
    df = summary_frame(study)
    store.write_table(df, study.output / "summary")
    rep = None
    if study.replicates > 1:
        rep = replicate_frame(study, df)
        store.write_table(rep, study.output / "replicates")
    return df, rep


def format_table(df, rep=None, params=()):
    """A screen-sized table: the SCREEN quantities in their display units (forces in kN)."""
    import pandas as pd
    show = pd.DataFrame({"run": df.run_id.str[:8], "status": df.status})
    for p in params:
        show[p] = df[p]
    for name in SCREEN:
        q = Q.BY_NAME[name]
        for c in q.present(df.columns):
            show[q.heading.format(q.wheel_of(c))] = q.display(df[c])
    show["wall s"] = df.wall_time
    text = show.to_string(index=False, float_format=lambda x: f"{x:.4g}", na_rep="-")
    bad = df[df.status == "failed"]
    for _, r in bad.iterrows():
        text += f"\nfailed {r.run_id}: {r.status_message}"
    if rep is not None:
        cols = [p for p in params if p != "seed"] + ["completed"]
        t = rep[cols].copy()
        g = Q.BY_NAME["peak_ground_force_y"]
        t[g.heading + " median [min, max]"] = [
            f"{g.display(a):.4g} [{g.display(b):.4g}, {g.display(c):.4g}]" for a, b, c in
            zip(rep[g.name + "_median"], rep[g.name + "_min"], rep[g.name + "_max"])]
        t["spread > 5 %"] = rep.sensitive.replace("", "-")
        text += "\n\nreplicates (median, min, max over seeds; full table in replicates.csv):\n"
        text += t.to_string(index=False)
    return text


def _study_of(path):
    """A study file, or a results folder (its runs.json, written by `study run`). A study file
    with [search] gets the runs its search has asked for so far (limits.replay)."""
    path = Path(path)
    if not path.is_dir():
        return _searched(load_study(path))
    m = store.read_json(path / "runs.json")
    if m is None:
        return load_study(path / "study.toml", output=path)
    search = SearchSpec(**m["search"]) if m.get("search") else None
    study = Study(name=m["name"], description=m["description"], source=path / "study.toml", output=path,
                  replicates=m["replicates"], base={}, param_names=m["param_names"], search=search,
                  points=m.get("points", []))
    study.runs = [Run(**r) for r in m["runs"]]
    return study


def _searched(study):
    """A study file's study, with [search] the runs its search has asked for so far added."""
    if study.search is not None and Path(study.output).is_dir():
        from .limits import replay
        replay(study)
    return study


def missing_folder(study):
    """'<folder> does not exist (why it was looked for there)': a study file's missing results folder."""
    out = Path(study.output)
    where = "" if out.is_absolute() else (" ([study] output is relative to the directory `study run` ran in: "
                                          "run this there, or give the results folder)")
    return f"{os.path.abspath(out)} does not exist{where}"


def study_folder(path):
    """A study file or its results folder -> (study, results folder); StudyError (one line)
    when the path or the results folder does not exist. A study file's folder is its [study]
    output (default results/<name>) relative to the current directory, as `study run` puts it."""
    path = Path(path)
    if not path.exists():
        raise StudyError(f"{path} does not exist")
    if path.is_dir():
        if not ((path / "runs.json").is_file() or (path / "study.toml").is_file()):
            raise StudyError(f"{path} is not a study results folder (no runs.json or study.toml inside)")
        return _study_of(path), path
    study = load_study(path)
    if not Path(study.output).is_dir():
        raise StudyError(f"no results of study {study.name}: {missing_folder(study)}")
    return _searched(study), Path(study.output)


def open_run(path, run):
    """One run's Dataset (xarray.open_dataset) by run id, id prefix or row number."""
    import xarray as xr
    study = _study_of(path)
    ids = [r.run_id for r in study.runs]
    if isinstance(run, (int, np.integer)):
        rid = ids[run]
    else:
        match = [i for i in ids if i.startswith(str(run))]
        if len(match) != 1:
            raise KeyError(f"run {run!r} matches {len(match)} runs of study {study.name}")
        rid = match[0]
    return xr.open_dataset(store.run_dir(study.output, rid) / "timeseries.nc")


def open_study(path, run=None):
    """The summary of a study (a study file or its results folder) as a pandas DataFrame,
    rebuilt from the runs' run.json; with ``run`` (id, id prefix or row number) that run's
    Dataset instead. ``df.attrs['study_dir']`` is the results folder."""
    if run is not None:
        return open_run(path, run)
    return summary_frame(_study_of(path))


_STACK = dict(
    join="outer", data_vars="all", coords="minimal", compat="override", combine_attrs="drop_conflicts"
)


def _have_dask():
    return importlib.util.find_spec("dask") is not None


def _stacked(paths, lazy):
    """The runs' files along ``run``, lazily from their headers (stacked.py: one dask chunk per
    run where dask is installed); where they do not line up, with xarray.open_mfdataset where
    dask is installed (the `dask` extra), else read into memory (each file closed after reading)."""
    import xarray as xr

    from .stacked import open_stacked
    ds = open_stacked(paths, chunk=lazy)
    if ds is not None:
        return ds
    if lazy:
        return xr.open_mfdataset(paths, combine="nested", concat_dim="run", parallel=False, **_STACK)
    return xr.concat([xr.load_dataset(p) for p in paths], dim="run", **_STACK)


def open_study_dataset(path, status=("completed", "failed")):
    """All runs' time histories stacked along a ``run`` dimension, opened lazily: a run's file
    is read when a selection needs it (one dask chunk per run where dask is installed); runs of
    different durations are aligned on time (NaN-padded). The study's parameters and each run's status
    become coordinates along ``run``."""
    study = _study_of(path)
    df = summary_frame(study)
    df = df[df.status.isin(status)]
    paths = [store.run_dir(study.output, r) / "timeseries.nc" for r in df.run_id]
    keep = [p.exists() for p in paths]
    df, paths = df[keep], [p for p, k in zip(paths, keep) if k]
    if not paths:
        raise FileNotFoundError(f"no run of study {study.name} has a timeseries.nc yet")
    ds = _stacked(paths, lazy=_have_dask())
    coords = {"run": ("run", df.run_id.to_numpy()), "status": ("run", df.status.to_numpy())}
    for p in study.param_names:
        coords[p] = ("run", df[p].to_numpy())
    return ds.assign_coords(coords)
