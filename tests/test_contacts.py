"""Each contact case of docs/model.md against hand-computed geometry, Eq. (7), Eq. (8)."""

import numpy as np
import pytest

from trackbench.model.core import indices as L
from trackbench.model.core.bundles import arm_table, model_arrays, work_arrays
from trackbench.model.dynamics.track_loads import track_loads
from trackbench.model.ground.terrain import ground_from_points
from trackbench.model.vehicle.parameters import (
    pack,
    paper_contact,
    paper_track,
    paper_vehicle,
    station_columns,
)
from trackbench.status import CORNER_THROUGH_TRACK, WHEEL_THROUGH_TRACK

K = 1e8  # k_w = k_g of the paper
RHO = 0.30  # wheel radius 0.28 + pad 0.02
HG = 0.02


def loads(pins, wheels, ground=((-1000, 0.0), (1000, 0.0)), velocities=None, geometry="paper"):
    """Run the shared kernel on a hand-made configuration."""
    pins = np.array(pins, float)
    wheels = np.array(wheels, float).reshape(-1, 2)
    v = paper_vehicle()
    v["n_wheels"] = len(wheels)
    tr = paper_track()
    tr["n_links"] = len(pins) - 1
    par, piv, ends = pack(v, tr, 9.81, {**paper_contact(), "geometry": geometry})
    g = ground_from_points(ground)
    arms = arm_table(piv, 0.0, 0.0, station_columns(v, tr))
    m = model_arrays(par, arms, ends, g.segments, g.corners, len(pins) - 1)
    w = work_arrays(m, len(wheels), len(pins) - 1)
    w.apos[:] = pins
    w.wc[:] = wheels
    if velocities is not None:
        w.avel[:] = np.array(velocities, float)
    diag = np.zeros(L.n_diag(len(wheels), len(pins) - 1))
    track_loads(w, m, diag)
    fpin, fwheel = w.fpin.copy(), w.fwheel.copy()
    tension = diag[L.diag_tension(len(wheels)) :]
    # remove the tension pull so only contact forces remain
    for b, T in enumerate(tension):
        t = (pins[b + 1] - pins[b]) / np.linalg.norm(pins[b + 1] - pins[b])
        fpin[b] -= T * t
        fpin[b + 1] += T * t
    return fpin, fwheel, diag, tension


def straight_track(y=0.5, n=4, x0=0.38):
    """n links of exactly L0 = 0.19 m running towards -x (inner normal +y), far above ground."""
    return [[x0 - 0.19 * b, y] for b in range(n + 1)]


def test_tension_law_eq8_both_ways():
    pins = [[0.4, 1.0], [0.2, 1.0], [0.0, 1.0], [-0.2, 1.0]]
    pins[2][0] = 0.2 - 0.18  # second link 0.18 m: compressed by 0.01 m
    _, _, diag, T = loads(pins, [[5.0, 5.0]])
    assert T[0] == pytest.approx(8e6 * (0.2 - 0.19))
    assert T[1] == pytest.approx(8e6 * (0.18 - 0.19))  # negative: it pushes
    assert diag[L.D_E_TENSION] == pytest.approx(0.5 * 8e6 * (0.01**2 + 0.01**2 + (0.22 - 0.19) ** 2))


def test_wheel_on_link_eq4_and_eq7_split():
    pins = straight_track()
    w = [0.30, 0.5 + 0.29]  # above link 0 (pins 0.38 -> 0.19), s = 0.29
    fpin, fwheel, diag, _ = loads(pins, [w])
    p = K * (RHO - 0.29)
    np.testing.assert_allclose(fwheel[0], [0.0, p], atol=1e-6)
    d0, d1 = 0.38 - 0.30, 0.30 - 0.19  # from pin 0 (front) and from pin 1
    np.testing.assert_allclose(fpin[0], [0.0, -p * d1 / 0.19], atol=1e-6)
    np.testing.assert_allclose(fpin[1], [0.0, -p * d0 / 0.19], atol=1e-6)
    assert np.abs(fpin[2:]).max() < 1e-6
    assert diag[L.D_E_PAD_WHEEL] == pytest.approx(0.5 * K * (RHO - 0.29) ** 2)


def test_eq7_preserves_force_and_moment_on_a_slanted_link():
    pins = [[0.3, 0.6], [0.12, 0.54], [-0.06, 0.5], [-0.25, 0.5]]
    t = np.subtract(pins[1], pins[0])
    t /= np.linalg.norm(t)
    n = np.array([t[1], -t[0]])
    u = np.array(pins[0]) + 0.07 * t  # foot of the wheel centre on link 0
    w = u + 0.285 * n
    fpin, fwheel, _, _ = loads(pins, [w])
    p = K * (RHO - 0.285)
    np.testing.assert_allclose(fwheel[0], p * n, rtol=1e-9)
    # force: the pin shares add up to the contact force on the track
    np.testing.assert_allclose(fpin[0] + fpin[1], -p * n, rtol=1e-9)
    # moment about the contact point u is zero
    m = sum((pins[b][0] - u[0]) * fpin[b, 1] - (pins[b][1] - u[1]) * fpin[b, 0] for b in (0, 1))
    assert abs(m) < 1e-6 * p


