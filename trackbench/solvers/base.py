"""What every solver returns, and the output arrays it fills."""

from dataclasses import dataclass, field

import numpy as np

from ..model import layout as L


@dataclass
class RunResult:
    time: np.ndarray          # (n_out,) output times
    y: np.ndarray             # (n_out, 2 nq + 1) reduced state (q, qd, W) at the output times
    diag: np.ndarray          # (n_out, n_diag) forces and energies at the output times
    peaks: np.ndarray         # (n_peaks, 6) value, time, then the last two samples (f, t)
    stats: np.ndarray         # layout.S_*
    extra: dict = field(default_factory=dict)   # solver-specific time series and figures


def allocate_outputs(scenario, model, ny):
    n_out = int(np.floor(scenario["duration"] / scenario["output_interval"] * (1 + 1e-12))) + 1
    out_y = np.full((n_out, ny), np.nan)
    out_d = np.full((n_out, L.n_diag(model.nw, model.n_links)), np.nan)
    peaks = np.zeros((L.n_peaks(model.nw), 6))
    stats = np.zeros(L.N_STATS)
    return out_y, out_d, peaks, stats


def trimmed(scenario, out_y, out_d, peaks, stats, extra=None):
    n = int(stats[L.S_N_OUT])
    t = np.arange(n) * scenario["output_interval"]
    return RunResult(t, out_y[:n], out_d[:n], peaks, stats, extra or {})
