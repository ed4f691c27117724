"""Storage of a run's files: full (lossless) and compact (the resolution results_schema.md states)."""

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from trackbench.outputs.files import storage
from trackbench.outputs.files.netcdf import write_netcdf
from trackbench.study import StudyError, load_study, run_study, store

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def files(paper_run, tmp_path_factory):
    """paper_step written by xarray itself (the writer before outputs/files/storage.py), full and compact."""
    d = tmp_path_factory.mktemp("storage")
    paper_run.to_netcdf(
        d / "xarray.nc", engine="netcdf4", encoding={k: {"_FillValue": None} for k in paper_run.coords}
    )
    write_netcdf(paper_run, d / "full.nc")
    write_netcdf(paper_run, d / "compact.nc", storage="compact")
    return d


def schema_bounds():
    """variable -> ("absolute" | "relative", bound) from results_schema.md's compact table: its
    first row names the positions, its second row holds for every other time history ("*")."""
    text = (REPO / "results_schema.md").read_text()
    rows = re.findall(r"^\| (.+?) \| .+? \| (absolute|relative) ([0-9.e-]+)", text, re.M)
    assert len(rows) == 2 and rows[1][0].startswith("every other"), "results_schema.md: the compact table"
    bounds = {name: (rows[0][1], float(rows[0][2])) for name in re.findall(r"`([a-z_]+)`", rows[0][0])}
    bounds["*"] = (rows[1][1], float(rows[1][2]))
    return bounds


def test_full_storage_reads_back_bit_for_bit_as_the_xarray_writer(files):
    a, b = xr.load_dataset(files / "xarray.nc"), xr.load_dataset(files / "full.nc")
    assert set(a.variables) == set(b.variables)
    for k in a.variables:
        assert a[k].dtype == b[k].dtype and a[k].dims == b[k].dims and a[k].attrs == b[k].attrs, k
        assert np.array_equal(a[k].values, b[k].values, equal_nan=True), k
    assert b.attrs == {**a.attrs, "storage": "full"}
    assert (files / "full.nc").stat().st_size < 0.9 * (files / "xarray.nc").stat().st_size


def test_compact_is_smaller_and_within_the_resolution_results_schema_states(files, paper_run):
    full, compact = xr.load_dataset(files / "full.nc"), xr.load_dataset(files / "compact.nc")
    assert (files / "compact.nc").stat().st_size < 0.4 * (files / "full.nc").stat().st_size
    assert compact.attrs["storage"] == "compact"
    bounds = schema_bounds()
    reduced = 0
    for k in full.data_vars:
        a, b = full[k].values, compact[k].values
        if not storage.is_history(k, full[k]):
            assert np.array_equal(a, b, equal_nan=True), k  # peaks and their times: as computed
            continue
        kind, bound = bounds.get(k, bounds["*"])
        err = np.abs(b - a)
        limit = bound if kind == "absolute" else bound * np.abs(a)
        assert np.all(err <= limit), (k, float(np.max(err - limit)))
        assert np.array_equal(np.isnan(a), np.isnan(b)) and np.array_equal(a == 0, b == 0), k
        reduced += not np.array_equal(a, b)
        assert compact[k].attrs["resolution"] and compact[k].attrs["units"] == full[k].attrs["units"]
    assert reduced >= 20
    assert np.array_equal(compact.time.values, paper_run.time.values)


def test_compact_positions_too_wide_for_int32_are_kept_exactly(tmp_path):
    x = np.array([[0.0, 1.0], [300.0, np.nan]])
    ds = xr.Dataset(
        {"pin_x": (("time", "pin"), x, {"units": "m"}), "pin_y": (("time", "pin"), x / 1e3)},
        coords={"time": [0.0, 1.0], "pin": [0, 1]},
    )
    write_netcdf(ds, tmp_path / "c.nc", storage="compact")
    back = xr.load_dataset(tmp_path / "c.nc")
    assert back.pin_x.dtype == np.float64 and np.array_equal(back.pin_x.values, x, equal_nan=True)
    assert np.nanmax(np.abs(back.pin_y.values - x / 1e3)) <= 5e-8 and np.isnan(back.pin_y.values[1, 1])


def test_bad_storage_names_the_value_and_what_is_allowed(tmp_path):
    with pytest.raises(ValueError, match=r"^--storage 'small' is not allowed: expected full or compact$"):
        storage.check_storage("small")
    p = tmp_path / "s.toml"
    p.write_text("[study]\nname = 's'\nstorage = 'tiny'\n")
    with pytest.raises(
        StudyError, match=r"\[study\] storage = 'tiny' is not allowed: expected full or compact"
    ):
        load_study(p)
    r = subprocess.run(
        [
            sys.executable,
            "-c",
            "from trackbench.cli import main; main()",
            "run",
            "--storage",
            "x",
            "--out",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert (
        r.returncode == 2
        and r.stderr.strip() == "error: --storage 'x' is not allowed: expected full or compact"
    )
    assert not list(tmp_path.glob("*.nc"))


def test_study_with_compact_storage_has_the_same_summary(tmp_path):
    p = tmp_path / "c.toml"
    p.write_text(
        "[study]\nname = 'c'\nstorage = 'compact'\n[scenario]\nduration = 0.1\noutput_interval = 0.001\n"
        "[grid]\nspeed = [8.0, 12.0]\n"
    )
    compact = run_study(p, workers=2, output=tmp_path / "c", quiet=True)
    full = run_study(p, workers=2, output=tmp_path / "f", quiet=True, storage="full")
    assert compact.problem() is None and full.problem() is None
    cols = [c for c in full.summary.columns if c not in ("wall_time", "solve_time")]
    pd.testing.assert_frame_equal(compact.summary[cols], full.summary[cols])
    for rid in compact.summary.run_id:
        c, f = store.run_dir(tmp_path / "c", rid), store.run_dir(tmp_path / "f", rid)
        rc, rf = json.loads((c / "run.json").read_text()), json.loads((f / "run.json").read_text())
        assert (rc["storage"], rf["storage"]) == ("compact", "full") and rc["results"] == rf["results"]
        with xr.open_dataset(c / "timeseries.nc") as ds:
            assert ds.attrs["storage"] == "compact" and ds.link_tension.encoding["dtype"] == np.float32
        for name in ("timeseries.nc", "recording.rrd"):
            assert (c / name).stat().st_size < (f / name).stat().st_size, name  # (short runs: mostly headers)
    assert 'storage = "compact"' in (tmp_path / "c" / "study.toml").read_text()


def test_run_command_with_compact_storage(tmp_path):
    r = subprocess.run(
        [
            sys.executable,
            "-c",
            "from trackbench.cli import main; main()",
            "run",
            "--storage",
            "compact",
            "--duration",
            "0.05",
            "--set",
            "output_interval=0.001",
            "--out",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    with xr.open_dataset(tmp_path / "paper_step.nc") as ds:
        assert ds.attrs["storage"] == "compact" and ds.pin_x.encoding["dtype"] == np.int32
    assert (tmp_path / "paper_step.rrd").stat().st_size > 0
