"""`study run`: validate, lock, skip what is done, run the rest, keep the summary.

    outcome = run_study("studies/speed_sweep.toml", workers=2)
"""

import sys
import time
from dataclasses import dataclass, field

from . import executors, store
from .spec import load_study, resolved_toml
from .summary import format_table, summary_frame, write_summary


@dataclass
class Outcome:
    study: object
    ran: int = 0
    skipped: int = 0
    failed: list = field(default_factory=list)    # run ids failed in this invocation
    summary: object = None                          # DataFrame
    replicates: object = None                       # DataFrame or None
    elapsed: float = 0.0

    @property
    def failed_total(self):
        return int((self.summary.status == "failed").sum()) if self.summary is not None else len(self.failed)


def manifest(study):
    """runs.json: the study's runs as expanded now, so the folder can be read later even when
    the package's defaults (and so a re-expansion's run ids) have changed."""
    return {"name": study.name, "description": study.description, "replicates": study.replicates,
            "param_names": study.param_names,
            "runs": [{"run_id": r.run_id, "index": r.index, "variant": r.variant, "replicate": r.replicate,
                      "params": r.params, "scenario": r.scenario} for r in study.runs]}


def plan(study, force=False):
    """(tasks to run, ids already completed)."""
    tasks, done = [], []
    for run in study.runs:
        if not force and store.is_completed(study.output, run.run_id):
            done.append(run.run_id)
            continue
        tasks.append({"run_id": run.run_id, "output": str(study.output), "scenario": run.scenario,
                      "meta": {"study": study.name, "index": run.index, "variant": run.variant,
                               "replicate": run.replicate, "params": run.params}})
    return tasks, done


class _Progress:
    """A rich progress bar on a terminal; one plain line per finished run otherwise."""

    def __init__(self, total, skipped, quiet=False, stream=None):
        from rich.console import Console
        self.console = Console(file=stream or sys.stderr)
        self.total, self.done, self.failed = total, 0, 0
        self.quiet, self.t0 = quiet, time.perf_counter()
        self.bar = None
        if not quiet and self.console.is_terminal and total:
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn
            self.bar = Progress(TextColumn("[bold]{task.description}"), BarColumn(),
                                TextColumn("{task.fields[counts]}"), TimeElapsedColumn(),
                                TextColumn("ETA"), TimeRemainingColumn(), console=self.console)
            self.task = self.bar.add_task("runs", total=total, counts=self._counts())
            self.bar.start()
        elif not quiet:
            self.console.print(f"{total} runs to do, {skipped} already completed", highlight=False)

    def _counts(self):
        return f"done {self.done}  failed {self.failed}  remaining {self.total - self.done - self.failed}"

    def update(self, rec):
        if rec["status"] == "completed":
            self.done += 1
        else:
            self.failed += 1
        if self.bar is not None:
            self.bar.update(self.task, advance=1, counts=self._counts())
        elif not self.quiet:
            n = self.done + self.failed
            el = time.perf_counter() - self.t0
            eta = el / n * (self.total - n)
            msg = "" if rec["status"] == "completed" else f": {rec.get('status_message', '')}"
            self.console.print(f"[{n}/{self.total}] {rec['run_id']} {rec['status']}{msg}  ({self._counts()}, "
                               f"ETA {eta:.0f} s)", highlight=False, markup=False)

    def close(self):
        if self.bar is not None:
            self.bar.stop()


def run_study(path, workers=2, executor="local", scheduler=None, force=False, output=None,
              quiet=False, compress=False):
    """Run a study file; raises StudyError / ValueError before anything starts on bad input,
    StudyLocked when another process works on the same folder."""
    if not isinstance(workers, int) or workers < 1:
        raise ValueError(f"--workers {workers!r} is not allowed: expected an integer >= 1")
    executors.check_executor(executor, scheduler)
    study = load_study(path, output=output)
    out = Outcome(study=study)
    t0 = time.perf_counter()
    with store.study_lock(study.output):
        store.clean_tmp(study.output)
        store.write_text(study.output / "study.toml", resolved_toml(study))
        store.write_json(study.output / "runs.json", manifest(study))
        tasks, done = plan(study, force)
        for t in tasks:
            t["compress"] = compress
        out.skipped = len(done)
        progress = _Progress(len(tasks), len(done), quiet)
        if executor == "dask":
            stream = executors.run_dask(tasks, workers, scheduler)
        else:
            stream = executors.run_local(tasks, workers)
        try:
            if tasks:
                for task, rec in stream:
                    out.ran += 1
                    if rec["status"] != "completed":
                        out.failed.append(task["run_id"])
                    progress.update(rec)
        finally:
            stream.close()
            progress.close()
            out.summary, out.replicates = write_summary(study)
    out.elapsed = time.perf_counter() - t0
    return out


def status_counts(study):
    """{'completed': n, 'failed': n, 'pending': n} from the runs' run.json."""
    df = summary_frame(study)
    return {s: int((df.status == s).sum()) for s in ("completed", "failed", "pending")}, df


def report(outcome):
    """The text printed after a study run."""
    s = outcome.study
    text = format_table(outcome.summary, outcome.replicates, s.param_names)
    n_failed = outcome.failed_total
    text += (f"\n\nstudy {s.name}: {len(s.runs)} runs, {outcome.ran} run now, {outcome.skipped} already completed, "
             f"{n_failed} failed; {outcome.elapsed:.1f} s\nresults: {s.output}/summary.csv")
    return text
