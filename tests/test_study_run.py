"""Studies end to end: CLI, resume after kill -9, failure isolation, lock, dask, reading results."""

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import trackbench as tb
from trackbench.study import StudyLocked, load_study, run_study, store
from trackbench.study.read.summary import write_summary

REPO = Path(__file__).resolve().parents[1]
CLI = [sys.executable, "-c", "from trackbench.cli import main; main()"]
FAST = "duration = 0.05\noutput_interval = 0.001\nrecord = { enabled = false }\n"


def cli(args, cwd, timeout=300):
    return subprocess.run(CLI + args, cwd=cwd, capture_output=True, text=True, timeout=timeout)


def files(folder):
    """path -> (inode, mtime_ns) of every file below folder."""
    return {
        str(p.relative_to(folder)): (p.stat().st_ino, p.stat().st_mtime_ns)
        for p in Path(folder).rglob("*")
        if p.is_file()
    }


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    """The shipped speed sweep at 0.05 s through the CLI (2 workers), then a resume."""
    d = tmp_path_factory.mktemp("sweep")
    text = (REPO / "studies" / "speed_sweep.toml").read_text().replace("duration = 0.5", "duration = 0.05")
    (d / "speed_sweep.toml").write_text(
        text.replace('solver = "reduced"', 'solver = "reduced"\nrecord = { enabled = false }')
    )
    first = cli(["study", "run", "speed_sweep.toml"], d)
    snap = files(d / "results" / "speed_sweep" / "runs")
    second = cli(["study", "run", "speed_sweep.toml"], d)
    return d, first, snap, second


def test_speed_sweep_cli_end_to_end(sweep):
    d, first, _, _ = sweep
    assert first.returncode == 0, first.stderr
    out = d / "results" / "speed_sweep"
    assert "15 runs, 15 run now, 0 already completed, 0 failed" in first.stdout
    assert "[15/15]" in first.stderr and "ETA" in first.stderr
    progress = [line for line in first.stderr.splitlines() if "ETA" in line]  # one line a run, never wrapped
    assert len(progress) == 15 and all(line.startswith("[") and line.endswith(" s)") for line in progress)
    df = pd.read_csv(out / "summary.csv")
    assert len(df) == 15 and set(df.status) == {"completed"}
    pq = pd.read_parquet(out / "summary.parquet")
    assert list(pq.columns) == list(df.columns)
    for col in [
        "run_id",
        "status",
        "speed",
        "terrain.height",
        "peak_wheel1_force_y",
        "peak_wheel5_force_y",
        "peak_wheel5_force_y_time",
        "peak_ground_force_y",
        "peak_ground_force_y_time",
        "peak_link_tension",
        "peak_chassis_ay",
        "min_chassis_ay",
        "min_chassis_vx",
        "min_chassis_vx_time",
        "first_compression_time",
        "max_energy_balance_error",
        "steps",
        "wall_time",
    ]:
        assert col in df.columns, col
    assert sorted(set(df.speed)) == [5.0, 7.5, 10.0, 12.5, 15.0]
    assert (df.peak_ground_force_y > 1e5).all() and (df.steps > 0).all()
    # a faster vehicle hits harder, at every height (first impact lies within 0.05 s)
    piv = df.pivot(index="speed", columns="terrain.height", values="peak_ground_force_y")
    assert (piv.loc[15.0] > piv.loc[5.0]).all()
    assert (out / "study.toml").exists() and not list(out.rglob(".*.tmp*"))
    for rid in df.run_id:
        rec = json.loads((out / "runs" / rid / "run.json").read_text())
        assert rec["status"] == "completed" and rec["run_id"] == rid and rec["model_version"]
        assert rec["scenario"]["duration"] == 0.05
        ds = xr.load_dataset(out / "runs" / rid / "timeseries.nc")
        assert float(ds.peak_ground_force_y) == pytest.approx(
            df.set_index("run_id").loc[rid, "peak_ground_force_y"]
        )
        assert json.loads(ds.attrs["scenario"])["speed"] == rec["params"]["speed"]


