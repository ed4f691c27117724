"""`study run`: validate, lock, skip what is done, run the rest, keep the summary.

    outcome = run_study("studies/speed_sweep.toml", workers=2)
"""

import os
import re
import socket
import time
from contextlib import closing
from dataclasses import dataclass, field
from pathlib import Path

from trackbench.study import store
from trackbench.study.execute import executors
from trackbench.study.execute.progress import StudyProgress
from trackbench.study.spec.study_file import Study, StudyError, load_study, resolved_toml


@dataclass
class Outcome:
    study: object
    ran: int = 0
    skipped: int = 0
    failed: list = field(default_factory=list)    # run ids failed in this invocation
    summary: object = None                          # DataFrame
    replicates: object = None                       # DataFrame or None
    elapsed: float = 0.0
    summary_error: str = ""                         # why summary.csv could not be written
    others: int = 0                                 # run folders of no run of this study (kept)
    limits: object = None                           # with [search]: limits.csv's DataFrame
    search_state: str = ""                          # with [search]: its state in one line

    def counts(self):
        """(failed, not run) over the study's runs: the summary's view, plus the runs failed in
        this invocation whose record could not be written."""
        if self.summary is None:
            return len(self.failed), 0
        status = dict(zip(self.summary.run_id, self.summary.status))
        status.update({rid: "failed" for rid in self.failed})
        failed = sum(s == "failed" for s in status.values())
        return failed, sum(s not in ("completed", "failed") for s in status.values())

    @property
    def failed_total(self):
        return self.counts()[0]

    def _decided_failures(self):
        """Failed runs a search counted as over its limit (limits.quantity_of: a maximum or a
        ride figure that passed the limit before the run stopped): the search's answer, not a
        problem."""
        from trackbench.study.read.limits import failed_over_limit
        s, df = self.study.search, self.summary
        if s is None or df is None:
            return 0
        return int(failed_over_limit(df, s.quantity, s.limit).sum())

    def problem(self):
        """None when every run of the study is completed and recorded (or failed over a
        search's limit, which decides it); otherwise the one line that goes with a nonzero
        exit, saying how many runs are not completed."""
        failed, missing = self.counts()
        failed -= self._decided_failures()
        n = len(self.study.runs)
        parts = ([f"{failed} of {n} runs failed"] if failed else []) + (
            [f"{missing} of {n} runs not run"] if missing else [])
        if self.summary_error:
            parts.append(f"the summary could not be written: {self.summary_error}")
        if not parts:
            return None
        return ", ".join(parts) + " (reasons in the summary and in runs/<run-id>/run.json)"


def manifest(study):
    """runs.json: the study's runs as expanded now, so the folder can be read later even when
    the package's defaults (and so a re-expansion's run ids) have changed; ``source`` is the
    study file (absolute), which the folder belongs to (check_output)."""
    return {
        "name": study.name,
        "source": os.path.abspath(study.source),
        "description": study.description,
        "replicates": study.replicates,
        "storage": study.storage,
        "param_names": study.param_names,
        "search": study.search.as_dict() if study.search is not None else None,
        "points": study.points,
        "runs": [
            {
                "run_id": r.run_id,
                "index": r.index,
                "variant": r.variant,
                "replicate": r.replicate,
                "params": r.params,
                "scenario": r.scenario,
            }
            for r in study.runs
        ],
    }


def recorded_source(output):
    """The study file a results folder belongs to, as (path, exact): runs.json's ``source``
    (exact), else the path in study.toml's first line (as it was given: relative paths are
    compared by file name), else None (a new folder)."""
    m = store.read_json(Path(output) / "runs.json")
    if isinstance(m, dict) and m.get("source"):
        return m["source"], True
    try:
        with open(Path(output) / "study.toml") as f:
            first = f.readline()
    except OSError:
        return None
    m = re.match(r"# resolved copy of (.*): \d+ runs$", first.rstrip("\n"))
    return (m.group(1), os.path.isabs(m.group(1))) if m else None


