"""Rough ground (docs/usage.md, "Terrain"): ISO 8608 random profiles
(terrain.kind = "random") and measured profiles read from a CSV file (terrain.kind =
"profile"), each as (x, height) arrays, x increasing.

A random profile is flat (height 0) over the run-in, x in [0, run_in], then rough over
x in [run_in, run_in + length]. The rough section is a sum of cosines at the wavenumbers
n_k = k / length (cycles/m) of the band 1 / wavelength_max <= n_k <= 1 / wavelength_min,

    r(x) = sum_k A_k cos(2 pi n_k (x - run_in) + phi_k),   A_k = sqrt(2 Gd(n_k) / length),

with ISO 8608's displacement PSD Gd(n) = Gd(n0) (n / n0)^-2, n0 = 0.1 cycle/m (one-sided,
m^3), and phases phi_k uniform in [0, 2 pi) from numpy's Generator(PCG64(seed)), drawn in
the order of k. Gd(n0) is the roughness class' (A .. H: 16, 64, ... 262144 x 1e-6 m^3,
the classes' geometric means), or, given rms, what makes the band's RMS, sqrt(sum_k
A_k^2 / 2), equal to it. The amplitudes are the PSD's (only the phases are random), so the
rough section's RMS over its length is that value on every seed. The section holds
whole periods of every cosine: its sample spacing is length / M, M the power of two at or
above length / dx (so between dx / 2 and dx), and the sum over k is a radix-2 FFT on that
grid written out in real arithmetic (_rough_heights), ~30 ms for 2^17 points.

The rough heights fade in over the first `blend` metres, r(x) (1 - cos(pi u)) / 2, u =
(x - run_in) / blend: height and slope are continuous where the run-in ends, so the
vehicle starts on flat ground in equilibrium and meets no step.

Bit for bit: the phases are numpy's PCG64 stream (the same on every machine for one numpy
version), the tables fixed_math's cos and sin, the sum elementwise IEEE operations in a
fixed order; no library FFT, no BLAS, no numpy transcendental."""

import math
from pathlib import Path

import numpy as np

N0 = 0.1   # cycle/m, ISO 8608's reference wavenumber
SPACING = 0.05   # m: a run's random profile sampled at most this far apart (a tenth of the
#                  shortest default wavelength; the links are 0.19 m)
BLEND = 5.0      # m: a run's random profile fades in over this much of its rough section
# NRMM states a course's roughness as the RMS elevation in inches after removing wavelengths
# longer than 60 ft (WES's detrending, as Project Chrono's RandomSurfaceTerrain.h notes it):
# with terrain.rms_in the band ends there, and rms = rms_in x 0.0254 m over the band
NRMM_WAVELENGTH_MAX = 60 * 0.3048   # m
INCH = 0.0254                       # m
CLASSES = {      # Gd(n0), m^3: the classes' geometric means
    "A": 16e-6, "B": 64e-6, "C": 256e-6, "D": 1024e-6,
    "E": 4096e-6, "F": 16384e-6, "G": 65536e-6, "H": 262144e-6,
}


def _number(name, value, low, what, strict=True):
    """A finite float of at least (strict: above) low, or a one-line ValueError."""
    ok = not isinstance(value, bool) and isinstance(value, (int, float, np.integer, np.floating))
    if ok:
        value = float(value)
        ok = math.isfinite(value) and (value > low if strict else value >= low)
    if not ok:
        raise ValueError(f"{name} = {value!r} is not allowed: expected {what}")
    return value


def rms_of(terrain):
    """The RMS elevation (m) a random terrain table asks for: rms, or NRMM's rms_in in inches
    (over its band: NRMM_WAVELENGTH_MAX unless wavelength_max is given), else None."""
    if terrain.get("rms_in") is not None:
        if terrain.get("rms") is not None:
            raise ValueError(f"rms = {terrain['rms']!r} and rms_in = {terrain['rms_in']!r} are both given: "
                             "expected one of them")
        return terrain["rms_in"] * INCH
    return terrain.get("rms")


def _seed(seed):
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed = {seed!r} is not allowed: expected an integer >= 0")
    return int(seed)


def _class_psd(roughness_class, rms):
    """Gd(n0) of the class, or None when rms sets the scale; checks that exactly one is given."""
    if roughness_class is not None and rms is not None:
        raise ValueError(
            f"roughness_class = {roughness_class!r} and rms = {rms!r} are both given: expected one of them"
        )
    if roughness_class is None and rms is None:
        raise ValueError("neither roughness_class nor rms is given: expected one of them")
    if rms is not None:
        return None
    if roughness_class not in CLASSES:
        raise ValueError(
            f"roughness_class = {roughness_class!r} is not allowed: expected one of {', '.join(CLASSES)}"
        )
    return CLASSES[roughness_class]


