"""Big studies: status and summary from the small per-run records, a coordinator that holds no
run's arrays, the runs stacked lazily from their files' headers."""

import gc
import json
import os

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

import trackbench as tb
from trackbench.cli.app import app
from trackbench.study import load_study, run_study, store
from trackbench.study.execute import runner
from trackbench.study.read.opening import _STACK
from trackbench.study.read.summary import write_summary

N = 300


def _record(folder, run, status):
    """A run.json as a worker writes it (results as the summary reads them; no netCDF read)."""
    rec = {"run_id": run.run_id, "status": status, "status_message": "" if status == "completed" else
           "diverged at t = 0.01 s", "index": run.index, "variant": run.variant, "replicate": run.replicate,
           "params": run.params, "scenario": run.scenario, "steps": 10, "rejected_steps": 1,
           "t_final": 0.01, "wall_time": 0.2, "solve_time": 0.1,
           "results": {"peak_ground_force_y": 1000.0 + run.index, "first_contact_time": 0.05}}
    store.write_json(store.run_dir(folder, run.run_id) / "run.json", rec)


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """A 300-run study whose run folders are written here, not run: 250 completed, 20 failed,
    30 never started. Every completed run's timeseries.nc is garbage: status and summary must
    not open it."""
    d = tmp_path_factory.mktemp("big")
    (d / "big.toml").write_text(
        '[study]\nname = "big"\n[scenario]\nduration = 0.01\n'
        f"[grid]\nspeed = {{ start = 1.0, stop = {1.0 + 0.01 * (N - 0.5):.3f}, step = 0.01 }}\n"
    )
    study = load_study(d / "big.toml", output=d / "results")
    study.output.mkdir()
    store.write_json(study.output / "runs.json", runner.manifest(study))
    for run in study.runs[:270]:
        _record(study.output, run, "completed" if run.index < 250 else "failed")
        if run.index < 250:
            (store.run_dir(study.output, run.run_id) / "timeseries.nc").write_bytes(b"not a netCDF file")
    return d, study


def test_status_of_a_big_study_reads_the_run_records_only(generated):
    d, study = generated
    assert len(study.runs) == N
    r = CliRunner().invoke(app, ["study", "status", str(d / "results")])
    assert r.exit_code == 0, r.output
    assert f"{N} runs: 250 done, 20 failed, 30 pending" in r.output
    assert r.output.count("failed ") == 20 and "diverged at t = 0.01 s" in r.output


def test_summary_of_a_big_study_from_the_run_records(generated):
    d, study = generated
    df, rep = write_summary(study)
    assert rep is None and len(df) == N
    assert (df.status.value_counts().to_dict()) == {"completed": 250, "pending": 30, "failed": 20}
    ok = df[df.status == "completed"]
    assert np.array_equal(ok.peak_ground_force_y.to_numpy(), 1000.0 + np.arange(250))
    written = (d / "results" / "summary.csv").read_text().splitlines()
    assert len(written) == N + 1 and written[0].startswith("run_id,status")


def test_the_coordinator_holds_no_run_arrays(tmp_path, monkeypatch):
    """What a worker sends back is a small record of plain values (no array of the run's
    time histories), and nothing the size of a run's arrays stays alive in the coordinator."""
    (tmp_path / "s.toml").write_text(
        '[study]\nname = "s"\n[scenario]\nduration = 0.02\noutput_interval = 1e-4\n'
        "record = { enabled = false }\n[grid]\nspeed = [5.0, 6.0, 7.0, 8.0]\n"
    )
    seen, confirm = [], runner.confirm

    def spy(task, rec):
        seen.append(len(json.dumps(rec)))   # plain values only: no default= needed
        return confirm(task, rec)

    monkeypatch.setattr(runner, "confirm", spy)
    gc.collect()
    # held here, so that no new array can take an old one's id; type(): a dead weak proxy raises
    before = {id(o): o for o in gc.get_objects() if type(o) is np.ndarray and o.nbytes > 16_000}
    out = run_study(tmp_path / "s.toml", workers=2, output=tmp_path / "out", quiet=True)
    gc.collect()
    big = [o for o in gc.get_objects()
           if type(o) is np.ndarray and o.nbytes > 16_000 and id(o) not in before]
    assert out.problem() is None and len(seen) == 4
    # a run's chassis_y alone is 201 x 8 bytes; pin_x 201 x 31 x 8 = 50 kB
    assert max(seen) < 16_000 and not big


