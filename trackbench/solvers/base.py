"""What every time integrator takes and returns, and what it must do (its contract, as
scipy's OdeSolver documents its own). solvers/registry.py names the integrators and what
each one supports.

A solver sees the problem only through its right-hand side and its controls, never the
scenario: its module has ``run(model, y0, controls) -> RunResult`` (and, where its registry
entry says ``streams``, ``run(model, y0, controls, sink=None)``), where

- ``model`` is the right-hand side's bundle: the assembled model of one run (run/assemble.py
  Model: the compiled arrays model/dynamics/rhs.py evaluates, and their sizes), and ``y0`` the
  reduced state at t = 0 (q, qd, extras, bristle deflections: model/core/indices.py);
- ``controls`` is a ``Controls``, built once per run by the run layer from the validated
  scenario (registry.SolverEntry.controls): t_end, the output interval, the tolerances, the
  step limits (h0, h_max, h_min, max_steps), the number of samples, the method it runs, its
  own settings table (``controls.settings``: e.g. lee's ``accel_order``), the pins'
  velocities' own tolerance where the scenario sets one and the step controller
  (``pi_beta``: the explicit pairs' loop steps by the PI controller where it is not 0); the
  compiled loops take its numeric part, ``controls.loop_control`` (a ``Control``).

The solver:

1. integrates the model from y0 at t = 0 to ``controls.t_end`` with the method
   ``controls.method``; it validates nothing itself (the scenario did, against the
   solver's registry entry);
2. may integrate in coordinates of its own, but takes and returns the reduced layout
   (model/core/indices.py): every output means the same whichever solver made it;
3. controls its step by an error estimate and never steps over a contact switch: an onset
   or release inside a rejected step is located (solvers/common/events.py) and the retry
   ends just after it. In the reduced solver the estimate's norm is an RMS over q, qd and the
   bristles' deflections (never the extras: work quadratures, the drive's integral) of
   e_k / (tol_k (1 + max(|y_k|, |y_new,k|))) (DOP853: Hairer's combination of its two
   estimates), tol_k = ``controls.rtol`` (= atol, the scenario's tolerance) for every
   component, except that a method whose registry entry says so (ros34pw2) holds the pins'
   velocities to ``controls.tolerance_pin_velocity`` (0: the method's default;
   solvers/common/stepping.py error_norm_pins);
4. chooses its step by its error control alone (from ``h0``, up to ``h_max``), whatever the
   output interval, and fills ``Outputs`` (``allocate_outputs``): samples at t_k = k dt_out
   from its dense output between accepted steps, the peaks over every accepted step
   (solvers/common/monitor.py update_peaks, so no impulse between samples is missed), the
   statistics (indices.S_*: steps, rejected steps, right-hand sides, status, t_final);
5. moves the ground's memories (soil sinkage, approach speeds) only after an accepted step,
   never inside one (a rejected step leaves no trace); the bristle law's deflections are
   states (in the error test and the dense output), not memories;
6. stops at the first failure with a status code (status.Result: NaN, step-size underflow
   below ``h_min``, a wheel through the track, ``max_steps``), keeping the samples up to
   there; compiled code never raises;
7. is reproducible to the last bit: no fastmath, no threads, the elementary functions of
   model/core/fixed_math (docs/development.md, "Bit for bit");
8. returns ``trimmed(controls, out, extra)``; figures of its own go to RunResult.extra and
   are named in results_schema.md;
9. if its entry ``streams``, takes ``sink``: then its samples go to it chunk by chunk
   (``run_chunks``, CHUNK_ROWS samples at a time: the loop pauses before a step whose samples
   would not fit and resumes with it, its state in Outputs.resume), so a long run's memory does
   not grow with it (run/stream.py); a solver that does not stream runs in one piece.

What a solver supports beyond that (the closed track, the models beyond the paper, its
settings table, the method name its outputs carry) is declared in its registry entry, which
scenario validation, the run layer and the outputs read.
"""

from collections import namedtuple
from dataclasses import dataclass, field

import numpy as np

from ..model.core import indices as L

H0 = 1e-5        # s: first trial step; the controller grows it at once
H_MIN = 1e-13    # s: below this the run stops with STEP_SIZE_UNDERFLOW
# Samples a chunk of a streamed run holds (Outputs' rows): a few MB of y and diag. A step never
# spans a whole chunk (controls: h_max <= (CHUNK_ROWS - 1) output intervals), so a run streamed
# in chunks takes the steps of the same run in one piece (the loop pauses before a step whose
# samples would not fit, and resumes with it).
CHUNK_ROWS = 4096

