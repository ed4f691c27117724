"""Peak tracking at accepted steps (solvers/monitor.py): the parabola refinement finds a
smooth peak between samples and never overshoots a kink met by a located tiny step."""

import numpy as np

from trackbench.solvers.monitor import _up


def _track(times, values):
    peaks = np.full((1, 6), np.nan)
    peaks[0, 0] = -np.inf
    for t, v in zip(times, values):
        _up(peaks, 0, v, t)
    return peaks[0, 0], peaks[0, 1]


def test_smooth_peak_is_refined_between_samples():
    t = np.arange(0.0, 1.0, 0.03)
    f = np.cos(7.0 * (t - 0.4111))           # peak 1 at t = 0.4111, between samples
    sampled = f.max()
    peak, when = _track(t, f)
    assert 1.0 - sampled > 1e-3               # the samples miss the peak ...
    assert abs(peak - 1.0) < 1e-4             # ... the parabola finds it
    assert abs(when - 0.4111) < 2e-3


def test_kink_with_uneven_steps_is_not_overshot():
    # a force rising linearly and falling after a contact change at t = 0.5 (a kink):
    # the event location lands a tiny step on it, the next step is long again. A
    # parabola through those three samples would report 0.5037 at t = 0.5075.
    def f(x):
        return np.where(x <= 0.5, x, 0.5 - 3.0 * (x - 0.5))
    t = np.array([0.40, 0.47, 0.4999, 0.5000, 0.56, 0.62])
    peak, when = _track(t, f(t))
    assert peak == 0.5 and when == 0.5


def test_running_maximum_without_interior_peak():
    t = np.linspace(0.0, 1.0, 11)
    peak, when = _track(t, t ** 2)
    assert peak == 1.0 and when == 1.0
