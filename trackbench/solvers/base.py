"""What every time integrator takes and returns, and what it must do (its contract, as
scipy's OdeSolver documents its own). solvers/registry.py names the integrators.

A solver is a module with ``run(scenario, model, y0) -> RunResult`` that:

1. integrates the model (assembly.Model: the compiled arrays of one run) from the reduced
   state y0 = (q, qd, extras, bristle deflections: model/core/indices.py) at t = 0 to
   ``scenario["duration"]``, with its settings from the validated scenario only
   (``control(scenario)``: tolerance, output interval, step limits; ``method``); it
   validates nothing itself;
2. may integrate in coordinates of its own, but takes and returns the reduced layout
   (model/core/indices.py): every output means the same whichever solver made it;
3. controls its step by an error estimate and never steps over a contact switch: an onset
   or release inside a rejected step is located (solvers/common/events.py) and the retry
   ends just after it;
4. chooses its step by its error control alone (up to ``max_step`` where set), whatever the
   output interval, and fills ``Outputs`` (``allocate_outputs``): samples at t_k = k output_interval from its
   dense output between accepted steps, the peaks over every accepted step
   (solvers/common/monitor.py update_peaks, so no impulse between samples is missed), the
   statistics (indices.S_*: steps, rejected steps, right-hand sides, status, t_final);
5. moves the ground's memories (soil sinkage, approach speeds) only after an accepted step,
   never inside one (a rejected step leaves no trace); the bristle law's deflections are
   states (in the error test and the dense output), not memories;
6. stops at the first failure with a status code (status.Result: NaN, step-size underflow,
   a wheel through the track, max steps), keeping the samples up to there; compiled code
   never raises;
7. is reproducible to the last bit: no fastmath, no threads, the elementary functions of
   model/core/fixed_math (docs/development.md, "Bit for bit");
8. returns ``trimmed(scenario, out, extra)``; figures of its own go to RunResult.extra and
   are named in results_schema.md;
9. the reduced solvers also take ``sink``: then their samples go to it chunk by chunk
   (``run_chunks``, CHUNK_ROWS samples at a time: the loop pauses before a step whose samples
   would not fit and resumes with it, its state in Outputs.resume), so a long run's memory does
   not grow with it (trackbench/stream.py); the lee solver runs in one piece.
"""

from collections import namedtuple
from dataclasses import dataclass, field

import numpy as np

from ..model.core import indices as L

H0 = 1e-5        # s: first trial step; the controller grows it at once
H_MIN = 1e-13    # s: below this the run stops with STEP_SIZE_UNDERFLOW
# Samples a chunk of a streamed run holds (Outputs' rows): a few MB of y and diag. A step never
# spans a whole chunk (control: h_max <= (CHUNK_ROWS - 1) output intervals), so a run streamed
# in chunks takes the steps of the same run in one piece (the loop pauses before a step whose
# samples would not fit, and resumes with it).
CHUNK_ROWS = 4096

# Step control of a run (numba reads the named tuple as one argument).
Control = namedtuple("Control", ["t_end", "dt_out", "rtol", "atol", "h0", "h_max", "h_min", "max_steps",
                                 "n_samples"])

# Filled by the compiled loops: samples on the output grid, peaks over every accepted step.
Outputs = namedtuple("Outputs", [
    "y",         # (n_out, ny) reduced state (q, qd, extras, bristles) at the output times
    "diag",      # (n_out, n_diag) forces and energies at the output times
    "peaks",     # (n_peaks, 6) value, time, then the last two samples (f, t)
    "stats",     # (N_STATS,) indices.S_*
    "resume",    # (N_RUN_STATE,) indices.RS_*: the loop's state between the chunks of a streamed run
])


@dataclass
class RunResult:
    time: np.ndarray          # (n_out,) output times
    y: np.ndarray             # (n_out, ny) reduced state (q, qd, extras, bristles) at the output times
    diag: np.ndarray          # (n_out, n_diag) forces and energies at the output times
    peaks: np.ndarray         # (n_peaks, 6) value, time, then the last two samples (f, t)
    stats: np.ndarray         # indices.S_*
    extra: dict = field(default_factory=dict)   # solver-specific arrays and figures


def control(scenario):
    """The step is the error control's alone, whatever the output interval (samples come from
    the dense output), up to ``max_step`` where a scenario sets one (0: none)."""
    tol = scenario["tolerance"]
    t_end = float(scenario["duration"])
    dt_out = float(scenario["output_interval"])
    h_max = min(float(scenario["max_step"]) or t_end, (CHUNK_ROWS - 1) * dt_out)
    return Control(t_end, dt_out, float(tol), float(tol), min(H0, h_max), h_max, H_MIN,
                   step_cap(scenario), n_samples(scenario))


STEPS_PER_SECOND = 400_000   # max_steps = 0: the closed track with friction takes ~160,000 a second
MIN_STEPS = 2_000_000


def step_cap(scenario):
    """The accepted + rejected steps after which a run stops (Result.MAX_STEPS): max_steps, or
    with max_steps = 0, in proportion to the simulated time (a guard against a run whose steps
    collapse, not a bound on a long run)."""
    if int(scenario["max_steps"]):
        return int(scenario["max_steps"])
    return max(MIN_STEPS, int(STEPS_PER_SECOND * float(scenario["duration"])))


def n_samples(scenario):
    return int(np.floor(scenario["duration"] / scenario["output_interval"] * (1 + 1e-12))) + 1


def allocate_outputs(scenario, model, ny, rows=None):
    """Outputs of a run: rows samples (default: all of them, the run in one piece)."""
    n_out = n_samples(scenario) if rows is None else min(rows, n_samples(scenario))
    return Outputs(np.full((n_out, ny), np.nan), np.full((n_out, L.n_diag(model.nw, model.n_links)), np.nan),
                   np.zeros((L.n_peaks(model.nw), 6)), np.zeros(L.N_STATS), np.zeros(L.N_RUN_STATE))


def run_chunks(integrate, out, sink):
    """Call integrate() (a compiled loop on out) until the run ends; with a sink, hand it each
    chunk as sink(first sample's index, y rows, diag rows, stats, peaks so far) (views, valid
    during the call), and resume the loop with its chunk emptied."""
    rs = out.resume
    while True:
        integrate()
        if sink is not None:
            n = int(rs[L.RS_N_OUT] - rs[L.RS_BASE])
            sink(int(rs[L.RS_BASE]), out.y[:n], out.diag[:n], out.stats, out.peaks)
        if rs[L.RS_PAUSED] == 0.0:
            return
        rs[L.RS_BASE] = rs[L.RS_N_OUT]
        out.y.fill(np.nan)     # as a fresh run's: the columns a model never writes stay NaN
        out.diag.fill(np.nan)


def trimmed(scenario, out, extra=None):
    """The RunResult of a run in one piece (of a streamed one: its last chunk's samples)."""
    base = int(out.resume[L.RS_BASE])
    n = int(out.stats[L.S_N_OUT]) - base
    t = np.arange(base, base + n) * scenario["output_interval"]
    return RunResult(t, out.y[:n], out.diag[:n], out.peaks, out.stats, extra or {})
