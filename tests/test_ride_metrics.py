"""Ride metrics (trackbench/ride_metrics.py) against the spec's check values
(/work/shared/spec/mobility.md), scipy's discretisation (an independent check of the
bilinear transforms; scipy is on no result's path) and closed forms. Fast: no simulation."""

import math
import time

import numpy as np
import pytest
import scipy.signal as ss

from trackbench.outputs.metrics import ride as rm

DT = 1e-4
WK_CHECK = {1.0: 0.4825, 2.0: 0.5314, 4.0: 0.9672, 8.0: 1.0364, 16.0: 0.7687, 31.5: 0.4048}
AP_CHECK = {1.0: 0.0417, 2.0: 0.2053, 4.0: 1.0558, 8.0: 0.4259, 16.0: 0.1048}


def _response(sections, f, dt):
    return ss.sosfreqz(sections, worN=np.atleast_1d(np.asarray(f, dtype=float)), fs=1.0 / dt)[1]


def _sine(f, amplitude, settle, window, dt=DT):
    """amplitude sin(2 pi f t), t = i dt, over settle + window seconds."""
    n = round((settle + window) / dt)
    return amplitude * np.sin(2.0 * np.pi * f * dt * np.arange(n))


# ---------------------------------------------------------------- Wk


@pytest.mark.parametrize("f, check", WK_CHECK.items())
def test_wk_response_matches_the_spec(f, check):
    gain = abs(_response(rm.wk_sections(DT), f, DT)[0])
    assert gain == pytest.approx(check, rel=5e-3)


@pytest.mark.parametrize("f, check", WK_CHECK.items())
def test_wk_weighted_sinusoids(f, check):
    """A unit sinusoid, weighted, has RMS |Wk(f)| / sqrt(2): 10 s to settle (the 0.4 Hz
    high-pass), then 10 s, a whole number of periods at every check frequency."""
    measured = rm.weighted_rms_acceleration(_sine(f, 1.0, 10.0, 10.0), DT, settle=10.0) * math.sqrt(2.0)
    assert measured == pytest.approx(check, rel=5e-3)
    assert measured == pytest.approx(abs(_response(rm.wk_sections(DT), f, DT)[0]), rel=1e-6)


def _scipy_wk(dt):
    """Wk from scipy: butter for the band limits, bilinear for the other two factors."""
    fs = 1.0 / dt
    w3, w4, w5, w6 = (2 * np.pi * f for f in (12.5, 12.5, 2.37, 3.35))
    avt = ss.bilinear([1 / w3, 1.0], [1 / w4**2, 1 / (0.63 * w4), 1.0], fs=fs)
    step = (w5 / w6) ** 2
    ups = ss.bilinear(
        [step / w5**2, step / (0.91 * w5), step], [1 / w6**2, 1 / (0.91 * w6), 1.0], fs=fs
    )
    return np.vstack(
        [
            ss.butter(2, 0.4, "highpass", fs=fs, output="sos"),
            ss.butter(2, 100.0, fs=fs, output="sos"),
            ss.tf2sos(*avt),
            ss.tf2sos(*ups),
        ]
    )


@pytest.mark.parametrize("dt", [1e-4, 1e-3, 1.0 / 250.0])
def test_discretisation_agrees_with_scipy(dt):
    f = np.geomspace(0.05, 0.45 / dt, 400)
    for ours, theirs in [
        (rm.wk_sections(dt), _scipy_wk(dt)),
        (rm.legacy_lowpass_sections(dt), ss.butter(4, 30.0, fs=1 / dt, output="sos")),
        (
            rm.absorbed_power_sections(dt),
            ss.tf2sos(
                *ss.bilinear(
                    [14.5 * rm.FT_PER_M, 14.5 * rm.FT_PER_M * 44.0, 0.0],
                    np.polymul([1.0, 63.0], [1.0, 24.0, 750.0]),
                    fs=1 / dt,
                )
            ),
        ),
    ]:
        a, b = _response(ours, f, dt), _response(theirs, f, dt)
        assert np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-3)) < 1e-8


# ---------------------------------------------------------------- absorbed power