def _durations(tmp_path, intervals=(0.001, 0.001)):
    p = tmp_path / "a.toml"
    runs = "".join(f"[[runs]]\nduration = {d}\noutput_interval = {i}\n"
                   for d, i in zip((0.03, 0.05), intervals))
    p.write_text(f"[study]\nname = 'a'\n[scenario]\nrecord = {{ enabled = false }}\n{runs}")
    run_study(p, workers=2, output=tmp_path / "a", quiet=True)
    return sorted((tmp_path / "a" / "runs").glob("*/timeseries.nc"))


def test_runs_stacked_from_their_headers_are_xarrays_concatenation(tmp_path):
    """The lazy stacking gives what xarray's outer concatenation of the loaded files gives,
    a shorter run NaN-padded; a selection reads only the runs it selects."""
    from trackbench.study.read.stacked import open_stacked

    files = _durations(tmp_path)
    lazy = open_stacked(files, chunk=False)
    eager = xr.concat([xr.load_dataset(p) for p in files], dim="run", **_STACK)
    assert lazy.identical(eager.load()) and lazy.sizes["time"] == 51
    long = int(np.argmax(np.isfinite(eager.chassis_y.values[:, -1])))   # the 0.05 s run
    os.remove(files[1 - long])   # only the longer run is read below
    assert np.isfinite(lazy.chassis_y.isel(run=long).values).all()
    with pytest.raises(FileNotFoundError):
        lazy.chassis_y.isel(run=1 - long).values


def test_runs_that_do_not_line_up_are_left_to_xarray(tmp_path):
    """Runs of different output intervals do not share a time axis: open_stacked says so (None)
    and open_study_dataset aligns them with xarray on the union of their times."""
    from trackbench.study.read.stacked import open_stacked

    files = _durations(tmp_path, intervals=(0.001, 0.002))
    assert open_stacked(files) is None
    ds = tb.open_study_dataset(tmp_path / "a")
    assert ds.sizes["run"] == 2 and ds.sizes["time"] == 41   # 0..0.03 by 1 ms, then 0.032..0.05 by 2 ms
    ds.close()


def test_the_coordinator_checks_a_runs_file_by_its_signature_and_size(tmp_path):
    """A completed run's timeseries.nc is taken when it starts as netCDF-4 and has the size the
    worker reported; the same size of other bytes is not; a record without the size (a worker
    of an earlier version) has its file opened."""
    from trackbench.study.execute import executors

    (tmp_path / "c.toml").write_text('[study]\nname = "c"\n[scenario]\nduration = 0.01\n'
                                     "record = { enabled = false }\n")
    s = load_study(tmp_path / "c.toml", output=tmp_path / "c")
    s.output.mkdir()
    store.write_json(s.output / "runs.json", {})
    task = {"run_id": s.runs[0].run_id, "output": str(s.output), "scenario": s.runs[0].scenario,
            "meta": {}, "attempt_id": "a1"}
    rec = executors.execute_run(task)
    nc = store.run_dir(s.output, task["run_id"]) / "timeseries.nc"
    assert rec["timeseries_bytes"] == nc.stat().st_size and runner.confirm(task, rec) is rec
    old = {k: v for k, v in rec.items() if k != "timeseries_bytes"}
    assert runner.confirm(task, old) is old
    good = nc.read_bytes()
    nc.write_bytes(b"\0" * len(good))
    got = runner.confirm(task, rec)
    assert got["status"] == "failed" and "not a netCDF-4 (HDF5) file" in got["status_message"]
    assert not nc.exists()
