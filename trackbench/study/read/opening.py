"""A study's results as Python objects: open_study (the summary as a pandas DataFrame, or one
run's Dataset), open_study_dataset (every run on a "run" dimension, lazily), open_limits (a
search's limits.csv)."""

from __future__ import annotations

import importlib.util
import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Union

import numpy as np

from trackbench.study import store
from trackbench.study.read.folder import _study_of, study_folder
from trackbench.study.read.limits import LIMITS_FILE
from trackbench.study.read.summary import summary_frame
from trackbench.study.spec.study_file import StudyError

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr

StudyPath = Union[str, "os.PathLike[str]"]   # a study file (TOML) or its results folder

_STACK: dict[str, Any] = dict(
    join="outer", data_vars="all", coords="minimal", compat="override", combine_attrs="drop_conflicts"
)


def open_run(path: StudyPath, run: int | str) -> xr.Dataset:
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


def open_study(path: StudyPath, run: int | str | None = None) -> pd.DataFrame | xr.Dataset:
    """The summary of a study (a study file or its results folder) as a pandas DataFrame,
    rebuilt from the runs' run.json; with ``run`` (id, id prefix or row number) that run's
    Dataset instead. ``df.attrs['study_dir']`` is the results folder."""
    if run is not None:
        return open_run(path, run)
    return summary_frame(_study_of(path))


def _have_dask() -> bool:
    return importlib.util.find_spec("dask") is not None


def _stacked(paths: Sequence[Path], lazy: bool) -> xr.Dataset:
    """The runs' files along ``run``, lazily from their headers (stacked.py: one dask chunk per
    run where dask is installed); where they do not line up, with xarray.open_mfdataset where
    dask is installed (the `dask` extra), else read into memory (each file closed after reading)."""
    import xarray as xr

    from trackbench.study.read.stacked import open_stacked
    ds = open_stacked(paths, chunk=lazy)
    if ds is not None:
        return ds
    if lazy:
        return xr.open_mfdataset(paths, combine="nested", concat_dim="run", parallel=False, **_STACK)
    return xr.concat([xr.load_dataset(p) for p in paths], dim="run", **_STACK)


def open_study_dataset(path: StudyPath, status: Iterable[str] = ("completed", "failed")) -> xr.Dataset:
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


def open_limits(path: StudyPath) -> pd.DataFrame:
    """limits.csv of a study with [search] (a study file or its results folder) as a pandas
    DataFrame: one row per grid point, its parameters, search_value, status, runs."""
    import pandas as pd

    study, folder = study_folder(path)
    if study.search is None:
        raise StudyError(f"study {study.name} has no [search] table, so no {LIMITS_FILE}")
    p = Path(folder) / LIMITS_FILE
    if not p.is_file():
        raise FileNotFoundError(f"{p} does not exist: run `trackbench study run` on the study first")
    df = pd.read_csv(p, dtype={"status": str})
    df.attrs.update(study=study.name, study_dir=str(folder))
    return df