@pytest.mark.parametrize("f, check", AP_CHECK.items())
def test_absorbed_power_of_unit_sinusoids(f, check):
    power = rm.absorbed_power(_sine(f, 1.0, 2.0, 10.0), DT, settle=2.0)
    assert power == pytest.approx(check, rel=1e-2)
    gain = abs(_response(rm.absorbed_power_sections(DT), f, DT)[0])
    assert power == pytest.approx(gain * gain / 2.0, rel=1e-6)


# ---------------------------------------------------------------- the 30 Hz low-pass


@pytest.mark.parametrize("dt", [1e-4, 1e-3, 1.0 / 250.0])
def test_legacy_lowpass_is_minus_3_db_at_30_hz_and_4_poles(dt):
    db = 20 * np.log10(np.abs(_response(rm.legacy_lowpass_sections(dt), [30.0, 60.0], dt)))
    assert abs(db[0] + 10 * math.log10(2.0)) < 0.1
    if dt <= 1e-4:  # far below Nyquist: the analogue 4-pole, 10 log10(1 + 2^8) = 24.1 dB an octave up
        assert db[1] == pytest.approx(-10 * math.log10(1 + 2.0**8), abs=0.1)


def test_peak_of_a_step_is_the_4_pole_overshoot():
    """A 1 g step through the 4-pole filter peaks ~10.8 % high (a 2-pole one ~4.3 %); the
    same as scipy's sosfilt of butter(4, 30 Hz)."""
    a = np.full(20000, rm.G)
    a[0] = 0.0
    peak = rm.peak_seat_acceleration_g(a, DT)
    theirs = np.max(np.abs(ss.sosfilt(ss.butter(4, 30.0, fs=1 / DT, output="sos"), a))) / rm.G
    assert peak == pytest.approx(theirs, rel=1e-9)
    assert 1.10 < peak < 1.115
    assert rm.peak_seat_acceleration_g(-a, DT) == peak  # |a|: a downward jolt counts alike


def test_peak_of_a_slow_sinusoid_is_its_amplitude():
    a = _sine(2.0, 2.0 * rm.G, 0.0, 2.0)
    assert rm.peak_seat_acceleration_g(a, DT) == pytest.approx(2.0, rel=1e-3)


# ---------------------------------------------------------------- VDV


@pytest.mark.parametrize("f", [1.0, 4.0, 16.0])
def test_vdv_of_a_sinusoid_is_its_closed_form(f):
    """a_w = A |Wk| sin: the integral of a_w^4 over T (whole periods) is 3 T (A |Wk|)^4 / 8."""
    amplitude, settle, window = 2.0, 10.0, 10.0
    gain = abs(_response(rm.wk_sections(DT), f, DT)[0])
    expected = (3.0 * window / 8.0) ** 0.25 * amplitude * gain
    assert rm.vdv(_sine(f, amplitude, settle, window), DT, settle) == pytest.approx(expected, rel=1e-6)


# ---------------------------------------------------------------- the seat


def test_seat_at_the_centre_of_mass_moves_with_it():
    rng = np.random.default_rng(1)
    ay, alpha, omega, pitch = rng.normal(size=(4, 50))
    assert np.array_equal(rm.seat_acceleration(ay, alpha, omega, 0.0, 0.0, pitch), ay)


def test_seat_of_a_pitching_chassis_is_a_rigid_body_point():
    """The rigid-body formula to 1e-12, and the second derivative of the seat's height
    y_G + sin(theta) sx + cos(theta) sy by finite differences (the signs independently)."""
    sx, sy = 1.2, 0.9
    t = np.linspace(0.0, 2.0, 201)

    def motion(t):  # y_G, theta and their derivatives: a heave and a pitch oscillation
        yg, ay = 0.05 * np.sin(7.0 * t), -0.05 * 49.0 * np.sin(7.0 * t)
        th, om, al = 0.1 * np.sin(3.0 * t), 0.3 * np.cos(3.0 * t), -0.9 * np.sin(3.0 * t)
        return yg, ay, th, om, al

    yg, ay, th, om, al = motion(t)
    ours = rm.seat_acceleration(ay, al, om, sx, sy, th)
    formula = ay + al * (np.cos(th) * sx - np.sin(th) * sy) - om**2 * (np.sin(th) * sx + np.cos(th) * sy)
    assert np.max(np.abs(ours - formula)) < 1e-12

    h = 1e-4
    height = [g + np.sin(p) * sx + np.cos(p) * sy for g, _, p, _, _ in (motion(t + d) for d in (-h, 0, h))]
    fd = (height[0] - 2 * height[1] + height[2]) / (h * h)
    assert np.max(np.abs(ours - fd)) < 1e-5
    # nose up (alpha > 0) lifts a seat ahead of the centre of mass
    assert rm.seat_acceleration(0.0, 1.0, 0.0, 1.0, 0.0, 0.0) == 1.0


