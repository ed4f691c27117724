"""The results folder of a study: layout, atomic writes, the lock.

    <output>/study.toml               resolved copy of the study file
    <output>/runs.json                the expanded runs (id, grid point, resolved scenario)
    <output>/summary.csv (.parquet)   one row per run
    <output>/replicates.csv (.parquet) one row per variant (studies with replicates > 1)
    <output>/.lock                    held by the `study run` working on the folder
    <output>/runs/<run-id>/timeseries.nc, run.json, recording.rrd

Every file is written atomically (trackbench/atomic.py), so a killed process never leaves a
file that looks complete.
"""

import fcntl
import json
import os
import time
from contextlib import contextmanager
from pathlib import Path

from trackbench.outputs.files.atomic import TMP_SUFFIX, atomic_path, tmp_path  # noqa: F401  (tmp_path: the workers' and clean_tmp's)


class StudyLocked(RuntimeError):
    """Another process holds the study folder's lock."""


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
    for p in list(Path(output).glob(".*" + TMP_SUFFIX + "*")) + list(
        Path(output).glob("runs/*/.*" + TMP_SUFFIX + "*")
    ):
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