# Step control of a run as the compiled loops take it (numba reads the named tuple as one
# argument): Controls.loop_control.
Control = namedtuple("Control", ["t_end", "dt_out", "rtol", "atol", "h0", "h_max", "h_min", "max_steps",
                                 "n_samples", "pi_beta"])


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


@dataclass(frozen=True)
class Controls:
    """Everything a solver is told besides the model and y0 (the module's docstring); built
    once per run by ``controls`` (through registry.SolverEntry.controls)."""

    t_end: float      # s: the run ends here (it starts at t = 0)
    dt_out: float     # s: the output interval; samples at t_k = k dt_out
    rtol: float
    atol: float
    h0: float         # s: the first trial step
    h_max: float      # s: the largest step (max_step, at most CHUNK_ROWS - 1 output intervals)
    h_min: float      # s: a step below this stops the run (STEP_SIZE_UNDERFLOW)
    max_steps: int    # accepted + rejected steps after which the run stops (MAX_STEPS)
    n_samples: int    # the output grid's samples, t = 0 and the last included
    method: str       # the method the solver runs (its entry's method, or its label)
    settings: dict = field(default_factory=dict)   # the solver's own table (registry: settings)
    # the pins' velocities' own tolerance in the error norm (the scenario's tolerance_pin_velocity;
    # 0: not set, the method's default); the methods that read it say so in their registry entry
    # (contract point 3)
    tolerance_pin_velocity: float = 0.0
    # the step controller: the PI controller's exponent on the previous error (solvers/common/
    # control.py PI_BETA), 0: the plain controller; the explicit pairs' loop reads it
    pi_beta: float = 0.0

    @property
    def loop_control(self):
        """The numeric part, as the compiled loops take it."""
        return Control(self.t_end, self.dt_out, self.rtol, self.atol, self.h0, self.h_max, self.h_min,
                       self.max_steps, self.n_samples, self.pi_beta)


def controls(duration, output_interval, tolerance, max_step=0.0, max_steps=0, method="", settings=None,
             tolerance_pin_velocity=0.0, pi_beta=0.0):
    """The Controls of a run from its settings. The step is the error control's alone,
    whatever the output interval (samples come from the dense output), up to ``max_step``
    where one is set (0: none)."""
    t_end = float(duration)
    dt_out = float(output_interval)
    h_max = min(float(max_step) or t_end, (CHUNK_ROWS - 1) * dt_out)
    return Controls(t_end, dt_out, float(tolerance), float(tolerance), min(H0, h_max), h_max, H_MIN,
                    step_cap(max_steps, t_end), n_samples(t_end, dt_out), method, dict(settings or {}),
                    float(tolerance_pin_velocity or 0.0), float(pi_beta))


STEPS_PER_SECOND = 400_000   # max_steps = 0: the closed track with friction takes ~160,000 a second
MIN_STEPS = 2_000_000


def step_cap(max_steps, t_end):
    """The accepted + rejected steps after which a run stops (Result.MAX_STEPS): max_steps, or
    with max_steps = 0, in proportion to the simulated time (a guard against a run whose steps
    collapse, not a bound on a long run)."""
    if int(max_steps):
        return int(max_steps)
    return max(MIN_STEPS, int(STEPS_PER_SECOND * float(t_end)))


def n_samples(t_end, dt_out):
    """The samples of the output grid from 0 to t_end."""
    return int(np.floor(t_end / dt_out * (1 + 1e-12))) + 1


def allocate_outputs(controls, model, ny, rows=None):
    """Outputs of a run: rows samples (default: all of them, the run in one piece)."""
    n_out = controls.n_samples if rows is None else min(rows, controls.n_samples)
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


def trimmed(controls, out, extra=None):
    """The RunResult of a run in one piece (of a streamed one: its last chunk's samples)."""
    base = int(out.resume[L.RS_BASE])
    n = int(out.stats[L.S_N_OUT]) - base
    t = np.arange(base, base + n) * controls.dt_out
    return RunResult(t, out.y[:n], out.diag[:n], out.peaks, out.stats, extra or {})
