"""Peak tracking at accepted steps (solvers/monitor.py): the parabola refinement finds a
smooth peak between samples, also across uneven steps, and leaves a kink at a located
contact switch alone."""

import numpy as np

from trackbench.solvers.monitor import _up


def _track(times, values, t_switch=-1.0):
    peaks = np.full((1, 6), np.nan)
    peaks[0, 0] = -np.inf
    for t, v in zip(times, values):
        _up(peaks, 0, v, t, t_switch)
    return peaks[0, 0], peaks[0, 1]


def _bump(t):
    return np.cos(7.0 * (t - 0.4111))        # peak 1 at t = 0.4111


def test_smooth_peak_is_refined_between_samples():
    t = np.arange(0.0, 1.0, 0.03)
    f = _bump(t)
    peak, when = _track(t, f)
    assert 1.0 - f.max() > 1e-3               # the samples miss the peak ...
    assert abs(peak - 1.0) < 1e-4             # ... the parabola finds it
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
    assert unflagged > 0.5 + 5e-4             # a parabola through a kink overshoots ...
    peak, when = _track(t, kink(t), t_switch=0.5)
    assert peak == 0.5 and when == 0.5        # ... so the switch sample is kept as it is


def test_no_parabola_across_steps_after_a_rejection():
    # a plateau, then a steep fall caught by a rejected and much shortened step: the
    # parabola through (0.4, 0.5, 0.5005) would put a peak of 1.25 at 0.45
    t = np.array([0.3, 0.4, 0.5, 0.5005, 0.51])
    f = np.array([0.9, 0.99, 1.0, 0.995, 0.9])
    peak, when = _track(t, f)
    assert peak == 1.0 and when == 0.5


def test_running_maximum_without_interior_peak():
    t = np.linspace(0.0, 1.0, 11)
    peak, when = _track(t, t ** 2)
    assert peak == 1.0 and when == 1.0
