"""Where runs execute: one worker function, a local process pool or dask.distributed.

Worker processes come from a pool factory (PoolFactory): on its own the package spawns
fresh ones; the command line passes the fork server's (trackbench/warm), whose workers
start with the runs' kinds of model loaded.

Tasks and results are plain dicts (picklable, no Scenario objects)."""

import errno
import os
import shutil
import socket
import threading
import time
import traceback
import uuid
from collections import deque
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path

from trackbench.outputs.files import netcdf
from trackbench.outputs.files.storage import frame_step, recording_steps
from trackbench.outputs.quantities import run_summary
from trackbench.study import store


class PoolFactory:
    """Where a study's worker processes come from, and what they may load before its runs
    start. This one, the package's own, spawns fresh processes (each loads what its first
    run needs); the command line passes one that forks them warm (trackbench/warm)."""

    def compile_flag(self):
        """A file whose existence says the workers' models are being compiled, or None."""
        return None

    def prepare(self, scenarios, executor="local", scheduler=None):
        """The first wave's scenarios (dicts) are known: a factory may start loading them."""

    def pool(self, workers):
        import multiprocessing
        return ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))

    def dask_context(self):
        """The start method of a LocalCluster's worker processes."""
        return "spawn"

    def close(self):
        """The study is done: release what prepare() started."""


def _now():
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


def _record(ds, rdir, scenario, storage="full"):
    """Write recording.rrd beside timeseries.nc when asked and possible (thinned for compact
    storage); returns (name, error)."""
    if not scenario.get("record", {}).get("enabled"):
        return None, None
    try:
        from trackbench.outputs.recording.record import write_recording
    except ImportError as e:
        return None, f"recording skipped: trackbench.outputs.recording.record is not available ({e})"
    try:
        target = Path(rdir) / "recording.rrd"
        tmp = store.tmp_path(target) + ".rrd"
        try:   # a writer of its own temporary: whatever happens inside, only a finished file lands
            every = frame_step(scenario["record"], scenario["output_interval"])
            frames, signals = recording_steps(every, storage)
            write_recording(ds, tmp, every=frames, signal_every=signals)
            os.replace(tmp, target)
        finally:
            for p in (tmp, tmp[:-4]):
                if os.path.exists(p):
                    os.remove(p)
        return target.name, None
    except Exception as e:  # a failed recording must not fail the run
        return None, f"recording failed: {type(e).__name__}: {e}"


def execute_run(task):
    """Run one study run in this process and write its folder; returns the run.json dict.

    task: run_id, output (absolute: the study folder as every worker sees it), scenario
    (resolved dict), meta (study, variant, replicate, params), storage ("full" or "compact"),
    attempt, attempt_id.
    Never raises for a failing run: the failure is the record (its reason in status_message,
    the original exception in exception)."""
    t0 = time.perf_counter()
    output = Path(task["output"])
    rdir = store.run_dir(output, task["run_id"])
    rec = {"run_id": task["run_id"], **task["meta"], "status": "failed", "status_message": "",
           "started": _now(), "started_unix": time.time(), "host": socket.gethostname(), "pid": os.getpid(),
           "attempt": task.get("attempt", 1), "attempt_id": task.get("attempt_id")}
    rec["status_message"] = folder_problem(output) or ""
    if rec["status_message"]:
        return _finish(rec, task, t0, rdir=None)
    try:  # runs/<id> only: the study folder itself exists (checked), a worker never creates it
        rdir.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        _fail(rec, e, rdir)
        return _finish(rec, task, t0, rdir=None)
    ds = _simulate(task, rec)
    if ds is not None:
        _write(ds, rdir, task, rec)
    return _finish(rec, task, t0, rdir)


def folder_problem(output):
    """Why this worker cannot use the study folder ``output`` (None when it can): the reason
    names the folder and this host, since a worker elsewhere may not see the coordinator's files."""
    host = socket.gethostname()
    if not output.is_absolute():
        return (f"the study folder {output} is not an absolute path (host {host}): it would be taken "
                "against the worker's working directory")
    if not output.is_dir():
        return (f"the study folder {output} does not exist on worker host {host}: every worker must see "
                "the study folder at the same path (a shared file system)")
    if not (output / "runs.json").is_file():
        return (f"the folder {output} on worker host {host} is not the study's (no runs.json): every worker "
                "must see the study folder at the same path (a shared file system)")
    if not os.access(output, os.W_OK | os.X_OK):
        return (
            f"permission denied: worker host {host} (uid {os.getuid()}) cannot write to the study "
            f"folder {output}"
        )
    return None