def test_resume_skips_completed_runs_and_leaves_them_untouched(sweep):
    d, _, snap, second = sweep
    assert second.returncode == 0, second.stderr
    assert "0 run now, 15 already completed" in second.stdout
    assert files(d / "results" / "speed_sweep" / "runs") == snap


def test_status_and_summary_commands(sweep):
    d = sweep[0]
    r = cli(["study", "status", "speed_sweep.toml"], d)
    assert r.returncode == 0 and "15 runs: 15 done, 0 failed, 0 pending" in r.stdout
    r = cli(["study", "summary", "speed_sweep.toml"], d)
    assert r.returncode == 0 and r.stdout.count("completed") == 15 and "ground kN" in r.stdout


def test_open_study_and_dataset(sweep):
    d = sweep[0]
    df = tb.open_study(d / "speed_sweep.toml")  # relative output: resolved against the cwd
    assert (df.status == "pending").all()  # the test's cwd is not the study's
    df = tb.open_study(d / "results" / "speed_sweep")
    assert len(df) == 15 and (df.status == "completed").all()
    ds = tb.open_study(d / "results" / "speed_sweep", run=df.run_id[3][:6])
    assert float(ds.peak_ground_force_y) == pytest.approx(df.peak_ground_force_y[3])
    ds.close()
    big = tb.open_study_dataset(d / "results" / "speed_sweep")
    assert big.sizes["run"] == 15 and big.chassis_y.chunks is not None  # lazy (dask)
    assert list(big.run.values) == list(df.run_id)
    assert np.allclose(big.speed.values, df.speed.values)
    assert float(big.peak_ground_force_y.max()) == pytest.approx(df.peak_ground_force_y.max())
    big.close()


def test_force_reruns_everything(tmp_path):
    p = tmp_path / "f.toml"
    p.write_text(f"[study]\nname = 'f'\n[scenario]\n{FAST}[grid]\nspeed = [6.0, 9.0]\n")
    assert cli(["study", "run", str(p), "--workers", "1"], tmp_path).returncode == 0
    before = files(tmp_path / "results" / "f" / "runs")
    r = cli(["study", "run", str(p), "--workers", "1", "--force"], tmp_path)
    assert r.returncode == 0 and "2 run now, 0 already completed" in r.stdout
    after = files(tmp_path / "results" / "f" / "runs")
    assert set(after) == set(before) and all(after[k] != before[k] for k in after)


def test_runs_of_an_edited_grid_are_kept_and_said(tmp_path):
    """A grid edited (or a new model version: run ids include it) leaves run folders that belong
    to no run of the study: kept, not in the summary, and the report says how many."""
    from trackbench.study.execute.runner import report

    p = tmp_path / "g.toml"
    p.write_text(f"[study]\nname = 'g'\n[scenario]\n{FAST}[grid]\nspeed = [6.0, 9.0]\n")
    first = run_study(p, workers=1, output=tmp_path / "out", quiet=True)
    assert first.others == 0 and "other run folder" not in report(first)
    p.write_text(f"[study]\nname = 'g'\n[scenario]\n{FAST}[grid]\nspeed = [9.0]\n")
    second = run_study(p, workers=1, output=tmp_path / "out", quiet=True)
    assert second.skipped == 1 and second.others == 1 and len(second.summary) == 1
    assert "study g: 1 run, 0 run now, 1 already completed" in report(second)
    assert (
        "1 other run folder in " in report(second) and len(list((tmp_path / "out" / "runs").iterdir())) == 2
    )
    r = cli(["study", "status", str(tmp_path / "out")], tmp_path)
    assert (
        r.returncode == 0
        and "study g: 1 run: 1 done, 0 failed, 0 pending" in r.stdout
        and "1 other run folder kept" in r.stdout
    )