def _same_file(a, b):
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_output(study):
    """Raise StudyError (one line) when the study's results folder cannot be used: it cannot be
    created or written, or it holds the results of another study file (whose study.toml,
    runs.json and summary this run would replace). The same file, edited or not, resumes."""
    from trackbench.outputs.files.atomic import writable_folder
    try:
        writable_folder(study.output)
    except ValueError as e:
        raise StudyError(f"{study.source}: results folder {e}") from None
    rec = recorded_source(study.output)
    if rec is None or study.source is None:
        return
    owner, exact = rec
    same = _same_file(owner, study.source) if exact else Path(owner).name == Path(study.source).name
    if not same:
        raise StudyError(
            f"{study.output} holds the results of another study file, {owner}; running "
            f"{study.source} there would replace them: give {study.source} another [study] name (or "
            f"output), or run it with --output FOLDER"
        )


def plan(study, force=False, runs=None, ran=()):
    """(tasks to run, ids already completed) of ``runs`` (default: all the study's), each task
    storing its files as study.storage says; ``force`` reruns completed runs, but not those in
    ``ran`` (run by this invocation already)."""
    tasks, done = [], []
    for run in study.runs if runs is None else runs:
        if run.run_id in ran or (not force and store.is_completed(study.output, run.run_id)):
            done.append(run.run_id)
            continue
        tasks.append({"run_id": run.run_id, "output": str(study.output), "scenario": run.scenario,
                      "storage": study.storage,
                      "meta": {"study": study.name, "index": run.index, "variant": run.variant,
                               "replicate": run.replicate, "params": run.params}})
    return tasks, done


def run_study(path, workers=2, executor="local", scheduler=None, force=False, output=None,
              quiet=False, storage=None, pools=None):
    """Run a study (a study file, or a Study that load_study returned); raises StudyError /
    ValueError before anything starts on bad input, StudyLocked when another process works on
    the same folder. ``storage`` ("full" or "compact") overrides the study's [study] storage;
    ``pools`` (executors.PoolFactory) gives the worker processes (default: spawned fresh)."""
    t0 = time.perf_counter()
    study = _prepare(path, workers, executor, scheduler, output, storage)
    check_output(study)
    out = Outcome(study=study)
    with store.study_lock(study.output):
        check_output(study)   # again under the lock: another study may have taken the folder meanwhile
        store.clean_tmp(study.output)
        store.write_text(study.output / "study.toml", resolved_toml(study))
        store.write_json(study.output / "runs.json", manifest(study))
        pools = pools or executors.PoolFactory()
        waves = _Waves(study, out, force, (executor, workers, scheduler, pools), quiet)
        tables = _import_tables()
        try:
            if study.search is None:
                waves(study.runs)
            else:
                from trackbench.study.execute.searching import run_search
                run_search(study, waves, waves.search)
        finally:
            waves.close()
            pools.close()
            store.clean_tmp(study.output)  # what killed workers left half-written
            tables()
            _summarise(study, out)
            out.others = len(other_runs(study))
    out.elapsed = time.perf_counter() - t0
    return out


class _Waves:
    """Runs a study's runs in waves (a plain study: one; a search: its scan, then each round of
    bisection) on one executor: a dask cluster started for the first wave serves the rest, the
    progress counts across them, and --force reruns a run once."""

    def __init__(self, study, out, force, how, quiet):
        from contextlib import ExitStack
        self.study, self.out, self.force, self.how, self.quiet = study, out, force, how, quiet
        self.progress, self.client, self.ran, self.line = None, None, set(), None
        self.stack = ExitStack()

    def __call__(self, runs):
        """Run those of ``runs`` that are not completed (all with --force), one wave."""
        executor, workers, scheduler, pools = self.how
        if self.study.search is not None:   # the runs the search has asked for so far
            store.write_json(self.study.output / "runs.json", manifest(self.study))
        tasks, done = plan(self.study, self.force, runs, self.ran)
        self.out.skipped += len(done)
        if tasks and not self.ran:  # they load while this process sets up
            pools.prepare([t["scenario"] for t in tasks], executor, scheduler)
        if self.progress is None:
            self.progress = StudyProgress(len(tasks), len(done), self.quiet, workers=workers,
                                          flag=pools.compile_flag(), line=self.line)
        else:
            self.progress.more(len(tasks), len(done))
        if not tasks:
            return
        self.ran.update(t["run_id"] for t in tasks)
        if executor == "dask" and self.client is None:
            self.client = self.stack.enter_context(executors.dask_client(workers, scheduler, pools))
        if executor == "dask":
            stream = executors.run_dask(tasks, notify=self.progress.note, client=self.client)
        else:
            stream = executors.run_local(tasks, workers, notify=self.progress.note,
                                         on_running=self.progress.running, pools=pools)
        with closing(stream):
            for task, rec in stream:
                rec = confirm(task, rec)
                self.out.ran += 1
                if rec["status"] != "completed":
                    self.out.failed.append(task["run_id"])
                self.progress.update(rec)

    def search(self, text):
        self.line = text
        if self.progress is not None:
            self.progress.search(text)

    def close(self):
        try:
            self.stack.close()
        finally:
            if self.progress is not None:
                self.progress.close()