def _check_band(length, wavelength_min, wavelength_max, dx):
    length = _number("length", length, 0.0, "a number > 0 (m)")
    lo = _number("wavelength_min", wavelength_min, 0.0, "a number > 0 (m)")
    hi = _number("wavelength_max", wavelength_max, 0.0, "a number > 0 (m)")
    if lo >= hi:
        raise ValueError(
            f"wavelength_min = {lo!r} m is not allowed: expected below wavelength_max = {hi!r} m"
        )
    if hi > length:
        raise ValueError(
            f"wavelength_max = {hi!r} m is not allowed: expected at most length = {length!r} m "
            "(the rough section holds a whole period of its longest wave)"
        )
    dx = _number("dx", dx, 0.0, "a number > 0 (m)")
    if dx > lo / 4.0:
        raise ValueError(
            f"dx = {dx!r} m is not allowed: expected at most wavelength_min / 4 = {lo / 4.0!r} m "
            "(four points to the shortest wave)"
        )
    return length, lo, hi, dx


def _wavenumber_indices(length, wavelength_min, wavelength_max):
    """k of n_k = k / length in the band (length / wavelength rounded to 9 decimals first, so
    that a band edge on the grid is in it)."""
    first = math.ceil(round(length / wavelength_max, 9))
    last = math.floor(round(length / wavelength_min, 9))
    return np.arange(max(first, 1), last + 1, dtype=np.int64)


def _amplitudes(k, length, psd0, rms):
    """A_k = sqrt(2 Gd(n_k) / length), Gd(n_k) = psd0 (n0 length / k)^2; given rms instead,
    psd0 such that sum A_k^2 / 2 = rms^2 (the sum exact: math.fsum)."""
    inv_k = 1.0 / k.astype(np.float64)
    if psd0 is None:
        scale = rms * math.sqrt(2.0 / math.fsum((inv_k * inv_k).tolist()))
    else:
        scale = math.sqrt(2.0 * psd0 * (N0 * length) * (N0 * length) / length)
    return scale * inv_k


def _bit_reversed(m):
    """The indices 0 .. m - 1 (m a power of two) in bit-reversed order."""
    bits = m.bit_length() - 1
    i = np.arange(m, dtype=np.int64)
    rev = np.zeros(m, dtype=np.int64)
    for b in range(bits):
        rev |= ((i >> b) & 1) << (bits - 1 - b)
    return rev


