"""The taut paths of the track: the closed loop around sprocket, idler and road wheels."""

import math

import numpy as np
import pytest

from trackbench.model.vehicle.track_path import closed_loop, closed_track, link_count


def test_loop_around_two_circles_is_a_belt():
    r, d = 0.3, 4.0  # equal circles: 2 d + 2 pi r
    _, length = closed_loop([(0.0, 0.0, r), (d, 0.0, r)])
    assert length == pytest.approx(2 * d + 2 * math.pi * r, rel=1e-6)
    r1, r2 = 0.3, 0.5  # open belt: 2 sqrt(d^2 - (r2 - r1)^2) + pi (r1 + r2) + 2 (r2 - r1) asin((r2 - r1) / d)
    exact = (
        2 * math.sqrt(d * d - (r2 - r1) ** 2) + math.pi * (r1 + r2) + 2 * (r2 - r1) * math.asin((r2 - r1) / d)
    )
    assert closed_loop([(0.0, 0.0, r1), (d, 0.0, r2)])[1] == pytest.approx(exact, rel=1e-6)


def test_pins_on_the_loop_with_equal_links():
    circles = [(2.5, 0.3, 0.31), (-2.8, 0.3, 0.26)] + [(1.3 - 0.81 * i, -0.35, 0.30) for i in range(5)]
    pins, chord = closed_track(circles, 40)
    chords = np.hypot(*np.diff(np.vstack([pins, pins[:1]]), axis=0).T)
    np.testing.assert_allclose(chords, chord, rtol=1e-6)  # every link as long, the loop closed
    for cx, cy, r in circles:
        assert np.hypot(pins[:, 0] - cx, pins[:, 1] - cy).min() > r * (1 - 1e-5)  # on the loop, not inside
    area = 0.5 * np.sum(pins[:, 0] * np.roll(pins[:, 1], -1) - np.roll(pins[:, 0], -1) * pins[:, 1])
    assert area > 0.0  # counter-clockwise


def test_link_count_for_a_tension():
    # a loop of 12.3 m of the paper's links (0.19 m, 8e6 N/m) at 80 kN: each link 0.2 m long
    assert link_count(12.3, 0.19, 8e4, 8e6) == 62
    assert link_count(12.3, 0.19, 0.0, 8e6) == 65