def _import_tables():
    """Import pandas and pyarrow (the summary's frame and its files, 0.3-0.5 s) in a thread
    while the workers start and run, instead of after the last run; returns a function that
    waits for it. This process imports neither elsewhere until then (no two threads race for
    the same modules); a failed import is left for the summary to report."""
    import threading

    def body():
        for name in ("pandas", "pyarrow"):
            try:
                __import__(name)
            except Exception:  # noqa: BLE001  (pyarrow is optional; pandas fails again where used)
                pass
    th = threading.Thread(target=body, name="trackbench-import-tables", daemon=True)
    th.start()
    return th.join


def _prepare(path, workers, executor, scheduler, output, storage):
    """The study to run, its folder absolute, its storage decided; raises on bad input."""
    executors.check_arguments(workers, executor, scheduler, storage)
    study = path if isinstance(path, Study) and output is None else load_study(getattr(path, "source", path),
                                                                               output=output)
    # workers get absolute paths only: a relative one would land in each worker's own cwd
    study.output = Path(os.path.abspath(study.output))
    study.storage = storage or study.storage
    return study


def _summarise(study, out):
    """Write the summary files (and limits.csv of a search); when they cannot be written the
    frames are still returned and the reason kept (the study then does not count as done)."""
    from trackbench.study.read.summary import replicate_frame, summary_frame, write_summary
    try:
        if study.search is not None:   # first: its replay adds the runs a resumed search asks next
            from trackbench.study.read.limits import write_limits
            out.limits, out.search_state = write_limits(study)
            store.write_json(study.output / "runs.json", manifest(study))
        out.summary, out.replicates = write_summary(study)
    except OSError as e:
        out.summary_error = executors.failure_reason(e, study.output)
        out.summary = summary_frame(study)
        out.replicates = replicate_frame(study, out.summary) if study.replicates > 1 else None


def confirm(task, rec):
    """The coordinator's verdict on a run a worker returned: completed only when the study
    folder as this process sees it holds the run (run.json of this try saying completed and
    a timeseries.nc that opens); otherwise failed with the reason. Any verdict that is not
    already on disk as the worker's own record is written to run.json here."""
    rdir = store.run_dir(task["output"], task["run_id"])
    disk = store.read_json(rdir / "run.json")
    own = (
        disk is not None and rec.get("attempt_id") is not None and disk.get("attempt_id") == rec["attempt_id"]
    )
    if rec["status"] == "completed":
        reason = _files_problem(rdir, disk, own, rec)
        if reason is None:
            return rec
        rec = {**rec, "status": "failed", "status_message": reason, "worker_status": "completed"}
    elif own and disk.get("status") == rec["status"]:
        return rec
    try:
        store.write_json(rdir / "run.json", rec)
    except OSError as e:
        rec = {**rec, "status_message": f"{rec['status_message']}; not recorded in {rdir}: "
                                        f"{executors.failure_reason(e, rdir)}"}
    return rec


