"""Peak tracking at accepted steps (solvers/monitor.py): the parabola refinement finds a
smooth peak between samples, also across uneven steps, and leaves a kink at a located
contact switch alone."""

import numpy as np

from trackbench.solvers.common.monitor import _up


def _track(times, values, t_switch=-1.0):
    peaks = np.full((1, 6), np.nan)
    peaks[0, 0] = -np.inf
    for t, v in zip(times, values):
        _up(peaks, 0, v, t, t_switch)
    return peaks[0, 0], peaks[0, 1]


def _bump(t):
    return np.cos(7.0 * (t - 0.4111))  # peak 1 at t = 0.4111


def test_smooth_peak_is_refined_between_samples():
    t = np.arange(0.0, 1.0, 0.03)
    f = _bump(t)
    peak, when = _track(t, f)
    assert 1.0 - f.max() > 1e-3  # the samples miss the peak ...
    assert abs(peak - 1.0) < 1e-4  # ... the parabola finds it
    assert abs(when - 0.4111) < 2e-3


def test_smooth_peak_across_uneven_steps():
    t = np.array([0.30, 0.37, 0.407, 0.4145, 0.45, 0.52])  # steps 0.037, 0.0075, 0.0355
    peak, _ = _track(t, _bump(t))
    assert abs(peak - 1.0) < 1e-4 < 1.0 - _bump(t).max()


def kink(x):
    """A force rising, then falling three times as fast after a contact switch at 0.5."""
    return np.where(x <= 0.5, x, 0.5 - 3.0 * (x - 0.5))


def test_kink_at_a_located_switch_is_not_overshot():
    # the event location ends a step just after the switch; the next step is long again
    t = np.array([0.40, 0.47, 0.5, 0.56, 0.62])
    unflagged, _ = _track(t, kink(t))
    assert unflagged > 0.5 + 5e-4  # a parabola through a kink overshoots ...
    peak, when = _track(t, kink(t), t_switch=0.5)
    assert peak == 0.5 and when == 0.5  # ... so the switch sample is kept as it is


def test_no_parabola_across_steps_after_a_rejection():
    # a plateau, then a steep fall caught by a rejected and much shortened step: the
    # parabola through (0.4, 0.5, 0.5005) would put a peak of 1.25 at 0.45
    t = np.array([0.3, 0.4, 0.5, 0.5005, 0.51])
    f = np.array([0.9, 0.99, 1.0, 0.995, 0.9])
    peak, when = _track(t, f)
    assert peak == 1.0 and when == 0.5


def test_running_maximum_without_interior_peak():
    t = np.linspace(0.0, 1.0, 11)
    peak, when = _track(t, t**2)
    assert peak == 1.0 and when == 1.0


# ------------------------------------------------------- through update_peaks (the solvers' entry)
def _update_all(times, values, switch_times, row="wheel"):
    """Feed update_peaks with `values` in one quantity (wheel 1's force, or the chassis
    forward speed for its minimum); returns (peak, time) of that row."""
    from trackbench.model.core import indices as L
    from trackbench.solvers.common.monitor import init_peaks, update_peaks

    nw = 5
    peaks = np.zeros((L.n_peaks(nw), 6))
    diag = np.zeros(L.n_diag(nw, 30))
    init_peaks(peaks)
    for t, v in zip(times, values):
        vx = 10.0
        if row == "wheel":
            diag[L.D_WHEEL + 1] = v
        else:
            vx = v
        update_peaks(peaks, t, diag, vx, 0.0, 0.0, 0.0, t in switch_times)
    k = L.PK_WHEEL_FY if row == "wheel" else L.PK_VX_MIN
    return peaks[k, 0], peaks[k, 1]


def test_consecutive_switches_keep_the_kink():
    # two steps in a row end at located switches (0.5, then 0.53): the parabola through
    # (0.47, 0.5, 0.53) must still be skipped (it would report 0.50375 at 0.4925)
    t = np.array([0.40, 0.47, 0.5, 0.53, 0.56])
    peak, when = _update_all(t, kink(t), {0.5, 0.53})
    assert peak == 0.5 and when == 0.5


def test_minimum_is_refined_like_a_maximum():
    t = np.arange(0.0, 1.0, 0.03)
    low, when = _update_all(t, 9.0 - _bump(t), set(), row="vx")  # minimum 8 at t = 0.4111
    assert abs(low - 8.0) < 1e-4 < (9.0 - _bump(t)).min() - 8.0
    assert abs(when - 0.4111) < 2e-3
