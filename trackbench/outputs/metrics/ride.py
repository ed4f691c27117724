"""Ride metrics of the driver's seat (docs/validation.md, "Mobility"): what a
vertical seat acceleration a(t), sampled every dt, does to the person on the seat.

- ``peak_seat_acceleration_g``: NRMM's legacy obstacle criterion, max |a| after a 30 Hz
  Butterworth low-pass, in g;
- ``absorbed_power``: Pradko and Lee's vertical absorbed power (W);
- ``weighted_rms_acceleration``: the RMS of a after ISO 2631-1's weighting Wk (m/s^2);
- ``vdv``: the vibration dose value of the Wk-weighted a (m/s^1.75);
- ``seat_acceleration``: the seat's vertical acceleration from the chassis' motion.

The continuous filters are discretised by the bilinear transform into second-order
sections (rows b0 b1 b2 a0 a1 a2, scipy's layout; ``legacy_lowpass_sections``,
``absorbed_power_sections``, ``wk_sections``). The Butterworth sections (the 30 Hz
low-pass, Wk's 0.4 Hz high-pass and 100 Hz low-pass) are prewarped at their cut-off, so
that they are -3 dB there whatever dt. The others (Wk's acceleration-velocity transition
and upward step, the absorbed-power filter) have zeros and poles at several frequencies,
which one prewarping frequency cannot all hold: they take the plain transform, s = (2 /
dt)(z - 1)/(z + 1), as Project Chrono's ChFilters does. Its frequency warp, tan(pi f dt) /
(pi f dt) - 1, is 3.3e-5 at 31.5 Hz and 3.3e-4 at 100 Hz for the default output interval dt
= 1e-4 s; dt may be at most 1/250 s (Chrono's lowest rate for ISO 2631; Wk reaches 100 Hz).

Every section starts from rest (the seat at rest before the first sample: gravity is not in
a) and runs over the whole signal; the averages (absorbed power, weighted RMS) and the dose
(VDV) take the samples at t = i dt >= settle, so that the filters' start (Wk's 0.4 Hz
high-pass settles in ~5 s to 1e-4) and the vehicle's own start stay out of them. Which
settling time a run uses is the caller's choice (results_schema.md says it).

Bit for bit: the coefficients come from plain arithmetic and fixed_math's sin and tan;
the filters and sums are compiled loops in a fixed order (ride_metrics_jit.py); no BLAS, no
C library function, no numpy transcendental on the result's path. This module itself never
loads numba: the compiled parts are imported when a metric is first computed."""

import math

import numpy as np

G = 9.80665               # m/s^2 in one g (the spec's, and Chrono's 1 / 0.1019716213)
FT_PER_M = 3.28084        # the spec's 1 m/s^2 = 3.28084 ft/s^2 (absorbed power's input)
MIN_RATE = 250.0          # samples a second at least (dt <= 1/250 s)
# the figures over the run's second half: of a run that stopped early, the least the whole
# run's could be (ride_figures)
SECOND_HALF = ("absorbed_power", "weighted_rms_acceleration", "vdv")

LEGACY_CUTOFF = 30.0      # Hz, NRMM's obstacle criterion
LEGACY_POLES = 4          # Chrono's GetLegacyAz: ChButterworth_Lowpass(4, step, 30.0)

# ISO 2631-1 Wk (the spec's values; f in Hz)
WK_F1, WK_F2 = 0.4, 100.0                  # band limits: 2-pole Butterworth high- and low-pass
WK_F3, WK_F4, WK_Q4 = 12.5, 12.5, 0.63     # acceleration-velocity transition
WK_F5, WK_Q5, WK_F6, WK_Q6 = 2.37, 0.91, 3.35, 0.91   # upward step

# Pradko and Lee: H(s) = 14.5 s (s + 44) / ((s + 63) (s^2 + 24 s + 750)), input in ft/s^2
AP_GAIN, AP_ZERO, AP_POLE, AP_DAMP, AP_STIFF = 14.5, 44.0, 63.0, 24.0, 750.0


# ---------------------------------------------------------------- coefficients