def test_wheel_on_pin_wedge_only_when_bend_is_convex_towards_wheel():
    # bump up at pin 1 (apex towards the wheel): both links fail the foot test
    pins = [[0.19, 0.45], [0.0, 0.5], [-0.19, 0.45]]
    w = [0.0, 0.5 + 0.29]
    fpin, fwheel, _, _ = loads(pins, [w])
    p = K * (RHO - 0.29)
    np.testing.assert_allclose(fwheel[0], [0.0, p], atol=1e-6)
    np.testing.assert_allclose(fpin[1], [0.0, -p], atol=1e-6)
    # a dip (bend convex away from the wheel): the wheel centre above the pin lies on
    # both links (overlap), never in the wedge; both links push
    pins = [[0.19, 0.55], [0.0, 0.5], [-0.19, 0.55]]
    fpin, fwheel, _, _ = loads(pins, [[0.0, 0.5 + 0.29]])
    t0 = np.subtract(pins[1], pins[0]) / np.linalg.norm(np.subtract(pins[1], pins[0]))
    s = 0.29 * np.dot([0.0, 1.0], [t0[1], -t0[0]])
    assert fwheel[0, 1] == pytest.approx(2 * K * (RHO - s) * abs(t0[0]), rel=1e-9)


def test_wheel_through_track_stops_the_run():
    pins = straight_track()
    _, _, diag, _ = loads(pins, [[0.30, 0.5 - 0.05]])  # centre 5 cm below the centre line
    assert diag[L.D_STATUS] == WHEEL_THROUGH_TRACK
    _, _, diag, _ = loads(pins, [[0.30, 0.5 - 0.35]])  # far on the wrong side: no contact
    assert diag[L.D_STATUS] == 0


def test_pin_on_ground_segment_eq6():
    pins = [[0.38, 0.5], [0.19, 0.015], [0.0, 0.5]]
    fpin, _, diag, _ = loads(pins, [[5.0, 5.0]])
    np.testing.assert_allclose(fpin[1], [0.0, K * (HG - 0.015)], atol=1e-6)
    assert diag[L.D_GROUND_FY] == pytest.approx(K * (HG - 0.015))
    assert diag[L.D_CORNER_FORCE] == 0.0


def test_corner_on_link_split_and_corner_through_track():
    step = ((-1000, 0.0), (0.25, 0.0), (0.25, 0.1), (1000, 0.1))
    pins = [[0.38, 0.115], [0.19, 0.115], [0.0, 0.115]]  # link 0 spans the corner x = 0.25
    fpin, _, diag, _ = loads(pins, [[5.0, 5.0]], ground=step)
    p = K * (HG - 0.015)
    d0 = 0.38 - 0.25
    np.testing.assert_allclose(fpin[0], [0.0, p * (0.19 - d0) / 0.19], atol=1e-6)
    np.testing.assert_allclose(fpin[1], [0.0, p * d0 / 0.19], atol=1e-6)
    assert diag[L.D_CORNER_FORCE] == pytest.approx(p)
    pins = [[0.38, 0.095], [0.19, 0.095], [0.0, 0.095]]  # corner 5 mm above the centre line
    _, _, diag, _ = loads(pins, [[5.0, 5.0]], ground=step)
    assert diag[L.D_STATUS] == CORNER_THROUGH_TRACK


def test_corner_on_pin_wedge_convex_towards_ground():
    step = ((-1000, 0.0), (0.0, 0.0), (0.0, 0.1), (1000, 0.1))
    # V with its apex 5 mm left of and 12 mm above the corner: no segment foot, no link foot
    apex = np.array([-0.005, 0.112])
    pins = [apex + [0.134, 0.134], apex, apex + [-0.134, 0.134]]
    fpin, _, diag, _ = loads(pins, [[5.0, 5.0]], ground=step)
    d = apex - [0.0, 0.1]
    p = K * (HG - np.linalg.norm(d))
    np.testing.assert_allclose(fpin[1], p * d / np.linalg.norm(d), atol=1e-6)
    assert diag[L.D_CORNER_FORCE] == pytest.approx(p)


def test_pin_below_two_segments_presses_on_the_nearest_only():
    step = ((-1000, 0.0), (0.0, 0.0), (0.0, 0.1), (1000, 0.1))
    # pin past the face and under the top: s_face = -0.03, s_top = -0.01
    pins = [[0.05, 0.28], [0.03, 0.09], [0.01, 0.28]]
    fpin, _, _, _ = loads(pins, [[5.0, 5.0]], ground=step)
    np.testing.assert_allclose(fpin[1], [0.0, K * (HG + 0.01)], atol=1e-6)


def test_contact_power_matches_force_times_velocity():
    pins = straight_track()
    vel = np.zeros((len(pins), 2))
    vel[1] = [0.3, -2.0]
    fpin, fwheel, diag, _ = loads(pins, [[0.30, 0.79]], velocities=vel)
    # wheel at rest: power = force on the track . pin velocities
    assert diag[L.D_POWER] == pytest.approx(float(fpin[1] @ vel[1]), rel=1e-12)


def test_back_of_an_obstacle_does_not_push_pins_outside_the_ground():
    # a block from x = 1 to 2: a pin resting on the ground before it lies "behind" the
    # block's far face (s < 0 there) but is outside the ground: only its pad acts
    block = ((-1000, 0.0), (1.0, 0.0), (1.0, 0.05), (2.0, 0.05), (2.0, 0.0), (1000, 0.0))
    pins = [[0.6, 0.3], [0.4, 0.015], [0.2, 0.3]]
    fpin, _, diag, _ = loads(pins, [[5.0, 5.0]], ground=block)
    np.testing.assert_allclose(fpin[1], [0.0, K * (HG - 0.015)], atol=1e-6)
    # a pin inside the block (under its top, behind its far face) is pushed out of the
    # nearest surface only
    pins = [[1.9, 0.3], [1.7, 0.04], [1.5, 0.3]]
    fpin, _, _, _ = loads(pins, [[5.0, 5.0]], ground=block)
    np.testing.assert_allclose(fpin[1], [0.0, K * (HG + 0.01)], atol=1e-6)