def _rough_heights(k, amplitude, phase, m):
    """r_j = sum_k A_k cos(2 pi k j / m + phi_k), j = 0 .. m (m a power of two; r_m = r_0):
    the real part of sum_k c_k w^(kj), c_k = A_k e^(i phi_k), w = e^(2 pi i / m), by a radix-2
    FFT (decimation in time) written out in real arithmetic, its twiddles tabulated by
    fixed_math. Every operation is an elementwise IEEE +, - or * in a fixed order: the same
    bits on every machine (numpy's own FFT is not used: its kernels are a library's)."""
    from ..core import fixed_math as fm  # numba: loaded when first needed

    angle = (2.0 * math.pi / m) * np.arange(m // 2, dtype=np.float64)
    cos_table, sin_table = np.asarray(fm.vcos(angle)), np.asarray(fm.vsin(angle))
    re = np.zeros(m)
    im = np.zeros(m)
    re[k] = amplitude * np.asarray(fm.vcos(phase))
    im[k] = amplitude * np.asarray(fm.vsin(phase))
    order = _bit_reversed(m)
    re, im = re[order], im[order]
    size = 2
    while size <= m:
        half = size // 2
        wr = cos_table[:: m // size][:half]     # cos(2 pi j / size), j < half
        wi = sin_table[:: m // size][:half]
        re2, im2 = re.reshape(-1, size), im.reshape(-1, size)
        lr, li, rr, ri = re2[:, :half], im2[:, :half], re2[:, half:], im2[:, half:]
        tr = wr * rr - wi * ri
        ti = wr * ri + wi * rr
        re = np.concatenate([lr + tr, lr - tr], axis=1).reshape(-1)
        im = np.concatenate([li + ti, li - ti], axis=1).reshape(-1)
        size *= 2
    return np.append(re, re[0])


def _fade_in(x, blend):
    """(1 - cos(pi u)) / 2 for u = x / blend < 1, else 1."""
    from ..core import fixed_math as fm  # numba: loaded when first needed

    if blend == 0.0:
        return np.ones_like(x)
    u = np.minimum(x / blend, 1.0)
    return 0.5 - 0.5 * np.asarray(fm.vcos(math.pi * u))


def check_random(length, seed, roughness_class, rms, wavelength_min, wavelength_max, dx, run_in, blend):
    """random_profile's arguments checked (a one-line ValueError naming the culprit), without
    making the profile: (Gd(n0) or None, rms, seed, (length, wavelength_min, wavelength_max, dx),
    run_in, blend)."""
    psd0 = _class_psd(roughness_class, rms)
    if rms is not None:
        rms = _number("rms", rms, 0.0, "a number > 0 (m)")
    seed = _seed(seed)
    band = _check_band(length, wavelength_min, wavelength_max, dx)
    run_in = _number("run_in", run_in, 0.0, "a number >= 0 (m)", strict=False)
    blend = _number("blend", blend, 0.0, "a number >= 0 (m)", strict=False)
    if blend > band[0]:
        raise ValueError(f"blend = {blend!r} m is not allowed: expected at most length = {band[0]!r} m")
    return psd0, rms, seed, band, run_in, blend


def random_profile(
    length,
    seed,
    roughness_class=None,
    rms=None,
    *,
    wavelength_min=0.5,
    wavelength_max=50.0,
    dx=0.05,
    run_in=10.0,
    blend=5.0,
):
    """An ISO 8608 random profile (module docstring): (x, height) arrays (m), x from 0 over
    the flat run-in (run_in m, sampled at most dx apart) and the rough section (length m,
    sampled length / M apart, M the power of two at or above length / dx), its heights
    faded in over `blend` m.

    roughness_class ("A" .. "H") or rms (m, the band's RMS elevation): exactly one.
    wavelength_min < wavelength_max <= length (m): the band generated; dx <=
    wavelength_min / 4; run_in >= 0; 0 <= blend <= length. The same arguments give the
    same profile bit for bit; another seed another profile."""
    psd0, rms, seed, (length, lo, hi, dx), run_in, blend = check_random(
        length, seed, roughness_class, rms, wavelength_min, wavelength_max, dx, run_in, blend
    )
    k = _wavenumber_indices(length, lo, hi)
    phase = (2.0 * math.pi) * np.random.Generator(np.random.PCG64(seed)).random(k.shape[0])
    m = 2
    while m < round(length / dx, 9):    # the power of two >= length / dx: spacing <= dx
        m *= 2
    step = length / m
    local = step * np.arange(m + 1, dtype=np.float64)
    rough = _rough_heights(k, _amplitudes(k, length, psd0, rms), phase, m) * _fade_in(local, blend)

    flat = math.ceil(round(run_in / dx, 9))
    x_flat = (run_in / flat) * np.arange(flat, dtype=np.float64) if flat else np.empty(0)
    x = np.concatenate([x_flat, run_in + local])
    return x, np.concatenate([np.zeros(flat), rough])


def read_profile_csv(path):
    """A measured course (terrain.kind = "profile"): a CSV file of two columns, x and height
    (m), one point a line, x strictly increasing, at least two points; blank lines and lines
    starting with '#' are skipped, and the first line may be the header "x,height". Returns
    (x, height) float arrays; a missing or malformed file raises a one-line ValueError."""
    path = Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise ValueError(f"profile file {str(path)!r} does not exist") from None
    except (OSError, UnicodeDecodeError) as e:
        raise ValueError(f"profile file {str(path)!r} cannot be read: {e}") from None
    rows = []
    for number, line in enumerate(text.splitlines(), start=1):
        fields = [f.strip() for f in line.split(",")]
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        if not rows and [f.lower() for f in fields] == ["x", "height"]:
            continue
        rows.append(_profile_row(path, number, fields, rows[-1][1] if rows else None))
    if len(rows) < 2:
        raise ValueError(
            f"profile file {str(path)!r} has {len(rows)} point(s): expected at least 2 lines of x, height"
        )
    data = np.array([[x, h] for _, x, h in rows], dtype=np.float64)
    return data[:, 0].copy(), data[:, 1].copy()


def _profile_row(path, number, fields, previous_x):
    """(line number, x, height) of one data line, checked."""
    where = f"profile file {str(path)!r}, line {number}"
    if len(fields) != 2:
        raise ValueError(f"{where}: {len(fields)} fields: expected 2, x and height (m)")
    values = []
    for name, field in zip(("x", "height"), fields):
        try:
            v = float(field)
        except ValueError:
            v = math.nan
        if not math.isfinite(v):
            raise ValueError(f"{where}: {name} = {field!r} is not allowed: expected a finite number (m)")
        values.append(v)
    if previous_x is not None and values[0] <= previous_x:
        raise ValueError(
            f"{where}: x = {values[0]!r} after x = {previous_x!r}: expected x strictly increasing"
        )
    return number, values[0], values[1]