def _bilinear(num, den, k):
    """One section (b0 b1 b2 1 a1 a2) of H(s) = (B0 + B1 s + B2 s^2) / (A0 + A1 s + A2 s^2)
    under s = k (z - 1)/(z + 1). A first-order H (B2 = A2 = 0) stays first order (b2 = a2 =
    0): carried as second order it would have a pole on the unit circle at z = -1."""
    (n0, n1, n2), (d0, d1, d2) = num, den
    if n2 == 0.0 and d2 == 0.0:
        b = (n0 + n1 * k, n0 - n1 * k, 0.0)
        a = (d0 + d1 * k, d0 - d1 * k, 0.0)
    else:
        kk = k * k
        b = (n0 + n1 * k + n2 * kk, 2.0 * (n0 - n2 * kk), n0 - n1 * k + n2 * kk)
        a = (d0 + d1 * k + d2 * kk, 2.0 * (d0 - d2 * kk), d0 - d1 * k + d2 * kk)
    return [b[0] / a[0], b[1] / a[0], b[2] / a[0], 1.0, a[1] / a[0], a[2] / a[0]]


def _butterworth(poles, fc, dt, highpass=False):
    """Sections of a Butterworth filter of an even number of poles, cut-off fc (Hz),
    prewarped: s / wc = k (z - 1)/(z + 1), k = 1 / tan(pi fc dt). Section j has the
    damping term 2 sin((2j - 1) pi / (2 poles)), lowest first (Chrono's order)."""
    from trackbench.model.core import fixed_math as fm  # numba: loaded when first needed

    k = 1.0 / fm.tan(math.pi * fc * dt)
    num = (0.0, 0.0, 1.0) if highpass else (1.0, 0.0, 0.0)
    rows = []
    for j in range(1, poles // 2 + 1):
        d = 2.0 * fm.sin((2 * j - 1) * math.pi / (2 * poles))
        rows.append(_bilinear(num, (1.0, d, 1.0), k))
    return rows


def legacy_lowpass_sections(dt):
    """The 30 Hz low-pass of ``peak_seat_acceleration_g``: 4 poles (two sections), as the
    filter of Chrono's GetLegacyAz, prewarped at 30 Hz."""
    _check_dt(dt)
    return np.array(_butterworth(LEGACY_POLES, LEGACY_CUTOFF, dt))


def absorbed_power_sections(dt):
    """Pradko and Lee's filter for an input in m/s^2 (the ft/s^2 conversion in its gain):
    FT_PER_M 14.5 / (s + 63), then s (s + 44) / (s^2 + 24 s + 750); plain bilinear."""
    _check_dt(dt)
    k = 2.0 / dt
    first = _bilinear((AP_GAIN * FT_PER_M, 0.0, 0.0), (AP_POLE, 1.0, 0.0), k)
    second = _bilinear((0.0, AP_ZERO, 1.0), (AP_STIFF, AP_DAMP, 1.0), k)
    return np.array([first, second])


def wk_sections(dt):
    """ISO 2631-1 Wk as four sections: the 0.4 Hz high-pass and 100 Hz low-pass (2-pole
    Butterworth, prewarped), the acceleration-velocity transition (1 + s/w3) / (1 + s/(Q4
    w4) + s^2/w4^2) and the upward step (1 + s/(Q5 w5) + s^2/w5^2) / (1 + s/(Q6 w6) +
    s^2/w6^2) (w5/w6)^2 (plain bilinear), in Chrono's order."""
    _check_dt(dt)
    k = 2.0 / dt
    w3, w4, w5, w6 = (2.0 * math.pi * f for f in (WK_F3, WK_F4, WK_F5, WK_F6))
    step = (w5 / w6) * (w5 / w6)
    avt = _bilinear((1.0, 1.0 / w3, 0.0), (1.0, 1.0 / (WK_Q4 * w4), 1.0 / (w4 * w4)), k)
    ups = _bilinear(
        (step, step / (WK_Q5 * w5), step / (w5 * w5)), (1.0, 1.0 / (WK_Q6 * w6), 1.0 / (w6 * w6)), k
    )
    rows = _butterworth(2, WK_F1, dt, highpass=True) + _butterworth(2, WK_F2, dt) + [avt, ups]
    return np.array(rows)


# ---------------------------------------------------------------- checks

def _number(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name} = {value!r} is not allowed: expected a number")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} = {value!r} is not allowed: expected a finite number")
    return value