def failure_reason(exc, folder, need_bytes=None):
    """A reason a user can act on for ``exc`` raised while working in ``folder``: a full disk
    (with the folder's free space), permission denied, a missing path; else the exception
    itself. netCDF/HDF5 report a full disk as "NetCDF: HDF error" (no errno, or netCDF's own
    negative code): when writing ``need_bytes`` failed that way, free space below that (plus
    1 MiB of slack) is taken as a full disk."""
    host = socket.gethostname()
    err = getattr(exc, "errno", None)
    where = os.fsdecode(getattr(exc, "filename", None) or folder)
    free = _free_bytes(folder)
    full = need_bytes is not None and free is not None and free < need_bytes + 2**20
    # HDF5 creating a file on a full disk can come back as "permission denied": in a folder
    # this process may write to, with no room for the run, the disk is what is wrong
    denied = err in (errno.EACCES, errno.EPERM) and not (full and os.access(folder, os.W_OK | os.X_OK))
    if denied:
        return f"permission denied: {where} (host {host}, uid {os.getuid()})"
    if err == errno.EROFS:
        return f"read-only file system: {where} (host {host})"
    if err == errno.ENOENT:
        return f"{where} does not exist on host {host}"
    if err in (errno.ENOSPC, errno.EDQUOT, errno.EACCES, errno.EPERM) or ((err is None or err < 0) and full):
        size = f", the run writes about {need_bytes / 1e6:.2f} MB" if need_bytes else ""
        room = "free space unknown" if free is None else f"{free / 1e6:.2f} MB free"
        return f"no space left on the device holding {folder} (host {host}): {room}{size}"
    return f"{type(exc).__name__}: {exc}"


def _free_bytes(folder):
    """Free bytes on the file system of ``folder`` (its nearest existing parent), or None."""
    p = Path(folder)
    while not p.exists() and p != p.parent:
        p = p.parent
    try:
        return shutil.disk_usage(p).free
    except OSError:
        return None


def _fail(rec, exc, folder, need_bytes=None):
    """Mark ``rec`` failed by ``exc``: the readable reason, the original exception, the traceback."""
    tb = "".join(traceback.format_exception(exc, limit=8))
    rec.update(status="failed", status_message=failure_reason(exc, folder, need_bytes),
               exception=f"{type(exc).__name__}: {exc}", traceback=tb)


def _simulate(task, rec):
    """The run's Dataset, or None (``rec`` failed) when the scenario or the solver raised."""
    try:
        from trackbench import __version__
        from trackbench.run.simulate import simulate
        from trackbench.scenario import Scenario
        from trackbench.version import MODEL_VERSION
        rec.update(model_version=MODEL_VERSION, trackbench_version=__version__)
        return simulate(Scenario.from_dict({}, base=task["scenario"]))
    except Exception as e:
        rec.update(status="failed", status_message=f"{type(e).__name__}: {e}",
                   exception=f"{type(e).__name__}: {e}", traceback=traceback.format_exc(limit=8))
        return None


def _in_thread(fn, *args):
    """Start fn(*args) in a thread; returns a function that waits for it and returns the
    exception it raised, or None."""
    box = {}

    def body():
        try:
            fn(*args)
        except BaseException as e:  # handed to the caller
            box["exc"] = e
    th = threading.Thread(target=body, name="trackbench-netcdf", daemon=True)
    th.start()

    def join():   # pop: no reference cycle keeps the exception's frames (and an open file) alive
        th.join()
        return box.pop("exc", None)
    return join


