"""Where runs execute: one worker function, a local process pool (spawn) or dask.distributed.

Tasks and results are plain dicts (picklable, no Scenario objects)."""

import math
import os
import socket
import time
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed
from datetime import datetime, timezone
from pathlib import Path

from . import store


def _now():
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


def results_of(ds):
    """The numbers of a run the summary shows (plain floats, SI units)."""
    out = {}
    for w, f, t in zip(ds["wheel"].values, ds["peak_wheel_force_y"].values, ds["peak_wheel_force_y_time"].values):
        out[f"peak_wheel{int(w)}_force_y"] = float(f)
        out[f"peak_wheel{int(w)}_force_y_time"] = float(t)
    for name in ("peak_ground_force_y", "peak_link_tension", "peak_chassis_ay", "min_chassis_ay", "min_chassis_vx"):
        out[name] = float(ds[name])
        out[name + "_time"] = float(ds[name + "_time"])
    for name in ("first_contact_time", "first_compression_time", "max_energy_balance_error", "max_energy_residual"):
        out[name] = float(ds[name])
    return {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in out.items()}


def _record(ds, rdir, scenario):
    """Write recording.rrd beside timeseries.nc when asked and possible; returns (name, error)."""
    if not scenario.get("record", {}).get("enabled"):
        return None, None
    try:
        from ..replay.record import write_recording
    except ImportError as e:
        return None, f"recording skipped: trackbench.replay.record is not available ({e})"
    try:
        target = Path(rdir) / "recording.rrd"
        tmp = store.tmp_path(target) + ".rrd"
        try:
            write_recording(ds, tmp, every=int(scenario["record"].get("every", 1)))
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

    task: run_id, output, scenario (resolved dict), meta (study, variant, replicate, params),
    compress. Never raises for a failing run: the failure is the record."""
    t0 = time.perf_counter()
    rdir = store.run_dir(task["output"], task["run_id"])
    rdir.mkdir(parents=True, exist_ok=True)
    rec = {"run_id": task["run_id"], **task["meta"], "status": "failed", "status_message": "",
           "started": _now(), "started_unix": time.time(), "host": socket.gethostname(), "pid": os.getpid()}
    try:
        from .. import __version__
        from ..output import MODEL_VERSION
        from ..scenario import Scenario
        from ..simulate import simulate
        rec.update(model_version=MODEL_VERSION, trackbench_version=__version__)
        sc = Scenario.from_dict({}, base=task["scenario"])
        ds = simulate(sc)
        store.write_timeseries(ds, rdir / "timeseries.nc", compress=task.get("compress", False))
        a = ds.attrs
        msg = a["status_message"] if a["status"] == "completed" else f"{a['status_message']} at t = {a['t_final']:.6g} s"
        rec.update(status=a["status"], status_message=msg, t_final=a["t_final"], steps=a["steps"],
                   rejected_steps=a["rejected_steps"], solve_time=a["solve_time"], sim_wall_time=a["wall_time"],
                   timeseries="timeseries.nc", results=results_of(ds))
        rec["recording"], err = _record(ds, rdir, task["scenario"])
        if err:
            rec["recording_error"] = err
    except Exception as e:
        rec.update(status="failed", status_message=f"{type(e).__name__}: {e}",
                   traceback=traceback.format_exc(limit=8))
    rec["finished"] = _now()
    rec["finished_unix"] = time.time()
    rec["wall_time"] = time.perf_counter() - t0
    rec["scenario"] = task["scenario"]
    store.write_json(rdir / "run.json", rec)
    return rec


def crashed(task, exc):
    """The record of a run whose worker died or could not be reached; written to run.json."""
    rec = {"run_id": task["run_id"], **task["meta"], "status": "failed",
           "status_message": f"the worker running it died or failed: {type(exc).__name__}: {exc}",
           "finished": _now(), "scenario": task["scenario"]}
    store.write_json(store.run_dir(task["output"], task["run_id"]) / "run.json", rec)
    return rec


def _warm():
    """Pool initializer: import the package, netCDF4 and xarray's backends once per worker,
    load the compiled kernels from the numba cache and set up netCDF and rerun (a 1 ms run
    written to a temporary folder: ~1 s the first time in a process, which would otherwise
    land on the worker's first run)."""
    import netCDF4  # noqa: F401
    import xarray

    import tempfile

    import trackbench
    xarray.backends.list_engines()
    try:  # warming is an optimisation only; a real run reports real errors
        ds = trackbench.simulate(trackbench.Scenario.paper(duration=1e-3, output_interval=1e-3))
        with tempfile.TemporaryDirectory() as tmp:
            store.write_timeseries(ds, Path(tmp) / "warm.nc")
            from ..replay.record import write_recording
            write_recording(ds, Path(tmp) / "warm.rrd")
    except Exception:
        pass


def run_local(tasks, workers=2):
    """Yield (task, record) as runs finish, on a spawn-context process pool."""
    import multiprocessing
    ctx = multiprocessing.get_context("spawn")
    # one BLAS thread per worker: the workers already fill the cores, and idle OpenBLAS
    # threads spin (seen at ~6 % of a core per worker); spawned children inherit this
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_warm) as pool:
        futures = {pool.submit(execute_run, t): t for t in tasks}
        try:
            for fut in as_completed(futures):
                task = futures[fut]
                try:
                    yield task, fut.result()
                except Exception as e:  # BrokenProcessPool, pickling errors
                    yield task, crashed(task, e)
        except BaseException:
            for f in futures:
                f.cancel()
            raise


def run_dask(tasks, workers=2, scheduler=None):
    """Yield (task, record) as runs finish, on a dask.distributed cluster (a LocalCluster of
    ``workers`` processes when no scheduler address is given)."""
    from dask.distributed import Client, LocalCluster
    from dask.distributed import as_completed as dask_completed
    cluster = None
    if scheduler:
        try:
            client = Client(scheduler, timeout="20s")
        except (OSError, TimeoutError) as e:
            raise RuntimeError(f"cannot reach the dask scheduler at {scheduler}: {e}") from None
    else:
        cluster = LocalCluster(n_workers=workers, processes=True, threads_per_worker=1,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        futures = {}
        for t in tasks:
            futures[client.submit(execute_run, t, pure=False, key=f"trackbench-run-{t['run_id']}")] = t
        for fut in dask_completed(list(futures)):
            task = futures[fut]
            try:
                yield task, fut.result()
            except Exception as e:
                yield task, crashed(task, e)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


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
            raise ValueError("--executor dask needs dask.distributed: pip install 'trackbench[dask]'") from None