# ---------------------------------------------------------------- arguments, speed


@pytest.mark.parametrize(
    "call, fragment",
    [
        (lambda: rm.absorbed_power(np.zeros(10), 0.01, 0.0), "dt = 0.01 s is not allowed"),
        (lambda: rm.absorbed_power(np.zeros(10), -1e-4, 0.0), "dt = -0.0001 s is not allowed"),
        (lambda: rm.vdv(np.zeros(10), DT, 1.0), "settle = 1.0 s is not allowed"),
        (lambda: rm.vdv(np.zeros(10), DT, -1.0), "settle = -1.0 s is not allowed"),
        (lambda: rm.weighted_rms_acceleration(np.zeros((2, 5)), DT, 0.0), "a of shape (2, 5)"),
        (lambda: rm.peak_seat_acceleration_g(np.array([0.0, np.nan]), DT), "not finite"),
    ],
)
def test_bad_arguments_say_what_is_allowed(call, fragment):
    with pytest.raises(ValueError) as e:
        call()
    assert fragment in str(e.value) and "\n" not in str(e.value)


def test_a_minute_at_1e4_takes_well_under_a_tenth_of_a_second():
    """600,000 samples (a 60 s run at 1e-4 s): compiled loops, not Python ones (a generous
    bound: the machine is shared; the measured times are ~10 ms)."""
    a = np.random.default_rng(0).normal(size=600_000)
    for metric in (rm.absorbed_power, rm.weighted_rms_acceleration, rm.vdv):
        metric(a[:100], DT, 0.0)
        start = time.perf_counter()
        value = metric(a, DT, 10.0)
        assert time.perf_counter() - start < 0.1 and value > 0.0
    rm.peak_seat_acceleration_g(a[:100], DT)
    start = time.perf_counter()
    rm.peak_seat_acceleration_g(a, DT)
    assert time.perf_counter() - start < 0.1


def test_the_same_signal_gives_the_same_bits():
    a = np.random.default_rng(3).normal(size=50_000)
    def metrics(a):
        return [rm.vdv(a, DT, 1.0), rm.absorbed_power(a, DT, 1.0), rm.peak_seat_acceleration_g(a, DT)]

    assert [v.hex() for v in metrics(a)] == [v.hex() for v in metrics(a.copy())]


def test_a_stopped_run_gives_the_least_its_ride_figures_could_be():
    """Of a run that stopped after k of its n samples, the second-half figures are over the
    half it was to have, the samples it lacks counted as 0: never above the whole run's, never
    falling as k grows, the whole run's at k = n, 0 before the half; the peak its own."""
    t = DT * np.arange(20001)
    a = 3.0 * np.sin(2 * np.pi * 4.0 * t) + 1.5 * np.sin(2 * np.pi * 11.0 * t + 0.3) * (t > 1.2)
    n, settle = a.size, 0.5 * (a.size - 1) * DT
    whole = rm.ride_figures(a, DT, settle)
    keys = ("absorbed_power", "weighted_rms_acceleration", "vdv")
    last = dict.fromkeys(keys, 0.0)
    for k in (5000, 10000, 10001, 12000, 15000, 19999, 20001):
        part = rm.ride_figures(a[:k], DT, settle, n)
        for key in keys:
            assert 0.0 <= part[key] <= whole[key] and part[key] >= last[key], (k, key)
            last[key] = part[key]
        if k <= 10000:
            assert all(part[key] == 0.0 for key in keys)
        assert part["peak_seat_acceleration_g"] == rm.peak_seat_acceleration_g(a[:k], DT)
    assert all(last[key] == whole[key] for key in keys)
    assert rm.ride_figures(a[:15000], DT, settle, n)["absorbed_power"] > 0.5 * whole["absorbed_power"]