def _write(ds, rdir, task, rec):
    """timeseries.nc and the recording of a finished simulation, written at the same time
    (netCDF's writes and compression and rerun's encoding run outside the GIL); the solver's
    verdict in ``rec``. When timeseries.nc cannot be written the run fails and keeps no recording."""
    storage = task.get("storage", "full")
    written = _in_thread(netcdf.write_netcdf, ds, rdir / "timeseries.nc", storage)
    recording, err = _record(ds, rdir, task["scenario"], storage)
    exc = written()
    if exc is not None:
        if recording:
            (rdir / recording).unlink(missing_ok=True)
        if not isinstance(exc, Exception):
            raise exc
        _fail(rec, exc, rdir, need_bytes=ds.nbytes)
        return
    a = ds.attrs
    msg = (
        a["status_message"]
        if a["status"] == "completed"
        else f"{a['status_message']} at t = {a['t_final']:.6g} s"
    )
    rec.update(status=a["status"], status_message=msg, t_final=a["t_final"], steps=a["steps"],
               rejected_steps=a["rejected_steps"], solve_time=a["solve_time"], sim_wall_time=a["wall_time"],
               timeseries="timeseries.nc", storage=storage, results=run_summary(ds), recording=recording,
               timeseries_bytes=(rdir / "timeseries.nc").stat().st_size)   # the coordinator's check
    if err:
        rec["recording_error"] = err


def _finish(rec, task, t0, rdir):
    """Times and scenario into ``rec``; run.json written last (when ``rdir`` is usable). A run
    whose run.json cannot be written is failed, and its timeseries.nc removed: nothing is left
    that looks like a result."""
    rec["finished"] = _now()
    rec["finished_unix"] = time.time()
    rec["wall_time"] = time.perf_counter() - t0
    rec["scenario"] = task["scenario"]
    if rdir is None:
        return rec
    try:
        store.write_json(rdir / "run.json", rec)
    except Exception as e:
        why = failure_reason(e, rdir)
        rec.update(status="failed", status_message=f"run.json could not be written: {why}",
                   exception=f"{type(e).__name__}: {e}")
        try:
            (rdir / "timeseries.nc").unlink(missing_ok=True)
        except OSError:
            pass
    return rec


def crashed(task, exc, tries=None):
    """The record of a run whose worker died or could not be reached (the coordinator writes it)."""
    times = f" ({tries} times)" if tries and tries > 1 else ""
    return {"run_id": task["run_id"], **task["meta"], "status": "failed",
            "status_message": f"the worker process running it died or could not be reached{times}: "
                              f"{type(exc).__name__}: {exc}",
            "exception": f"{type(exc).__name__}: {exc}", "attempt": tries or task.get("attempt", 1),
            "attempt_id": task.get("attempt_id"), "finished": _now(), "scenario": task["scenario"]}


MAX_ATTEMPTS = 3  # tries of a run whose worker process died (dask: allowed-failures + 1)


def _attempt(task, number):
    """The task for try ``number``: a fresh attempt_id lets the coordinator tell this try's
    run.json from an older one (a --force rerun, an earlier try)."""
    return {**task, "attempt": number, "attempt_id": uuid.uuid4().hex}


def _next_task(fresh, retry, running):
    """A run tried before goes beside fresh runs only: a run that kills its worker then cannot
    use up the tries of the runs that happened to run next to it."""
    if retry and not any(t["attempt"] > 1 for t in running.values()):
        return retry.popleft()
    return fresh.popleft() if fresh else None


def run_local(tasks, workers=2, notify=None, on_running=None, pools=None):
    """Yield (task, record) as runs finish, on a process pool of ``pools`` (a PoolFactory).

    No more runs are submitted than there are workers, so the runs in flight are known: a
    worker that dies (killed, out of memory) breaks the pool (BrokenProcessPool); the pool is
    started again and the runs that were in flight are tried again, each at most MAX_ATTEMPTS
    times, and yielded once. ``notify(text)`` hears about the restarts, ``on_running(n)`` how
    many runs are in flight."""
    fresh, retry, running, pool = deque(_attempt(t, 1) for t in tasks), deque(), {}, None
    pools = pools or PoolFactory()
    try:
        while fresh or retry or running:
            pool = pool or pools.pool(workers)
            broken = _fill(pool, fresh, retry, running, workers)
            if on_running:
                on_running(len(running))
            if not broken:
                wait(list(running), return_when=FIRST_COMPLETED)
                broken = any(f.done() and not f.cancelled() and isinstance(f.exception(), BrokenProcessPool)
                             for f in running)
            if broken:  # every future of the pool ends now: shut it down, then sort them
                pool.shutdown(wait=True, cancel_futures=True)
                pool = None
            for fut in [f for f in running if f.done()]:
                task = running.pop(fut)
                if fut.cancelled():  # never started: back in line, no try spent
                    (retry if task["attempt"] > 1 else fresh).appendleft(task)
                    continue
                exc = fut.exception()
                if isinstance(exc, BrokenProcessPool) and task["attempt"] < MAX_ATTEMPTS:
                    retry.append(_attempt(task, task["attempt"] + 1))
                    if notify:
                        notify(f"a worker process died; run {task['run_id']} is tried again "
                               f"(try {task['attempt'] + 1} of {MAX_ATTEMPTS})")
                else:
                    yield task, (crashed(task, exc, task["attempt"]) if exc else fut.result())
    finally:
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)


