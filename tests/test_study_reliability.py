"""Studies on unreliable ground: dask workers started elsewhere or seeing another file system,
a worker process killed mid-run, a full disk, results a worker claims but the folder lacks."""

import errno
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections import namedtuple
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from trackbench.outputs.files import netcdf
from trackbench.study import load_study, run_study, store
from trackbench.study.execute import executors
from trackbench.study.execute.runner import confirm

REPO = Path(__file__).resolve().parents[1]
CLI = [sys.executable, "-c", "from trackbench.cli import main; main()"]
FAST = "duration = 0.02\noutput_interval = 0.001\nrecord = { enabled = false }\n"
ENV = {**os.environ, "PYTHONPATH": str(REPO), "NUMBA_CACHE_DIR": os.environ.get("NUMBA_CACHE_DIR", "")}
if not ENV["NUMBA_CACHE_DIR"]:
    del ENV["NUMBA_CACHE_DIR"]
DASK = str(Path(sys.executable).parent / "dask")


def write_study(folder, name, speeds=(5.0, 6.0, 7.0), scenario=FAST):
    folder.mkdir(parents=True, exist_ok=True)
    p = folder / f"{name}.toml"
    p.write_text(f"[study]\nname = '{name}'\n[scenario]\n{scenario}[grid]\nspeed = {list(speeds)}\n")
    return p


def cli(args, cwd, timeout=300):
    return subprocess.run(CLI + args, cwd=cwd, env=ENV, capture_output=True, text=True, timeout=timeout)


def _unshare_works():
    try:
        r = subprocess.run(
            ["unshare", "-rmu", "sh", "-c", "hostname x && mount -t tmpfs tmpfs /mnt"],
            capture_output=True,
            timeout=10,
        )
        return r.returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


needs_unshare = pytest.mark.skipif(
    shutil.which("unshare") is None or not _unshare_works(),
    reason="needs unshare (user + mount + uts namespaces) to fake another node",
)