def _check_dt(dt):
    dt = _number("dt", dt)
    if not 0.0 < dt <= 1.0 / MIN_RATE:
        raise ValueError(
            f"dt = {dt!r} s is not allowed: expected 0 < dt <= {1.0 / MIN_RATE:g} s "
            f"({MIN_RATE:g} samples a second at least: the weightings reach 100 Hz)"
        )
    return dt


def _signal(a):
    a = np.ascontiguousarray(a, dtype=np.float64)
    if a.ndim != 1 or a.shape[0] < 2:
        raise ValueError(f"a of shape {a.shape} is not allowed: expected a 1-D array of at least 2 samples")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise ValueError(
            f"a holds {bad.size} samples that are not finite (the first at index {bad[0]}): "
            "expected finite accelerations"
        )
    return a


def _first_sample(n, dt, settle):
    """Index of the first sample at t = i dt >= settle (settle/dt rounded to 9 decimals
    first, so that settle = 10 s, dt = 1e-4 s starts at i = 100000)."""
    settle = _number("settle", settle)
    start = math.ceil(round(settle / dt, 9)) if settle > 0.0 else 0
    if settle < 0.0 or start >= n:
        raise ValueError(
            f"settle = {settle!r} s is not allowed: expected 0 <= settle <= {(n - 1) * dt:g} s "
            f"(the last sample's time)"
        )
    return start


def _filtered(a, dt, sections, settle):
    """(the filtered signal, the first sample after settling)."""
    from trackbench.outputs.metrics.ride_jit import sos_filter  # numba: loaded when first needed

    a = _signal(a)
    dt = _check_dt(dt)
    start = _first_sample(a.shape[0], dt, settle)
    y = np.empty_like(a)
    sos_filter(np.ascontiguousarray(sections(dt)), a, y)
    return y, start


# ---------------------------------------------------------------- the metrics

def peak_seat_acceleration_g(a, dt, settle=0.0):
    """NRMM's legacy obstacle criterion (the spec's limit: 2.5 g): max |a_f| / g over the
    samples at t >= settle (default: all), a_f = a (m/s^2, gravity not included) after a
    30 Hz Butterworth low-pass from rest.

    The filter is Chrono's GetLegacyAz's (ChFilters.h/.cpp: ChButterworth_Lowpass(4, step,
    30.0)): 4 poles, as two second-order sections applied once, forward in time (no
    zero-phase pass). Chrono's differs in what lies around it: it takes the largest upward
    value (not |a|, which the spec asks for), feeds the input through its 75 Hz 4-pole
    anti-aliasing low-pass first (-0.003 dB at 30 Hz), ramps the input in over 0.2-0.5 s,
    and does not prewarp (its -3 dB point 3e-5 lower at dt = 1e-4 s)."""
    from trackbench.outputs.metrics.ride_jit import max_abs  # numba: loaded when first needed

    y, start = _filtered(a, dt, legacy_lowpass_sections, settle)
    return max_abs(y, start) / G


def legacy_lowpass(a, dt):
    """a (m/s^2) after peak_seat_acceleration_g's 30 Hz low-pass, from rest (m/s^2)."""
    return _filtered(a, dt, legacy_lowpass_sections, 0.0)[0]


def _mean_square(y, start, n=None):
    """The mean of y^2 over the samples i >= start of a signal of n samples (default: y's); y
    shorter than that (a run that stopped early): the samples it lacks count as 0, so the mean
    of the whole signal is at least this (y^2 >= 0)."""
    from trackbench.outputs.metrics.ride_jit import sum_of_squares  # numba: loaded when first needed

    n = y.shape[0] if n is None else n
    return sum_of_squares(y, start) / (n - start) if start < y.shape[0] else 0.0


def _dose(y, start, dt):
    """(sum of y^4 dt)^(1/4) over i >= start; the fourth root as two square roots (exact IEEE
    operations). 0 when y ends before start (a run that stopped early: the dose only grows)."""
    from trackbench.outputs.metrics.ride_jit import sum_of_fourth_powers  # numba: loaded when first needed

    if start >= y.shape[0]:
        return 0.0
    return math.sqrt(math.sqrt(sum_of_fourth_powers(y, start) * dt))