def _fill(pool, fresh, retry, running, workers):
    """Submit runs up to one per worker; True when the pool turned out to be broken."""
    while len(running) < workers:
        task = _next_task(fresh, retry, running)
        if task is None:
            return False
        try:
            running[pool.submit(execute_run, task)] = task
        except BrokenProcessPool:  # a worker died while idle: the run never started
            (retry if task["attempt"] > 1 else fresh).appendleft(task)
            return True
    return False


@contextmanager
def dask_client(workers=2, scheduler=None, pools=None):
    """A dask.distributed Client: of the scheduler at ``scheduler``, else of a LocalCluster of
    ``workers`` processes (a worker that dies: the scheduler runs its task elsewhere, up to its
    allowed-failures, set to MAX_ATTEMPTS - 1, then the future raises KilledWorker)."""
    import dask
    from dask.distributed import Client, LocalCluster
    cluster = None
    if scheduler:
        try:
            client = Client(scheduler, timeout="20s")
        except (OSError, TimeoutError) as e:
            raise RuntimeError(f"cannot reach the dask scheduler at {scheduler}: {e}") from None
    else:
        method = (pools or PoolFactory()).dask_context()
        with dask.config.set({"distributed.scheduler.allowed-failures": MAX_ATTEMPTS - 1,
                              "distributed.worker.multiprocessing-method": method}):
            cluster = LocalCluster(n_workers=workers, processes=True, threads_per_worker=1,
                                   dashboard_address=None)
        client = Client(cluster)
    try:
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run_dask(tasks, workers=2, scheduler=None, notify=None, client=None):
    """Yield (task, record) as runs finish, on a dask.distributed cluster: ``client``'s, else
    one of dask_client(workers, scheduler) for these tasks. A run whose worker died for good
    is recorded as crashed."""
    if client is None:
        with dask_client(workers, scheduler) as client:
            yield from run_dask(tasks, notify=notify, client=client)
        return
    from dask.distributed import as_completed as dask_completed
    futures = {}
    for t in tasks:
        t = _attempt(t, 1)
        futures[client.submit(execute_run, t, pure=False, key=f"trackbench-run-{t['run_id']}")] = t
    for fut in dask_completed(list(futures)):
        task = futures[fut]
        try:
            yield task, fut.result()
        except Exception as e:
            yield task, crashed(task, e)


def check_arguments(workers, executor, scheduler, storage):
    """Raise ValueError (one line) on a bad worker count, executor or storage; nothing is started."""
    if not isinstance(workers, int) or isinstance(workers, bool) or workers < 1:
        raise ValueError(f"--workers {workers!r} is not allowed: expected an integer >= 1")
    check_executor(executor, scheduler)
    if storage is not None:
        from trackbench.outputs.files.storage import check_storage
        check_storage(storage)


def check_executor(executor, scheduler):
    """Raise ValueError (one line) when the executor cannot be used; nothing is started."""
    if executor not in ("local", "dask"):
        raise ValueError(f"--executor {executor!r} is not allowed: expected local or dask")
    if scheduler and executor != "dask":
        raise ValueError("--scheduler needs --executor dask")
    if executor == "dask":
        try:
            import dask.distributed  # noqa: F401
        except ImportError:
            raise ValueError(
                "--executor dask needs dask.distributed: pip install 'trackbench[dask]'"
            ) from None
