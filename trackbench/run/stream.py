"""A long run written to its netCDF file as it goes, so that its memory does not grow with
its duration: the run's one pipeline (run/simulate.py Prepared) with a sink. The solver hands
over its samples chunk by chunk (solvers/base.py run_chunks: the compiled loop pauses when its
chunk is full and resumes with the same step, so the run takes the steps of a run in one
piece); each chunk's variables are built as for a run in one piece (Prepared.dataset, with
the run's first sample in front: the energies are measured from it, and no other variable
reads across samples) and appended along the file's unlimited time dimension. The peaks,
first contacts and the run's attributes, located along the steps in the compiled loop as
ever, are written when the run ends.

The file grows under a temporary name beside its target and is renamed when the run ends
(outputs/files/atomic.py): a run killed halfway leaves no file that looks complete. The file
reads back (xarray) as the Dataset that simulate() returns, every array bit for bit
(tests/test_long_runs.py).

What streams: a solver whose registry entry streams (the reduced solver), on rigid ground
with the paper's track layout, stored in full (compact storage packs positions around their
whole run's range; the soil's and the closed track's outputs read across the run). Other
runs, and runs of at most one chunk, are built in memory.
"""

import os
import time
from pathlib import Path

import numpy as np

from trackbench.outputs.files.atomic import _umask, tmp_path
from trackbench.outputs.files.netcdf import Appender
from trackbench.solvers.base import CHUNK_ROWS, RunResult
from trackbench.solvers.registry import SOLVERS


def streamable(scenario, storage="full"):
    """Whether `trackbench run` streams this run to its file (see the module's docstring): its
    solver's registry entry streams (takes a sink), and the run has more than one chunk."""
    entry = SOLVERS[scenario["solver"]]
    return (
        storage == "full"
        and entry.streams
        and scenario["track"]["layout"] == "paper"
        and scenario["terrain"].get("soil", "rigid") == "rigid"
        and entry.controls(scenario).n_samples > CHUNK_ROWS
    )


class _Chunks:
    """The solver's sink: each chunk's Dataset (the run's first sample in front, then dropped)
    appended to the file."""

    def __init__(self, run, appender):
        self.run, self.scenario, self.appender = run, run.scenario, appender
        self.first = None
        self.seat = []   # the seat's acceleration, every chunk's: its ride metrics read the whole run

    def result(self, base, y, diag, stats, peaks=None):
        dt = self.scenario["output_interval"]
        n = y.shape[0]
        if base == 0 and self.first is None:
            self.first = (y[:1].copy(), diag[:1].copy())
        skip = 0 if base == 0 else 1
        t = np.arange(base, base + n) * dt
        if skip:
            y, diag, t = np.vstack([self.first[0], y]), np.vstack([self.first[1], diag]), np.r_[0.0, t]
        pk = peaks if peaks is not None else np.zeros((0, 6))
        return RunResult(t, y, diag, pk, stats), skip

    def __call__(self, base, y, diag, stats, peaks):
        result, skip = self.result(base, y, diag, stats, peaks)
        ds = self.run.dataset(result).isel(time=slice(skip, None))
        self.seat.append(ds["seat_acceleration_y"].values)
        self.appender.append(ds)

    def ride(self):
        """The ride metrics over the whole run (output.ride_variables)."""
        from trackbench.outputs.dataset import ride_variables
        a = np.concatenate(self.seat)
        return ride_variables(self.scenario, a, np.arange(a.shape[0]) * self.scenario["output_interval"])


def stream_run(scenario, path, failed_path):
    """Run ``scenario`` streamed to ``path`` (completed) or ``failed_path`` (stopped early);
    returns (the path written, completed?)."""
    from trackbench.run.simulate import prepare
    t_wall = time.perf_counter()
    run = prepare(scenario)
    tmp = tmp_path(path)
    appender = Appender(tmp, CHUNK_ROWS)
    try:
        sink = _Chunks(run, appender)
        t_solve = time.perf_counter()
        result = run.solve(sink=sink)
        solve_time = time.perf_counter() - t_solve
        # the peaks and attributes: a run of the first sample with the run's peaks and statistics
        first, _ = sink.result(0, sink.first[0], sink.first[1], result.stats, result.peaks)
        ds = run.dataset(first, time.perf_counter() - t_wall, solve_time)
        ds = ds.assign(sink.ride())
        appender.finish(ds)
        target = Path(path if ds.attrs["status"] == "completed" else failed_path)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, target)
        return target, ds.attrs["status"] == "completed"
    except BaseException:
        appender.close()
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
