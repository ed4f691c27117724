"""What every solver takes and returns: the step-control settings, the output arrays it
fills, and the result it hands to output.py."""

from collections import namedtuple
from dataclasses import dataclass, field

import numpy as np

from ..model import layout as L

H0 = 1e-5        # s: first trial step; the controller grows it at once
H_MIN = 1e-13    # s: below this the run stops with STEP_SIZE_UNDERFLOW

# Step control of a run (numba reads the named tuple as one argument).
Control = namedtuple("Control", ["t_end", "dt_out", "rtol", "atol", "h0", "h_max", "h_min", "max_steps"])

# Filled by the compiled loops: samples on the output grid, peaks over every accepted step.
Outputs = namedtuple("Outputs", [
    "y",         # (n_out, 2 nq + 1) reduced state (q, qd, W) at the output times
    "diag",      # (n_out, n_diag) forces and energies at the output times
    "peaks",     # (n_peaks, 6) value, time, then the last two samples (f, t)
    "stats",     # (N_STATS,) layout.S_*
])


@dataclass
class RunResult:
    time: np.ndarray          # (n_out,) output times
    y: np.ndarray             # (n_out, 2 nq + 1) reduced state (q, qd, W) at the output times
    diag: np.ndarray          # (n_out, n_diag) forces and energies at the output times
    peaks: np.ndarray         # (n_peaks, 6) value, time, then the last two samples (f, t)
    stats: np.ndarray         # layout.S_*
    extra: dict = field(default_factory=dict)   # solver-specific arrays and figures


def control(scenario):
    tol = scenario["tolerance"]
    dt_out = scenario["output_interval"]
    return Control(float(scenario["duration"]), float(dt_out), float(tol), float(tol), min(H0, dt_out),
                   float(dt_out), H_MIN, int(scenario["max_steps"]))


def n_samples(scenario):
    return int(np.floor(scenario["duration"] / scenario["output_interval"] * (1 + 1e-12))) + 1


def allocate_outputs(scenario, model, ny):
    n_out = n_samples(scenario)
    return Outputs(np.full((n_out, ny), np.nan), np.full((n_out, L.n_diag(model.nw, model.n_links)), np.nan),
                   np.zeros((L.n_peaks(model.nw), 6)), np.zeros(L.N_STATS))


def trimmed(scenario, out, extra=None):
    n = int(out.stats[L.S_N_OUT])
    t = np.arange(n) * scenario["output_interval"]
    return RunResult(t, out.y[:n], out.diag[:n], out.peaks, out.stats, extra or {})
