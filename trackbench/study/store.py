"""The results folder of a study: layout, atomic writes, the lock.

    <output>/study.toml               resolved copy of the study file
    <output>/runs.json                the expanded runs (id, grid point, resolved scenario)
    <output>/summary.csv (.parquet)   one row per run
    <output>/replicates.csv (.parquet) one row per variant (studies with replicates > 1)
    <output>/.lock                    held by the `study run` working on the folder
    <output>/runs/<run-id>/timeseries.nc, run.json, recording.rrd

Every file is written to a temporary name in its own folder (".<name>.<random>.tmp") and
renamed into place, so a killed process never leaves a file that looks complete.
"""

import fcntl
import json
import os
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

TMP_SUFFIX = ".tmp"


class StudyLocked(RuntimeError):
    """Another process holds the study folder's lock."""


def tmp_path(path):
    """A fresh temporary name beside ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix="." + path.name + ".", suffix=TMP_SUFFIX, dir=path.parent)
    os.close(fd)
    return tmp


def _umask():
    m = os.umask(0)
    os.umask(m)
    return m


@contextmanager
def atomic_path(path):
    """Yield a temporary path; on success rename it onto ``path``, on failure remove it."""
    tmp = tmp_path(path)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file the usual mode
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def write_text(path, text):
    with atomic_path(path) as tmp:
        with open(tmp, "w") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
    return Path(path)


def write_json(path, obj):
    return write_text(path, json.dumps(obj, indent=1, sort_keys=False, default=_json_default) + "\n")


def _json_default(x):
    if hasattr(x, "item"):
        return x.item()
    return str(x)


def write_timeseries(ds, path, compress=False):
    """netCDF, atomically (output.write_netcdf)."""
    from ..output import write_netcdf
    return write_netcdf(ds, path, compress=compress)


def write_table(df, stem):
    """``stem``.csv always, ``stem``.parquet when pyarrow is importable; returns the paths."""
    stem = Path(stem)
    paths = []
    with atomic_path(stem.with_suffix(".csv")) as tmp:
        df.to_csv(tmp, index=False)
    paths.append(stem.with_suffix(".csv"))
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return paths
    with atomic_path(stem.with_suffix(".parquet")) as tmp:
        df.to_parquet(tmp, index=False)
    paths.append(stem.with_suffix(".parquet"))
    return paths


def run_dir(output, rid):
    return Path(output) / "runs" / rid


def read_json(path):
    """A JSON file as a dict, or None when it does not exist (yet)."""
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None


def read_run(output, rid):
    """The run's run.json as a dict, or None when the run has not finished."""
    return read_json(run_dir(output, rid) / "run.json")


def is_completed(output, rid):
    rec = read_run(output, rid)
    return bool(rec and rec.get("status") == "completed"
                and (run_dir(output, rid) / "timeseries.nc").exists())


def clean_tmp(output):
    """Remove temporary files a killed run left behind; returns how many."""
    n = 0
    for p in list(Path(output).glob(".*" + TMP_SUFFIX + "*")) + list(Path(output).glob("runs/*/.*" + TMP_SUFFIX + "*")):
        try:
            p.unlink()
            n += 1
        except OSError:
            pass
    return n


@contextmanager
def study_lock(output):
    """Exclusive lock on the study folder (flock, released when the process dies)."""
    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    f = open(output / ".lock", "a+")
    try:
        try:
            fcntl.flock(f.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            f.seek(0)
            who = f.read().strip() or "another process"
            raise StudyLocked(f"{output} is in use by another `trackbench study run` ({who}); "
                              "wait for it to finish or stop it, then run again") from None
        f.seek(0)
        f.truncate()
        f.write(f"pid {os.getpid()}, started {time.strftime('%Y-%m-%d %H:%M:%S')}\n")
        f.flush()
        yield
    finally:
        f.close()