def _stop(procs):
    for p in reversed(procs):
        try:
            os.killpg(p.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
    for p in reversed(procs):
        try:
            p.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(timeout=15)


@contextmanager
def dask_cluster(cwd, workers):
    """A `dask scheduler` and the given `dask worker` commands (argument prefixes, e.g. an
    unshare wrapper), all started in ``cwd`` on 127.0.0.1; yields the scheduler address."""
    from dask.distributed import Client

    cwd.mkdir(parents=True, exist_ok=True)
    sched = cwd / "scheduler.json"
    procs = []
    log = open(cwd / "dask.log", "w")
    try:
        procs.append(
            subprocess.Popen(
                [
                    DASK,
                    "scheduler",
                    "--host",
                    "127.0.0.1",
                    "--port",
                    "0",
                    "--no-dashboard",
                    "--scheduler-file",
                    str(sched),
                ],
                cwd=cwd,
                env=ENV,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        )
        deadline = time.time() + 60
        while not sched.exists() and time.time() < deadline:
            time.sleep(0.1)
        address = json.loads(sched.read_text())["address"]
        for i, prefix in enumerate(workers):
            procs.append(
                subprocess.Popen(
                    prefix
                    + [
                        DASK,
                        "worker",
                        address,
                        "--nworkers",
                        "1",
                        "--nthreads",
                        "1",
                        "--host",
                        "127.0.0.1",
                        "--no-dashboard",
                        "--name",
                        f"w{i}",
                    ],
                    cwd=cwd,
                    env=ENV,
                    stdout=log,
                    stderr=subprocess.STDOUT,
                    start_new_session=True,
                )
            )
        with Client(address, timeout="30s") as c:
            c.wait_for_workers(len(workers), timeout=120)
        yield address
    finally:
        _stop(procs)
        log.close()


# --- 1. dask workers in another working directory / on "another node" -------------------


def test_dask_workers_started_elsewhere_write_into_the_study_folder(tmp_path):
    """A relative results folder, workers started in another directory."""
    pytest.importorskip("dask.distributed")
    here, elsewhere = tmp_path / "study", tmp_path / "elsewhere"
    write_study(here, "dk")
    with dask_cluster(elsewhere, [[], []]) as address:
        r = cli(["study", "run", "dk.toml", "--executor", "dask", "--scheduler", address], here)
    assert r.returncode == 0, r.stderr
    assert "3 runs, 3 run now, 0 already completed, 0 failed;" in r.stdout
    out = here / "results" / "dk"
    df = pd.read_csv(out / "summary.csv")
    assert list(df.status) == ["completed"] * 3
    pids = set()
    for rid in df.run_id:
        rec = json.loads((out / "runs" / rid / "run.json").read_text())
        assert rec["status"] == "completed"
        xr.load_dataset(out / "runs" / rid / "timeseries.nc")
        pids.add(rec["pid"])
    assert not (elsewhere / "results").exists()  # nothing landed in the workers' directory
    assert len(pids) >= 1


@needs_unshare
@pytest.mark.parametrize("view", ["absent", "stale copy"])
def test_dask_worker_on_a_node_without_the_folder_fails_the_runs_and_the_command(tmp_path, view):
    """A worker that sees another file system at the study's path (a node without the shared
    folder: here a mount namespace with its own tmpfs and host name). "absent": the path does
    not exist there; "stale copy": a folder that looks like the study's (runs.json) but is not
    shared, so the worker writes its results where the coordinator cannot see them."""
    pytest.importorskip("dask.distributed")
    here, elsewhere = tmp_path / "study", tmp_path / "elsewhere"
    write_study(here, "nf")
    out = here / "results" / "nf"
    out.mkdir(parents=True)
    if view == "absent":
        setup = f"mount -t tmpfs tmpfs {here}"
    else:
        (tmp_path / "stale.json").write_text("{}")
        setup = f"mount -t tmpfs tmpfs {out} && cp {tmp_path / 'stale.json'} {out}/runs.json"
    node = ["unshare", "-rmu", "sh", "-c", f'hostname other-node && {setup} && exec "$0" "$@"']
    with dask_cluster(elsewhere, [node]) as address:
        r = cli(["study", "run", "nf.toml", "--executor", "dask", "--scheduler", address], here)
    assert r.returncode == 1, r.stdout + r.stderr
    # "0 failed" as a count (a run id may end in 0 before its "failed" status)
    assert "3 of 3 runs failed" in r.stderr and not re.search(r"(^|[^0-9a-f])0 failed", r.stdout)
    df = pd.read_csv(out / "summary.csv")
    assert list(df.status) == ["failed"] * 3
    for msg in df.status_message:
        assert "other-node" in msg and "shared file system" in msg
        if view == "absent":
            assert f"the study folder {out} does not exist on worker host other-node" in msg
        else:
            assert "reported the run completed, but" in msg and "run.json is missing" in msg
    assert not list(out.glob("runs/*/timeseries.nc"))


def test_worker_reasons_name_the_folder_and_the_host(tmp_path):
    s = load_study(write_study(tmp_path, "w", speeds=(5.0,)), output=tmp_path / "w")
    run = s.runs[0]
    host = executors.socket.gethostname()
    for output, expect in [
        ("results/w", "is not an absolute path"),
        (str(tmp_path / "nowhere"), f"{tmp_path / 'nowhere'} does not exist on worker host {host}"),
    ]:
        rec = executors.execute_run(
            {"run_id": run.run_id, "output": output, "scenario": run.scenario, "meta": {}}
        )
        assert rec["status"] == "failed" and expect in rec["status_message"], rec["status_message"]
    assert not (tmp_path / "nowhere").exists() and not Path("results/w").exists()


def test_coordinator_rejects_a_completed_run_whose_netcdf_does_not_open(tmp_path):
    s = load_study(write_study(tmp_path, "c", speeds=(5.0,)), output=tmp_path / "c")
    store.write_json(s.output / "runs.json", {})
    run = s.runs[0]
    task = {
        "run_id": run.run_id,
        "output": str(s.output),
        "scenario": run.scenario,
        "meta": {},
        "attempt_id": "a1",
    }
    rec = executors.execute_run(task)
    assert confirm(task, rec) is rec and rec["status"] == "completed"
    nc = store.run_dir(s.output, run.run_id) / "timeseries.nc"
    nc.write_bytes(nc.read_bytes()[:1000])  # truncated behind the worker's back
    got = confirm(task, rec)
    assert got["status"] == "failed" and f"{nc} cannot be read" in got["status_message"]
    assert store.read_run(s.output, run.run_id)["status"] == "failed" and not nc.exists()
    # a run.json of an earlier try (another attempt_id) is not this try's result
    rec = executors.execute_run({**task, "attempt_id": "a2"})
    got = confirm({**task, "attempt_id": "a3"}, {**rec, "attempt_id": "a3"})
    assert got["status"] == "failed" and "is not the record it wrote" in got["status_message"]


# --- 3. a worker process killed mid-run ----------------------------------------------------

LONG = "duration = 0.5\noutput_interval = 0.001\nrecord = { enabled = false }\n"


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """4 runs of 0.5 s on an undisturbed process pool: the results a disturbed study must equal."""
    d = tmp_path_factory.mktemp("ref")
    p = write_study(d, "kw", speeds=(5.0, 6.0, 7.0, 8.0), scenario=LONG)
    o = run_study(p, workers=2, output=d / "ref", quiet=True)
    assert o.problem() is None
    return p, d / "ref", o


def _in_thread(fn):
    """Start fn in a thread; returns (thread, result dict, event set when fn has returned)."""
    stop, result = threading.Event(), {}

    def body():
        try:
            result["outcome"] = fn()
        except BaseException as e:  # surfaced by the test
            result["error"] = e
        finally:
            stop.set()

    th = threading.Thread(target=body)
    th.start()
    return th, result, stop


def _same_as_reference(o, out, reference):
    """Every run once, completed, its arrays and numbers bit for bit those of the reference."""
    _, ref_out, ref = reference
    assert o.problem() is None and o.ran == 4 and o.failed == []
    assert list(o.summary.run_id) == list(ref.summary.run_id) and o.summary.run_id.is_unique
    recs = [store.read_run(out, rid) for rid in o.summary.run_id]
    assert all(r["status"] == "completed" for r in recs)
    assert not list(out.rglob(".*.tmp*"))  # no half-written file of a killed try is left
    for rid, rec in zip(o.summary.run_id, recs):
        a = xr.load_dataset(store.run_dir(out, rid) / "timeseries.nc")
        b = xr.load_dataset(store.run_dir(ref_out, rid) / "timeseries.nc")
        assert set(a.data_vars) == set(b.data_vars)
        for v in a.data_vars:
            assert np.array_equal(a[v].values, b[v].values, equal_nan=True), (rid, v)
        assert rec["results"] == store.read_run(ref_out, rid)["results"]
    return recs


def test_killed_pool_worker_run_retried_once_counted_bit_for_bit(tmp_path, reference):
    """Once a run has started (its folder exists, no run.json yet), SIGKILL a pool worker."""
    import multiprocessing

    out = tmp_path / "killed"
    th, result, stop = _in_thread(lambda: run_study(reference[0], workers=2, output=out, quiet=True))
    killed = None
    while killed is None and not stop.is_set():
        started = [d for d in out.glob("runs/*") if not (d / "run.json").exists()]
        kids = multiprocessing.active_children()
        if started and kids:
            os.kill(kids[0].pid, signal.SIGKILL)
            killed = kids[0].pid
        time.sleep(0.002)
    th.join(timeout=300)
    assert not th.is_alive() and "error" not in result, result.get("error")
    assert killed is not None
    recs = _same_as_reference(result["outcome"], out, reference)
    assert max(r["attempt"] for r in recs) == 2  # the kill hit runs in flight; they ran again once


def test_killed_dask_worker_run_rescheduled_once_counted_bit_for_bit(tmp_path, reference):
    """A real scheduler with two workers; SIGKILL the worker process that is running a run."""
    pytest.importorskip("dask.distributed")
    from dask.distributed import Client

    out = tmp_path / "killed"
    with dask_cluster(tmp_path / "elsewhere", [[], []]) as address, Client(address, timeout="30s") as c:
        pids = c.run(os.getpid)
        th, result, stop = _in_thread(
            lambda: run_study(reference[0], executor="dask", scheduler=address, output=out, quiet=True)
        )
        killed, deadline = None, time.time() + 120
        while killed is None and not stop.is_set() and time.time() < deadline:
            for w, keys in c.processing().items():
                rids = [str(k).removeprefix("trackbench-run-") for k in keys]
                mid_run = [
                    r
                    for r in rids
                    if (out / "runs" / r).is_dir() and not (out / "runs" / r / "run.json").exists()
                ]
                if mid_run:
                    os.kill(pids[w], signal.SIGKILL)
                    killed = (mid_run[0], pids[w])
                    break
            time.sleep(0.002)
        th.join(timeout=300)
    assert not th.is_alive() and "error" not in result, result.get("error")
    assert killed is not None
    _same_as_reference(result["outcome"], out, reference)
    assert store.read_run(out, killed[0])["pid"] != killed[1]  # finished by another process


def test_pool_gives_up_on_a_run_that_keeps_killing_its_worker(monkeypatch):
    """A stand-in pool where one run kills its worker on every try, which (as in
    ProcessPoolExecutor) fails every run in flight with BrokenProcessPool: that run fails after
    MAX_ATTEMPTS tries, reported once; its neighbours are tried again, never beside it twice."""
    from concurrent.futures.process import BrokenProcessPool

    class Fut:
        def __init__(self, pool, task):
            self.pool, self.task = pool, task

        def done(self):
            return True

        def cancelled(self):
            return False

        def exception(self):
            return BrokenProcessPool("terminated abruptly") if self.pool.broken else None

        def result(self):
            return {"run_id": self.task["run_id"], "status": "completed", "attempt": self.task["attempt"]}

    class Pool:
        broken = False

        def submit(self, fn, task):
            if self.broken:
                raise BrokenProcessPool("broken")
            self.broken = self.broken or task["run_id"] == "r1"
            return Fut(self, task)

        def shutdown(self, wait=True, cancel_futures=False):
            pass

    class Pools(executors.PoolFactory):
        def pool(self, workers):
            return Pool()

    monkeypatch.setattr(executors, "wait", lambda futs, return_when: None)
    notes = []
    tasks = [{"run_id": f"r{i}", "meta": {}, "scenario": {}} for i in range(4)]
    got = list(executors.run_local(tasks, workers=2, notify=notes.append, pools=Pools()))
    assert sorted(t["run_id"] for t, _ in got) == ["r0", "r1", "r2", "r3"]  # each once
    rec = {t["run_id"]: r for t, r in got}
    assert rec["r1"]["status"] == "failed" and rec["r1"]["attempt"] == executors.MAX_ATTEMPTS == 3
    assert "died or could not be reached (3 times)" in rec["r1"]["status_message"]
    others = [rec[r] for r in ("r0", "r2", "r3")]
    assert all(r["status"] == "completed" and r["attempt"] <= 2 for r in others)
    assert len(notes) == 2 + sum(r["attempt"] - 1 for r in others) >= 3


# --- 4. disk full and other reasons a user can act on -----------------------------------------


def _serial(tasks, workers=2, notify=None, on_running=None, pools=None):
    """The local executor without its process pool, so that monkeypatches reach the worker code."""
    for t in tasks:
        t = executors._attempt(t, 1)
        yield t, executors.execute_run(t)


def test_injected_enospc_reason_says_disk_full_and_a_rerun_completes_the_rest(tmp_path, monkeypatch):
    p = write_study(tmp_path, "df")
    out = tmp_path / "df"
    real = netcdf.write_netcdf
    victim = load_study(p, output=out).runs[1].run_id

    def write(ds, path, storage="full"):
        if Path(path).parent.name == victim:
            Path(path).with_name(".timeseries.nc.x.tmp").write_bytes(b"half")  # cleaned by the coordinator
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(ds, path, storage)

    monkeypatch.setattr(executors, "run_local", _serial)
    monkeypatch.setattr(netcdf, "write_netcdf", write)
    o = run_study(p, output=out, quiet=True)
    assert list(o.summary.status) == ["completed", "failed", "completed"]
    assert o.problem().startswith("1 of 3 runs failed")
    msg = o.summary.status_message[1]
    assert f"no space left on the device holding {out / 'runs' / victim}" in msg and "MB free" in msg
    rec = store.read_run(out, victim)
    assert rec["exception"] == "OSError: [Errno 28] No space left on device" and rec["status_message"] == msg
    assert sorted(os.listdir(out / "runs" / victim)) == ["run.json"]  # nothing partial
    monkeypatch.undo()
    o = run_study(p, output=out, quiet=True)  # space again: the real pool
    assert o.problem() is None and o.ran == 1 and o.skipped == 2
    assert list(o.summary.status) == ["completed"] * 3


def test_hdf_error_is_called_a_full_disk_only_when_space_is_short(tmp_path, monkeypatch):
    s = load_study(write_study(tmp_path, "h", speeds=(5.0,)), output=tmp_path / "h")
    store.write_json(s.output / "runs.json", {})
    run = s.runs[0]
    task = {"run_id": run.run_id, "output": str(s.output), "scenario": run.scenario, "meta": {}}

    def hdf(ds, path, storage="full"):
        raise RuntimeError("NetCDF: HDF error")

    monkeypatch.setattr(netcdf, "write_netcdf", hdf)
    rec = executors.execute_run(task)  # plenty of space: the error as it is
    assert rec["status_message"] == "RuntimeError: NetCDF: HDF error"
    Usage = namedtuple("Usage", "total used free")
    monkeypatch.setattr(executors.shutil, "disk_usage", lambda p: Usage(10**9, 10**9, 0))
    rec = executors.execute_run(task)
    assert rec["status"] == "failed" and rec["exception"] == "RuntimeError: NetCDF: HDF error"
    rdir = store.run_dir(s.output, run.run_id)
    assert rec["status_message"].startswith(f"no space left on the device holding {rdir}")
    assert "0.00 MB free, the run writes about 0.0" in rec["status_message"]
    assert store.read_run(s.output, run.run_id)["exception"] == "RuntimeError: NetCDF: HDF error"


def test_reasons_for_permission_and_missing_paths():
    host = executors.socket.gethostname()
    r = executors.failure_reason(
        PermissionError(errno.EACCES, "Permission denied", "/data/s/runs/x"), "/data/s"
    )
    assert r.startswith(f"permission denied: /data/s/runs/x (host {host}, uid ")
    r = executors.failure_reason(FileNotFoundError(errno.ENOENT, "No such file", "/data/s"), "/data/s")
    assert r == f"/data/s does not exist on host {host}"
    r = executors.failure_reason(OSError(errno.EROFS, "Read-only file system", "/data/s"), "/data/s")
    assert r == f"read-only file system: /data/s (host {host})"


def test_permission_denied_on_a_full_disk_is_the_full_disk(tmp_path):
    """HDF5 creating a file on a full tmpfs came back as EACCES: in a folder the worker may
    write to, with less room than the run needs, the reason is the disk."""
    exc = PermissionError(errno.EACCES, "Permission denied", str(tmp_path / ".timeseries.nc.x.tmp"))
    free = executors._free_bytes(tmp_path)
    assert executors.failure_reason(exc, tmp_path, need_bytes=free + 2**30).startswith(
        f"no space left on the device holding {tmp_path}"
    )
    assert executors.failure_reason(exc, tmp_path, need_bytes=1000).startswith("permission denied: ")
    assert executors.failure_reason(exc, tmp_path).startswith("permission denied: ")


@needs_unshare
def test_real_full_disk_then_rerun_with_space(tmp_path):
    """A 0.8 MB file system for 4 runs of about 0.32 MB each: the runs that do not fit fail
    saying the disk is full; once the file system is larger, a rerun completes exactly those."""
    scen = "duration = 0.05\nrecord = { enabled = false }\n"
    p = write_study(tmp_path, "full", speeds=(5.0, 6.0, 7.0, 8.0), scenario=scen)
    out, keep = tmp_path / "results" / "full", tmp_path / "kept"
    out.mkdir(parents=True)
    run = f"{sys.executable} -c 'from trackbench.cli import main; main()' study run {p} --workers 2"
    script = (
        f"mount -t tmpfs -o size=800k tmpfs {out} || exit 99; "
        f"{run} > {tmp_path}/1.out 2> {tmp_path}/1.err; echo $? > {tmp_path}/1.rc; "
        f"cp -r {out} {tmp_path}/first; "
        f"mount -o remount,size=20m {out}; "
        f"{run} > {tmp_path}/2.out 2> {tmp_path}/2.err; echo $? > {tmp_path}/2.rc; "
        f"cp -r {out} {keep}"
    )
    r = subprocess.run(
        ["unshare", "-rm", "sh", "-c", script],
        cwd=tmp_path,
        env=ENV,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    rc1, rc2 = (int((tmp_path / f"{i}.rc").read_text()) for i in (1, 2))
    first = pd.read_csv(tmp_path / "first" / "summary.csv")
    bad = first[first.status != "completed"]
    assert rc1 == 1 and 1 <= len(bad) <= 3, (tmp_path / "1.err").read_text()
    assert f"{len(bad)} of 4 runs failed" in (tmp_path / "1.err").read_text()
    for _, row in bad.iterrows():
        assert row.status == "failed" and "no space left on the device holding" in row.status_message
        assert not (tmp_path / "first" / "runs" / row.run_id / "timeseries.nc").exists()
    assert not list((tmp_path / "first").rglob(".*.tmp*"))
    assert rc2 == 0, (tmp_path / "2.err").read_text()
    assert (
        f"{len(bad)} run now, {4 - len(bad)} already completed, 0 failed" in (tmp_path / "2.out").read_text()
    )
    assert list(pd.read_csv(keep / "summary.csv").status) == ["completed"] * 4