def ride_figures(a, dt, settle, n=None):
    """Every ride metric of one seat acceleration at once (each filter run once): a dict of
    peak_seat_acceleration_g (over the whole signal), peak_index (the sample of that peak),
    absorbed_power, weighted_rms_acceleration and vdv (over the samples at t >= settle).
    n: the samples of the whole run when a holds only its first ones (a run that stopped
    early): then the three second-half figures are the least the whole run's could be, each
    a mean or a dose of non-negative terms over which the samples it lacks count as 0 (0 when
    it stopped before settle), as the peak is the least the whole run's could be."""
    from trackbench.outputs.metrics.ride_jit import max_abs  # numba: loaded when first needed

    low = legacy_lowpass(a, dt)
    peak = max_abs(low, 0)
    n = a.shape[0] if n is None else n
    start = _first_sample(n, dt, settle)
    absorbed, _ = _filtered(a, dt, absorbed_power_sections, 0.0)
    weighted, _ = _filtered(a, dt, wk_sections, 0.0)
    return {
        "peak_seat_acceleration_g": peak / G,
        "peak_index": int(np.flatnonzero(np.abs(low) == peak)[0]),
        "absorbed_power": _mean_square(absorbed, start, n),
        "weighted_rms_acceleration": math.sqrt(_mean_square(weighted, start, n)),
        "vdv": _dose(weighted, start, dt),
    }


def absorbed_power(a, dt, settle):
    """Pradko and Lee's vertical absorbed power (W; the spec's limit: 6 W): the mean of the
    filter's output squared over the samples at t >= settle (s). The filter, H(s) = 14.5 s
    (s + 44) / ((s + 63)(s^2 + 24 s + 750)), takes a in ft/s^2 (a in m/s^2 times FT_PER_M,
    carried in its gain); plain bilinear (absorbed_power_sections). A sinusoid of 1 m/s^2
    gives 0.0417, 0.2053, 1.0558, 0.4259, 0.1048 W at 1, 2, 4, 8, 16 Hz."""
    y, start = _filtered(a, dt, absorbed_power_sections, settle)
    return _mean_square(y, start)


def weighted_rms_acceleration(a, dt, settle):
    """ISO 2631-1's weighted RMS acceleration (m/s^2): sqrt of the mean of a_w^2 over the
    samples at t >= settle (s), a_w = a after Wk (wk_sections)."""
    y, start = _filtered(a, dt, wk_sections, settle)
    return math.sqrt(_mean_square(y, start))


def vdv(a, dt, settle):
    """Vibration dose value (m/s^1.75): (sum of a_w^4 dt)^(1/4) over the samples at t >=
    settle (s), a_w = a after Wk (wk_sections). For a_w = A sin(2 pi f t) over whole periods,
    T long: (3 T / 8)^(1/4) A."""
    y, start = _filtered(a, dt, wk_sections, settle)
    return _dose(y, start, dt)


def seat_acceleration(ay, alpha, omega, seat_x, seat_y, pitch):
    """Vertical acceleration (m/s^2, y up, gravity not included) of the point fixed on the
    chassis at (seat_x, seat_y) (m, in the chassis frame from its centre of mass: x forward,
    y up), a rigid body's a_P = a_G + alpha x r - omega^2 r, r = R(pitch) (seat_x, seat_y):

        a_P,y = ay + alpha (cos(pitch) seat_x - sin(pitch) seat_y)
                   - omega^2 (sin(pitch) seat_x + cos(pitch) seat_y)

    ay: the centre of mass' vertical acceleration (m/s^2); pitch, omega, alpha: the chassis
    pitch (rad), its rate (rad/s) and acceleration (rad/s^2), counter-clockwise positive
    as q[Q_PITCH] (model/core/indices.py): with x forward, a positive pitch lifts the nose,
    and a seat ahead of the centre of mass (seat_x > 0) rises with alpha > 0. Arrays
    broadcast; a float when every argument is one."""
    from trackbench.model.core import fixed_math as fm  # numba: loaded when first needed

    ay, alpha, omega, sx, sy, pitch = np.broadcast_arrays(
        *(np.asarray(v, dtype=np.float64) for v in (ay, alpha, omega, seat_x, seat_y, pitch))
    )
    s = np.asarray(fm.vsin(pitch))
    c = np.asarray(fm.vcos(pitch))
    out = ay + alpha * (c * sx - s * sy) - omega * omega * (s * sx + c * sy)
    return float(out) if out.ndim == 0 else out