def test_failed_run_is_isolated_and_reported(tmp_path):
    p = tmp_path / "fail.toml"
    p.write_text(
        f"[study]\nname = 'fail'\n[scenario]\n{FAST}"
        "[[runs]]\nspeed = 5.0\n[[runs]]\nspeed = 6.0\nmax_steps = 10\n[[runs]]\nspeed = 7.0\n"
    )
    r = cli(["study", "run", str(p)], tmp_path)
    assert r.returncode == 1
    assert "1 of 3 runs failed" in r.stderr
    df = pd.read_csv(tmp_path / "results" / "fail" / "summary.csv")
    assert list(df.status) == ["completed", "failed", "completed"]
    assert "maximum number of steps" in df.status_message[1]
    rec = json.loads((tmp_path / "results" / "fail" / "runs" / df.run_id[1] / "run.json").read_text())
    assert rec["status"] == "failed" and "maximum number of steps" in rec["status_message"]
    s = cli(["study", "status", str(p)], tmp_path)
    assert "2 done, 1 failed, 0 pending" in s.stdout and "maximum number of steps" in s.stdout


def test_kill_9_mid_study_then_resume(tmp_path):
    p = tmp_path / "k.toml"
    p.write_text(
        "[study]\nname = 'k'\n[scenario]\nduration = 0.3\nrecord = { enabled = false }\n"
        "[grid]\nspeed = { start = 5.0, stop = 12.0, step = 1.0 }\n"
    )
    out = tmp_path / "results" / "k"
    proc = subprocess.Popen(
        CLI + ["study", "run", str(p), "--workers", "1"],
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    deadline = time.time() + 120
    while time.time() < deadline and len(list(out.glob("runs/*/run.json"))) < 2:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)  # the whole study: the command and its workers
    proc.wait()
    done = [q.parent.name for q in out.glob("runs/*/run.json")]
    assert 2 <= len(done) < 8, "the study must be killed part-way"
    # nothing that looks complete is broken: every run.json parses, every timeseries.nc opens
    for q in out.glob("runs/*/run.json"):
        assert json.loads(q.read_text())["status"] == "completed"
    for q in out.glob("runs/*/timeseries.nc"):
        xr.load_dataset(q)
    kept = {k: v for k, v in files(out / "runs").items() if k.split("/")[0] in done}
    r = cli(["study", "run", str(p), "--workers", "1"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert f"{8 - len(done)} run now, {len(done)} already completed" in r.stdout
    after = files(out / "runs")
    assert {k: after[k] for k in kept} == kept  # completed runs untouched
    assert not list(out.rglob(".*.tmp*"))  # leftovers of the killed run cleaned
    df = pd.read_csv(out / "summary.csv")
    assert len(df) == 8 and (df.status == "completed").all()


def test_second_study_run_on_the_same_folder_exits_clearly(tmp_path):
    p = tmp_path / "l.toml"
    p.write_text(f"[study]\nname = 'l'\n[scenario]\n{FAST}")
    out = tmp_path / "results" / "l"
    with store.study_lock(out):
        r = cli(["study", "run", str(p)], tmp_path)
        with pytest.raises(StudyLocked):
            run_study(p, output=out, quiet=True)
    assert r.returncode == 3
    assert "is in use by another `trackbench study run` (pid" in r.stderr
    assert not (out / "runs").exists()
    with store.study_lock(out):  # released when the holder is done
        pass


def test_dask_local_cluster(tmp_path):
    pytest.importorskip("dask.distributed")
    p = tmp_path / "d.toml"
    p.write_text(
        f"[study]\nname = 'd'\noutput = 'dd'\n[scenario]\n{FAST}"
        "[[runs]]\nspeed = 5.0\n[[runs]]\nspeed = 6.0\nmax_steps = 10\n[[runs]]\nspeed = 7.0\n"
    )
    o = run_study(p, workers=2, executor="dask", output=tmp_path / "dd", quiet=True)
    assert list(o.summary.status) == ["completed", "failed", "completed"] and o.failed_total == 1
    recs = [store.read_run(tmp_path / "dd", rid) for rid in o.summary.run_id]
    assert all(r["pid"] != os.getpid() for r in recs)
    assert (tmp_path / "dd" / "summary.csv").exists()


def test_replicates_statistics_and_flags(tmp_path):
    """Fabricated run.json records: median/min/max and the 5 % spread flag."""
    p = tmp_path / "r.toml"
    p.write_text(f"[study]\nname = 'r'\nreplicates = 3\n[scenario]\n{FAST}[grid]\nspeed = [5.0, 6.0]\n")
    s = load_study(p, output=tmp_path / "r")
    assert [r.scenario["seed"] for r in s.runs] == [1, 2, 3, 1, 2, 3]
    for r in s.runs:
        ground = 1000.0 * (1 + (0.1 if r.variant == 0 else 0.01) * r.replicate)
        res = {
            "peak_ground_force_y": ground,
            "peak_link_tension": 50.0,
            "peak_chassis_ay": 2.0,
            "min_chassis_ay": -3.0,
            "min_chassis_vx": 5.0,
        }
        res.update({f"peak_wheel{w}_force_y": 10.0 for w in range(1, 6)})
        store.write_json(
            store.run_dir(s.output, r.run_id) / "run.json",
            {"run_id": r.run_id, "status": "completed", "results": res},
        )
    df, rep = write_summary(s)
    assert len(df) == 6 and list(rep.speed) == [5.0, 6.0]
    assert rep.peak_ground_force_y_median.tolist() == [1100.0, 1010.0]
    assert rep.peak_ground_force_y_min.tolist() == [1000.0, 1000.0]
    assert rep.peak_ground_force_y_max.tolist() == [1200.0, 1020.0]
    assert rep.sensitive.tolist() == ["peak_ground_force_y", ""]
    assert (tmp_path / "r" / "replicates.csv").exists() and (tmp_path / "r" / "replicates.parquet").exists()


def test_replicates_run_with_distinct_perturbed_starts(tmp_path):
    p = tmp_path / "rr.toml"
    p.write_text(f"[study]\nname = 'rr'\nreplicates = 2\n[scenario]\n{FAST}")
    o = run_study(p, workers=2, output=tmp_path / "rr", quiet=True)
    assert list(o.summary.status) == ["completed", "completed"] and len(o.replicates) == 1
    y = [
        xr.load_dataset(store.run_dir(tmp_path / "rr", rid) / "timeseries.nc").pin_y[0].values
        for rid in o.summary.run_id
    ]
    assert 0 < np.abs(y[0] - y[1]).max() < 1e-8  # the 1e-9 m nudge, seeded differently


def test_open_study_dataset_aligns_different_durations(tmp_path, monkeypatch):
    p = tmp_path / "a.toml"
    p.write_text(
        "[study]\nname = 'a'\n[scenario]\noutput_interval = 0.001\nrecord = { enabled = false }\n"
        "[[runs]]\nduration = 0.03\n[[runs]]\nduration = 0.05\n"
    )
    run_study(p, workers=2, output=tmp_path / "a", quiet=True)
    ds = tb.open_study_dataset(tmp_path / "a")
    assert ds.sizes["run"] == 2 and ds.sizes["time"] == 51
    cy = ds.chassis_y.load()
    assert np.isnan(cy[0, -5:]).all() and not np.isnan(cy[1]).any() and not np.isnan(cy[0, :31]).any()
    assert list(ds.duration.values) == [0.03, 0.05]
    # without dask (the README's plain install) the same dataset, read into memory
    from trackbench.study.read import opening

    monkeypatch.setattr(opening, "_have_dask", lambda: False)
    eager = tb.open_study_dataset(tmp_path / "a")
    assert eager.chunks == {} and eager.identical(ds.load())
    ds.close()
    # the folder is read from its runs.json, not by expanding study.toml again (defaults may change)
    (tmp_path / "a" / "study.toml").write_text("[scenario]\nduration = 0.07\n")
    df = tb.open_study(tmp_path / "a")
    assert list(df.status) == ["completed", "completed"] and list(df.duration) == [0.03, 0.05]


def test_recording_failure_is_noted_not_fatal(tmp_path, monkeypatch):
    """A recording writer that raises: the run completes and run.json says why."""
    import types

    from trackbench.study.execute.executors import execute_run

    mod = types.ModuleType("trackbench.outputs.recording.record")

    def boom(ds, path, every=1, signal_every=1):
        Path(path).write_text("partial")
        raise RuntimeError("disk full")

    mod.write_recording = boom
    monkeypatch.setitem(sys.modules, "trackbench.outputs.recording.record", mod)
    s = load_study(
        _write(tmp_path, "[scenario]\nduration = 0.02\noutput_interval = 0.001\n"), output=tmp_path / "o"
    )
    run = s.runs[0]
    store.write_json(s.output / "runs.json", {})  # a worker writes only into an existing study folder
    task = {"run_id": run.run_id, "output": str(s.output), "scenario": run.scenario, "meta": {}}
    rec = execute_run(task)
    assert (
        rec["status"] == "completed" and "recording failed: RuntimeError: disk full" in rec["recording_error"]
    )
    assert sorted(os.listdir(store.run_dir(s.output, run.run_id))) == ["run.json", "timeseries.nc"]

    def ok(ds, path, every=1, signal_every=1):
        Path(path).write_text(f"rrd every={every}")

    mod.write_recording = ok
    rec = execute_run(task)
    assert rec["recording"] == "recording.rrd" and "recording_error" not in rec
    every = run.scenario["record"]["every"]
    assert (store.run_dir(s.output, run.run_id) / "recording.rrd").read_text() == f"rrd every={every}"


def _write(tmp_path, text):
    p = tmp_path / "x.toml"
    p.write_text(text)
    return p


def test_progress_is_a_live_bar_on_a_terminal_and_one_line_per_run_otherwise():
    import io

    from trackbench.study.execute.progress import StudyProgress

    runs = [
        {"run_id": "a1", "status": "completed"},
        {"run_id": "b2", "status": "failed", "status_message": "NaN " + "x" * 200},
        {"run_id": "c3", "status": "completed"},
    ]
    log = io.StringIO()
    p = StudyProgress(3, 1, stream=log, workers=2)
    for r in runs:
        p.update(r)
    p.close()
    lines = log.getvalue().splitlines()
    assert (
        lines[0] == "3 runs to do, 1 already completed" and len(lines) == 4 and "\x1b" not in log.getvalue()
    )
    assert lines[2].startswith("[2/3] b2 failed: NaN xxx") and lines[2].endswith(
        "(done 1  failed 1  running 1  of 3, ETA 0 s)"
    )
    term = io.StringIO()
    p = StudyProgress(3, 0, stream=term, workers=2, terminal=True)
    p.running(2)
    p.update(runs[0])
    p.close()
    out = term.getvalue()
    assert (
        "\x1b" in out and "done 1  failed 0  running 2  of 3" in out and "ETA" in out and "[1/3]" not in out
    )


def test_progress_says_when_the_workers_waited_for_the_compiler(tmp_path):
    """The fork server compiles the study's model once for all workers and says so in a flag
    file: a terminal's bar shows it while it lasts, a log says how long the first run waited,
    and the ETA does not count that wait once per run."""
    import io
    import json

    from trackbench.study.execute.progress import StudyProgress

    flag = tmp_path / "flag.json"
    flag.write_text(json.dumps({"compiling": True, "seconds": 0.0}))
    term = io.StringIO()
    p = StudyProgress(3, 0, stream=term, workers=2, terminal=True, flag=flag)
    p.bar.refresh()
    assert "compiling the model" in re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]", "", term.getvalue())
    p.close()
    flag.write_text(json.dumps({"compiling": False, "seconds": 3600.0}))
    log = io.StringIO()
    p = StudyProgress(3, 0, stream=log, workers=2, flag=flag)
    p.update({"run_id": "a1", "status": "completed"})
    lines = log.getvalue().splitlines()
    assert lines[1].startswith("(the workers waited 3600 s for the model to compile")
    assert lines[2].endswith("ETA 0 s)")  # not 7200 s: the hour of compiling is not per run


def test_one_warm_scenario_per_kind_of_compiled_model():
    from trackbench.warm.protocol import warm_kinds

    paper = tb.Scenario.paper().to_dict()
    runs = [
        paper,
        {**paper, "speed": 5.0},
        tb.Scenario.paper(**{"terrain.soil": "lete_sand"}).to_dict(),
        tb.Scenario.paper(**{"track.layout": "closed"}).to_dict(),
        tb.Scenario.paper(method="dop853").to_dict(),
    ]
    kinds = warm_kinds(runs)
    assert [(k["track"]["layout"], k["method"]) for k in kinds] == [
        ("paper", "dopri5"),
        ("closed", "dopri5"),
        ("paper", "dop853"),
    ]


def test_workers_are_forks_of_a_single_threaded_preloaded_server():
    """The pool's workers come from the fork server: the kernels already loaded there, which had
    one thread when it forked (trackbench/study/preload.py says why that makes forking safe)."""
    from trackbench.warm.forkserver import ForkServerPools
    from trackbench.warm.preload import facts

    pool = ForkServerPools().pool(2)
    try:
        got = [f.result(timeout=300) for f in [pool.submit(facts) for _ in range(2)]]
    finally:
        pool.shutdown()
    assert all(
        g["threads_at_fork"] == 1 and g["loop_signatures"] >= 1 and g["pid"] != os.getpid() for g in got
    )


WARM_LATER = """
import json, sys
from trackbench.warm.forkserver import ForkServerPools, start_workers
from trackbench.warm.preload import facts
from trackbench.warm.protocol import LATER, announce, forget
start_workers(warm=LATER)
announce(json.loads(sys.argv[1]))
pool = ForkServerPools().pool(1)
print(json.dumps(pool.submit(facts).result(timeout=300)))
pool.shutdown()
forget()
"""


@pytest.mark.parametrize("announced", [[], [{"speed": 5.0}]])
def test_the_server_warms_what_the_command_announces_after_it_started(announced):
    """`study run` starts the workers' server before it reads the study file and announces the
    kinds of model later: the server waits for that, and loads those kinds only (nothing for
    []); its workers never load dask's arrays."""
    out = subprocess.run([sys.executable, "-c", WARM_LATER, json.dumps(announced)], capture_output=True,
                         text=True, check=True, timeout=600)
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert (got["loop_signatures"] >= 1) == bool(announced)
    assert got["threads_at_fork"] == 1 and not got["dask_arrays"]


STOPPED = """
import json
from trackbench.warm.forkserver import ForkServerPools, start_workers, stop_server
from trackbench.warm.preload import facts
from trackbench.warm.protocol import LATER
start_workers(warm=LATER)
stop_server()   # bad input found after the start: nothing will be announced
pool = ForkServerPools().pool(1)
print(json.dumps(pool.submit(facts).result(timeout=60)))
pool.shutdown()
"""


def test_a_server_started_again_after_a_stop_does_not_wait_for_an_announcement():
    """A long-lived process (a notebook, tests) whose command stopped the server before
    announcing anything gets a server that warms the paper's model when it starts again."""
    out = subprocess.run([sys.executable, "-c", STOPPED], capture_output=True, text=True, check=True,
                         timeout=100)
    assert json.loads(out.stdout.strip().splitlines()[-1])["loop_signatures"] >= 1