def _files_problem(rdir, disk, own, rec):
    """Why a run a worker reports completed is not completed here (None when it is). An
    unreadable timeseries.nc is removed: it must not look like a result."""
    here = socket.gethostname()
    said = f"the worker on host {rec.get('host', '?')} reported the run completed, but"
    shared = "do the workers see the study folder at the same path (a shared file system)?"
    if disk is None:
        return f"{said} {rdir / 'run.json'} is missing or unreadable on host {here}: {shared}"
    if not own:
        return f"{said} {rdir / 'run.json'} on host {here} is not the record it wrote: {shared}"
    if disk.get("status") != "completed":
        return f"{said} {rdir / 'run.json'} on host {here} says {disk.get('status')!r}"
    nc = rdir / "timeseries.nc"
    why = _unreadable(nc, rec)
    if why is not None:
        try:
            nc.unlink(missing_ok=True)
        except OSError:
            pass
        return f"{said} {nc} cannot be read on host {here}: {why}"
    return None


HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"   # the first bytes of a netCDF-4 file


def _unreadable(nc, rec):
    """Why ``nc`` is not the file the worker wrote (None when it is): it must start as an HDF5
    file and have the size the worker reported (files are renamed into place whole, so a file
    of that size that starts so is the one written). Opening every file with netCDF4 cost the
    coordinator 3-7 ms a run, as much as a short run's solve; a record without the size (a
    worker of an earlier version) has its file opened as before."""
    size = rec.get("timeseries_bytes")
    try:
        if size is None:
            import netCDF4
            with netCDF4.Dataset(nc, "r") as f:
                f.getncattr("status")
            return None
        with open(nc, "rb") as f:
            head, got = f.read(len(HDF5_SIGNATURE)), os.fstat(f.fileno()).st_size
    except Exception as e:
        return f"{type(e).__name__}: {e}"
    if head != HDF5_SIGNATURE:
        return "not a netCDF-4 (HDF5) file"
    return None if got == size else f"{got} bytes, where the worker wrote {size}"


def count(n, word):
    """'1 run', '2 runs'."""
    return f"{n} {word}" if n == 1 else f"{n} {word}s"


def others_note(n, where=""):
    """What a study says of the run folders that belong to none of its runs ('' for none)."""
    place = f" in {where}" if where else ""
    return f"{count(n, 'other run folder')}{place} kept (an earlier grid or model version)" if n else ""


def other_runs(study):
    """Run folders in the study folder that belong to none of its runs (a grid edited since, or
    an older model version: run ids include it). Kept, never in the summary."""
    ids = {r.run_id for r in study.runs}
    runs = Path(study.output) / "runs"
    return sorted(p.name for p in runs.iterdir() if p.is_dir() and p.name not in ids) if runs.is_dir() else []


def status_counts(study):
    """({'completed': n, 'failed': n, 'pending': n}, [(run id, why) of each failed run]) from
    the runs' run.json (of a search: the runs it has asked for so far). The small files only,
    and no pandas: `study status` of a 1,000-run study stays well under a second."""
    counts, failed = dict.fromkeys(("completed", "failed", "pending"), 0), []
    for run in study.runs:
        rec = store.read_run(study.output, run.run_id) or {"status": "pending"}
        if rec.get("status") in counts:
            counts[rec["status"]] += 1
        if rec.get("status") == "failed":
            failed.append((run.run_id, rec.get("status_message", "")))
    return counts, failed


def report(outcome):
    """The text printed after a study run."""
    from trackbench.study.read.summary import format_table
    s = outcome.study
    text = format_table(outcome.summary, outcome.replicates, s.param_names)
    n_failed, n_missing = outcome.counts()
    missing = f", {n_missing} not run" if n_missing else ""
    text += (
        f"\n\nstudy {s.name}: {count(len(s.runs), 'run')}, {outcome.ran} run now, {outcome.skipped} "
        "already completed, "
        f"{n_failed} failed{missing}; {outcome.elapsed:.1f} s\nresults: {s.output}/summary.csv"
    )
    if outcome.summary_error:
        text += f" NOT WRITTEN: {outcome.summary_error}"
    if outcome.limits is not None:
        text += (f"\n\n{outcome.limits.to_string(index=False, float_format=lambda x: f'{x:.6g}', na_rep='-')}"
                 f"\n{outcome.search_state}\nlimits: {s.output}/limits.csv")
    if outcome.others:
        text += f"\n{others_note(outcome.others, f'{s.output}/runs')}, not in the summary"
    return text
