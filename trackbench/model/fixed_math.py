"""Elementary functions that round the same on every machine.

numba's ``math.sin`` and friends call the C library, and glibc picks an implementation of
sin, cos, exp, log, atan2, pow, ... by CPU at load time (FMA or not), which differ in the
last bit for a small share of arguments; a chaotic simulation then diverges between
machines. The functions here are ports of the fdlibm / FreeBSD msun algorithms written
with plain IEEE double operations only (+ - * / sqrt, exact bit manipulation, no FMA, no
fastmath) in a fixed order, so they give the same bits on every x86-64 and ARM machine.

Algorithms and coefficients: fdlibm 5.3 and FreeBSD msun (k_sin, k_cos, k_tan,
e_rem_pio2, e_exp, s_expm1, s_atan, e_atan2, e_asin, e_acos, e_hypot), which carry this
notice: "Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved. Developed at
SunSoft, a Sun Microsystems, Inc. business. Permission to use, copy, modify, and
distribute this software is freely granted, provided that this notice is preserved."
The code is ours. Where it departs from fdlibm (atan2's quotient, the order of
evaluation in exp) the function's docstring says so. log is a table of 182 cells and a
short series (the table from decimal arithmetic at import), pow is exp(y log x) carried
in double-double; the reduction of huge arguments of sin, cos, tan (|x| >= 2^20 pi/2, up
to the largest double) is our own Payne-Hanek variant on fdlibm's table of 2/pi.
Nothing here allocates, so every function may be called from functions compiled without
numba's runtime (jit.BORROW).

Conventions are those of C (and of numba's ``math`` in compiled code): nothing raises;
an invalid argument (sin(inf), log(-1), asin(2), pow(-2, y)) gives a NaN with fixed
bits (0x7ff8000000000000, the same on x86 and ARM), a NaN argument is returned as it
is, overflow gives inf, log(0) = -inf, pow(0, -1) = inf; signed zeros and atan2 on the
axes as C99. ``pow`` takes x >= 0 only (no result of the model raises a negative number
to a power). The array versions (vsin, ..., vsincos: one compiled loop behind them all)
give the same bits as the scalar ones.

Accuracy, max error in ulp against mpmath at 200 bits (10^6 random arguments per range;
log and pow 10^4): sin 0.77, cos 0.76 (|x| < 10, < 1e4, 1e6 .. 1e300, next to multiples of
pi/2), tan 0.85, atan 0.84, asin 0.88, acos 0.90 (on [-1, 1]), exp 0.88 (-700 .. 700),
expm1 0.83 (0.50 for |x| < 1e-3), log 0.50 (1e-300 .. 1e300 and subnormals), atan2 0.83
(all quadrants), hypot 0.88, pow 0.79 (x 1e-8 .. 1e8 with |y| < 3, x 1e-300 .. 1e300).

Speed, ns a call in a compiled loop, warm, against glibc through numba's math.* (in
brackets): sin 16 (15), cos 16 (15), sincos 17 (19 for both), tan 19 (16), atan 6.5 (7.4),
asin 5.4 (9.6), acos 7.2 (9.9), exp 3.3 (2.9), expm1 12 (10), log 6.7 (2.9), atan2 20 (17),
hypot 9.4 (13), pow 14 (8.3): glibc's log and pow use FMA and larger tables.
"""

import math
import struct
from fractions import Fraction

import numpy as np
from numba import njit

from .jit import INLINE, KERNEL, SCALAR

__all__ = [
    "sin", "cos", "tan", "sincos", "atan", "atan2", "asin", "acos",
    "exp", "expm1", "log", "pow", "hypot",
    "vsin", "vcos", "vtan", "vsincos", "vatan", "vatan2", "vasin", "vacos",
    "vexp", "vexpm1", "vlog", "vpow", "vhypot",
]


def _w(hi, lo=0):
    """The double whose high and low 32-bit words are hi and lo."""
    return struct.unpack("<d", struct.pack("<Q", (hi << 32) | lo))[0]


_NAN = _w(0x7FF80000)          # the one NaN made here (x86 and ARM would differ in sign)
_INF = _w(0x7FF00000)
_TWO24 = 16777216.0
_TWOM1021 = _w(0x00200000)
_TWO54 = _w(0x43500000)
_TWOM1000 = _w(0x01700000)     # 2^-1000
_TWO1023 = _w(0x7FE00000)
_PIO2_HI = _w(0x3FF921FB, 0x54442D18)
_PIO2_LO = _w(0x3C91A626, 0x33145C07)
_PIO4_HI = _w(0x3FE921FB, 0x54442D18)
_PIO4_LO = _w(0x3C81A626, 0x33145C07)
_PI = _w(0x400921FB, 0x54442D18)
_PI_LO = _w(0x3CA1A626, 0x33145C07)


# ---------------------------------------------------------------- bits of a double
@njit(**INLINE)
def _bits(x):
    return np.float64(x).view(np.int64)


@njit(**INLINE)
def _double(b):
    return np.int64(b).view(np.float64)


@njit(**INLINE)
def _high(x):
    """High word, sign-extended (fdlibm's int32_t hx)."""
    return np.float64(x).view(np.int64) >> 32


@njit(**INLINE)
def _low(x):
    return np.float64(x).view(np.int64) & 0xFFFFFFFF


@njit(**INLINE)
def _words(hi, lo):
    return np.int64(((hi & 0xFFFFFFFF) << 32) | lo).view(np.float64)


@njit(**INLINE)
def _set_high(x, hi):
    return np.int64(((hi & 0xFFFFFFFF) << 32) | (np.float64(x).view(np.int64) & 0xFFFFFFFF)).view(np.float64)


@njit(**INLINE)
def _clear_low(x):
    """x with its low word zeroed (fdlibm's SET_LOW_WORD(x, 0))."""
    return np.int64(np.float64(x).view(np.int64) & -4294967296).view(np.float64)


@njit(**INLINE)
def _scale_subnormal(z, n):
    """z * 2^n rounded once, for z ~ 1 and -1100 < n <= -1022 (a subnormal result)."""
    return (z * _words(0x3FF00000 + ((n + 200) << 20), 0)) * _words(0x33700000, 0)   # * 2^-200


# ---------------------------------------------------------------- pi/2 reduction
_INVPIO2 = _w(0x3FE45F30, 0x6DC9C883)
_PIO2_1 = _w(0x3FF921FB, 0x54400000)    # first 33 bits of pi/2
_PIO2_1T = _w(0x3DD0B461, 0x1A626331)   # pi/2 - _PIO2_1
_PIO2_2 = _w(0x3DD0B461, 0x1A600000)    # second 33 bits
_PIO2_2T = _w(0x3BA3198A, 0x2E037073)
_PIO2_3 = _w(0x3BA3198A, 0x2E000000)    # third 33 bits
_PIO2_3T = _w(0x397B839A, 0x252049C1)
_TOINT = 1.5 * 2.0 ** 52
_2PIO2_1, _2PIO2_1T = 2 * _PIO2_1, 2 * _PIO2_1T
_3PIO2_1, _3PIO2_1T = 3 * _PIO2_1, 3 * _PIO2_1T
_4PIO2_1, _4PIO2_1T = 4 * _PIO2_1, 4 * _PIO2_1T

# fdlibm's 2/pi in 24-bit digits: 2/pi = sum ipio2[i] * 2^(-24 (i+1)); enough for doubles.
_IPIO2 = np.array([
    0xA2F983, 0x6E4E44, 0x1529FC, 0x2757D1, 0xF534DD, 0xC0DB62,
    0x95993C, 0x439041, 0xFE5163, 0xABDEBB, 0xC561B7, 0x246E3A,
    0x424DD2, 0xE00649, 0x2EEA09, 0xD1921C, 0xFE1DEB, 0x1CB129,
    0xA73EE8, 0x8235F5, 0x2EBB44, 0x84E99C, 0x7026B4, 0x5F7E41,
    0x3991D6, 0x398353, 0x39F49C, 0x845F8B, 0xBDF928, 0x3B1FF8,
    0x97FFDE, 0x05980F, 0xEF2F11, 0x8B5A0A, 0x6D1F6D, 0x367ECF,
    0x27CB09, 0xB74F46, 0x3F669E, 0x5FEA2D, 0x7527BA, 0xC7EBE5,
    0xF17B3D, 0x0739F7, 0x8A5292, 0xEA6BFB, 0x5FB11F, 0x8D5D08,
    0x560330, 0x46FC7B, 0x6BABF0, 0xCFBC20, 0x9AF436, 0x1DA9E3,
    0x91615E, 0xE61B08, 0x659985, 0x5F14A0, 0x68408D, 0xFFD880,
    0x4D7327, 0x310606, 0x1556CA, 0x73A8C9, 0x60E27B, 0xC08C6B,
], dtype=np.int64)
_NDIGITS = 9    # 24-bit digits kept below the top one: the fraction to ~2^-190 (need ~2^-130)


@njit(**SCALAR)
def _pio2_digit(k, t0, t1, t2):
    """Coefficient k of x * 2/pi in base 2^24 (x = t0 + t1 2^-24 + t2 2^-48, 24-bit
    integers t): sum t_a ipio2[k - a], exact (< 2^50)."""
    s = t0 * _IPIO2[k]
    if k >= 1:
        s += t1 * _IPIO2[k - 1]
    if k >= 2:
        s += t2 * _IPIO2[k - 2]
    return s


@njit(**SCALAR)
def _rem_pio2_large(x):
    """(n, y0, y1) with x = n pi/2 + y0 + y1, |y0| <= pi/4, for finite |x| >= 2^20.

    |x| = (t0 + t1 2^-24 + t2 2^-48) 2^e0 with 24-bit integers t; x 2/pi is then a sum of
    exact integer digits Q_k 2^(e0 - 24 (k+1)). The digits below jv are multiples of 8 and
    are skipped; carrying the next ones in base 2^24 gives the integer part mod 8 and the
    fraction, exactly, to 2^-190 (the closest double to a multiple of pi/2 is 2^-61 away).
    The fraction, summed smallest digit first in double-double, times pi/2 in
    double-double, gives y0 + y1."""
    ax = abs(x)
    e0 = ((_bits(ax) >> 52) & 0x7FF) - 1023 - 23
    z = _double(_bits(ax) - (e0 << 52))     # |x| 2^-e0, in [2^23, 2^24)
    t0 = np.int64(z)
    z = (z - t0) * _TWO24
    t1 = np.int64(z)
    z = (z - t1) * _TWO24
    t2 = np.int64(z)
    jv = (e0 - 3) // 24
    if jv < 0:
        jv = 0
    q0 = e0 - 24 * (jv + 1)                 # weight of digit jv is 2^q0, -27 <= q0 <= 2
    p = 24 - q0                             # fraction bits in the top value below

    c = np.int64(0)                         # pass 1: carry into digit 1
    for m in range(_NDIGITS, 1, -1):
        c = (_pio2_digit(jv + m, t0, t1, t2) + c) >> 24
    v = _pio2_digit(jv + 1, t0, t1, t2) + c
    d1 = v & 0xFFFFFF
    d0 = _pio2_digit(jv, t0, t1, t2) + (v >> 24)
    top = ((d0 & ((np.int64(1) << (3 - q0)) - 1)) << 24) | d1   # (x 2/pi mod 8) 2^p, truncated
    n = top >> p
    f1 = top & ((np.int64(1) << p) - 1)
    neg = (f1 >> (p - 1)) & 1               # fraction >= 1/2: use fraction - 1
    if neg:
        n += 1
        f1 = ((np.int64(1) << p) - 1) - f1

    # pass 2: the fraction (or 1 - fraction, digit by digit complemented) as hi + lo
    scale = _words(0x3FF00000 - ((p + 24 * (_NDIGITS - 1)) << 20), 0)
    hi = scale if neg else 0.0              # the +1 of the complement, at the last digit
    lo = 0.0
    c = np.int64(0)
    for m in range(_NDIGITS, 1, -1):
        v = _pio2_digit(jv + m, t0, t1, t2) + c
        c = v >> 24
        d = v & 0xFFFFFF
        if neg:
            d = 0xFFFFFF - d
        term = np.float64(d) * scale
        s = hi + term
        bb = s - hi
        lo += (hi - (s - bb)) + (term - bb)
        hi = s
        scale *= _TWO24
    term = np.float64(f1) * _words(0x3FF00000 - (p << 20), 0)
    s = hi + term
    bb = s - hi
    lo += (hi - (s - bb)) + (term - bb)
    fh = s + lo
    fl = lo - (fh - s)

    # times pi/2 (Dekker's exact product: no FMA)
    cs = 134217729.0 * fh
    ah = cs - (cs - fh)
    al = fh - ah
    cs = 134217729.0 * _PIO2_HI
    bh = cs - (cs - _PIO2_HI)
    bl = _PIO2_HI - bh
    ph = fh * _PIO2_HI
    pl = ((ah * bh - ph) + ah * bl + al * bh) + al * bl
    pl += fh * _PIO2_LO + fl * _PIO2_HI
    y0 = ph + pl
    y1 = pl - (y0 - ph)
    if neg:
        y0 = -y0
        y1 = -y1
    if x < 0.0:
        return -n, -y0, -y1
    return n, y0, y1


@njit(**SCALAR)
def _rem_pio2_medium(x, ix):
    """Cody-Waite with 33+33+33 bits of pi/2, good for |x| < 2^20 pi/2 (fdlibm)."""
    fn = (x * _INVPIO2 + _TOINT) - _TOINT
    n = np.int64(fn)
    r = x - fn * _PIO2_1
    w = fn * _PIO2_1T                       # first round good to 85 bits
    j = ix >> 20
    y0 = r - w
    i = j - ((_high(y0) >> 20) & 0x7FF)
    if i > 16:                              # second round, good to 118 bits
        t = r
        w = fn * _PIO2_2
        r = t - w
        w = fn * _PIO2_2T - ((t - r) - w)
        y0 = r - w
        i = j - ((_high(y0) >> 20) & 0x7FF)
        if i > 49:                          # third round, 151 bits
            t = r
            w = fn * _PIO2_3
            r = t - w
            w = fn * _PIO2_3T - ((t - r) - w)
            y0 = r - w
    y1 = (r - y0) - w
    return n, y0, y1


@njit(**SCALAR)
def _rem_pio2(x, hx):
    """(n, y0, y1): x = n pi/2 + y0 + y1, |y0| <= pi/4 (about); x finite, |x| > pi/4.
    hx is the high word of x."""
    ix = hx & 0x7FFFFFFF
    if ix <= 0x400F6A7A:                    # |x| ~<= 5pi/4
        if (ix & 0xFFFFF) == 0x921FB:       # |x| ~= pi/2 or 2pi/2: cancellation
            return _rem_pio2_medium(x, ix)
        if ix <= 0x4002D97C:                # |x| ~<= 3pi/4
            if hx > 0:
                z = x - _PIO2_1
                y0 = z - _PIO2_1T
                return 1, y0, (z - y0) - _PIO2_1T
            z = x + _PIO2_1
            y0 = z + _PIO2_1T
            return -1, y0, (z - y0) + _PIO2_1T
        if hx > 0:
            z = x - _2PIO2_1
            y0 = z - _2PIO2_1T
            return 2, y0, (z - y0) - _2PIO2_1T
        z = x + _2PIO2_1
        y0 = z + _2PIO2_1T
        return -2, y0, (z - y0) + _2PIO2_1T
    if ix <= 0x401C463B:                    # |x| ~<= 9pi/4
        if ix <= 0x4015FDBC:                # |x| ~<= 7pi/4
            if ix == 0x4012D97C:            # |x| ~= 3pi/2
                return _rem_pio2_medium(x, ix)
            if hx > 0:
                z = x - _3PIO2_1
                y0 = z - _3PIO2_1T
                return 3, y0, (z - y0) - _3PIO2_1T
            z = x + _3PIO2_1
            y0 = z + _3PIO2_1T
            return -3, y0, (z - y0) + _3PIO2_1T
        if ix == 0x401921FB:                # |x| ~= 4pi/2
            return _rem_pio2_medium(x, ix)
        if hx > 0:
            z = x - _4PIO2_1
            y0 = z - _4PIO2_1T
            return 4, y0, (z - y0) - _4PIO2_1T
        z = x + _4PIO2_1
        y0 = z + _4PIO2_1T
        return -4, y0, (z - y0) + _4PIO2_1T
    if ix < 0x413921FB:                     # |x| ~< 2^20 pi/2
        return _rem_pio2_medium(x, ix)
    return _rem_pio2_large(x)


# ---------------------------------------------------------------- sin, cos, tan kernels
_S1 = _w(0xBFC55555, 0x55555549)
_S2 = _w(0x3F811111, 0x1110F8A6)
_S3 = _w(0xBF2A01A0, 0x19C161D5)
_S4 = _w(0x3EC71DE3, 0x57B1FE7D)
_S5 = _w(0xBE5AE5E6, 0x8A2B9CEB)
_S6 = _w(0x3DE5D93A, 0x5ACFD57C)
_C1 = _w(0x3FA55555, 0x5555554C)
_C2 = _w(0xBF56C16C, 0x16C15177)
_C3 = _w(0x3EFA01A0, 0x19CB1590)
_C4 = _w(0xBE927E4F, 0x809C52AD)
_C5 = _w(0x3E21EE9E, 0xBDB4B1C4)
_C6 = _w(0xBDA8FAE9, 0xBE8838D4)
_T0 = _w(0x3FD55555, 0x55555563)
_T1 = _w(0x3FC11111, 0x1110FE7A)
_T2 = _w(0x3FABA1BA, 0x1BB341FE)
_T3 = _w(0x3F9664F4, 0x8406D637)
_T4 = _w(0x3F8226E3, 0xE96E8493)
_T5 = _w(0x3F6D6D22, 0xC9560328)
_T6 = _w(0x3F57DBC8, 0xFEE08315)
_T7 = _w(0x3F4344D8, 0xF2F26501)
_T8 = _w(0x3F3026F7, 0x1A8D1068)
_T9 = _w(0x3F147E88, 0xA03792A6)
_T10 = _w(0x3F12B80F, 0x32F0A7E9)
_T11 = _w(0xBEF375CB, 0xDB605373)
_T12 = _w(0x3EFB2A70, 0x74BF7AD4)


@njit(**SCALAR)
def _k_sin(x, y):
    """sin(x + y) on ~[-pi/4, pi/4], y the tail of x (fdlibm __kernel_sin, iy = 1)."""
    z = x * x
    w = z * z
    r = _S2 + z * (_S3 + z * _S4) + z * w * (_S5 + z * _S6)
    v = z * x
    return x - ((z * (0.5 * y - v * r) - y) - v * _S1)


@njit(**SCALAR)
def _k_sin0(x):
    """sin(x) on ~[-pi/4, pi/4] (fdlibm __kernel_sin, iy = 0)."""
    z = x * x
    w = z * z
    r = _S2 + z * (_S3 + z * _S4) + z * w * (_S5 + z * _S6)
    v = z * x
    return x + v * (_S1 + z * r)


@njit(**SCALAR)
def _k_cos(x, y):
    """cos(x + y) on ~[-pi/4, pi/4] (fdlibm __kernel_cos)."""
    z = x * x
    w = z * z
    r = z * (_C1 + z * (_C2 + z * _C3)) + w * w * (_C4 + z * (_C5 + z * _C6))
    hz = 0.5 * z
    w = 1.0 - hz
    return w + (((1.0 - w) - hz) + (z * r - x * y))


@njit(**SCALAR)
def _k_tan(x, y, iy):
    """tan(x + y) (iy = 1) or -1/tan(x + y) (iy = -1) on ~[-pi/4, pi/4] (fdlibm 2004
    __kernel_tan)."""
    hx = _high(x)
    ix = hx & 0x7FFFFFFF
    big = ix >= 0x3FE59428                  # |x| >= 0.6744
    if big:
        if hx < 0:
            x = -x
            y = -y
        z = _PIO4_HI - x
        w = _PIO4_LO - y
        x = z + w
        y = 0.0
    z = x * x
    w = z * z
    r = _T1 + w * (_T3 + w * (_T5 + w * (_T7 + w * (_T9 + w * _T11))))
    v = z * (_T2 + w * (_T4 + w * (_T6 + w * (_T8 + w * (_T10 + w * _T12)))))
    s = z * x
    r = y + z * (s * (r + v) + y)
    r += _T0 * s
    w = x + r
    if big:
        v = np.float64(iy)
        return np.float64(1 - ((hx >> 30) & 2)) * (v - 2.0 * (x - (w * w / (w + v) - r)))
    if iy == 1:
        return w
    z = _clear_low(w)                       # -1/(x + r) accurately
    v = r - (z - x)
    a = -1.0 / w
    t = _clear_low(a)
    s = 1.0 + t * z
    return t + a * (s + t * v)


# ---------------------------------------------------------------- sin, cos, tan, sincos
@njit(**SCALAR)
def sin(x):
    """sin(x); error < 1 ulp for all finite x; sin(+-inf) = NaN."""
    hx = _high(x)
    ix = hx & 0x7FFFFFFF
    if ix <= 0x3FE921FB:                    # |x| ~<= pi/4
        if ix < 0x3E500000:                 # |x| < 2^-26 (and +-0)
            return x
        return _k_sin0(x)
    if ix >= 0x7FF00000:
        return x if x != x else _NAN
    n, y0, y1 = _rem_pio2(x, hx)
    q = n & 3
    if q == 0:
        return _k_sin(y0, y1)
    if q == 1:
        return _k_cos(y0, y1)
    if q == 2:
        return -_k_sin(y0, y1)
    return -_k_cos(y0, y1)


@njit(**SCALAR)
def cos(x):
    """cos(x); error < 1 ulp for all finite x; cos(+-inf) = NaN."""
    hx = _high(x)
    ix = hx & 0x7FFFFFFF
    if ix <= 0x3FE921FB:
        if ix < 0x3E46A09E:                 # |x| < 2^-27 sqrt(2)
            return 1.0
        return _k_cos(x, 0.0)
    if ix >= 0x7FF00000:
        return x if x != x else _NAN
    n, y0, y1 = _rem_pio2(x, hx)
    q = n & 3
    if q == 0:
        return _k_cos(y0, y1)
    if q == 1:
        return -_k_sin(y0, y1)
    if q == 2:
        return -_k_cos(y0, y1)
    return _k_sin(y0, y1)


@njit(**SCALAR)
def sincos(x):
    """(sin(x), cos(x)) with one argument reduction; the same bits as sin(x), cos(x)."""
    hx = _high(x)
    ix = hx & 0x7FFFFFFF
    if ix <= 0x3FE921FB:
        if ix < 0x3E46A09E:
            return x, 1.0                   # 2^-27 sqrt(2) < 2^-26: sin is x as well
        if ix < 0x3E500000:
            return x, _k_cos(x, 0.0)
        return _k_sin0(x), _k_cos(x, 0.0)
    if ix >= 0x7FF00000:
        nan = x if x != x else _NAN
        return nan, nan
    n, y0, y1 = _rem_pio2(x, hx)
    s = _k_sin(y0, y1)
    c = _k_cos(y0, y1)
    q = n & 3
    if q == 0:
        return s, c
    if q == 1:
        return c, -s
    if q == 2:
        return -s, -c
    return -c, s


@njit(**SCALAR)
def tan(x):
    """tan(x); error < 1 ulp for all finite x; tan(+-inf) = NaN."""
    hx = _high(x)
    ix = hx & 0x7FFFFFFF
    if ix <= 0x3FE921FB:
        if ix < 0x3E400000:                 # |x| < 2^-27
            return x
        return _k_tan(x, 0.0, 1)
    if ix >= 0x7FF00000:
        return x if x != x else _NAN
    n, y0, y1 = _rem_pio2(x, hx)
    return _k_tan(y0, y1, 1 - ((n & 1) << 1))


# ---------------------------------------------------------------- exp, expm1
_O_THRESHOLD = _w(0x40862E42, 0xFEFA39EF)    # 709.78...
_U_THRESHOLD = _w(0xC0874910, 0xD52D3051)    # -745.13...
_LN2_HI = _w(0x3FE62E42, 0xFEE00000)
_LN2_LO = _w(0x3DEA39EF, 0x35793C76)
_INVLN2 = _w(0x3FF71547, 0x652B82FE)
_P1 = _w(0x3FC55555, 0x5555553E)
_P2 = _w(0xBF66C16C, 0x16BEBD93)
_P3 = _w(0x3F11566A, 0xAF25DE2C)
_P4 = _w(0xBEBBBD41, 0xC5D26BF1)
_P5 = _w(0x3E663769, 0x72BEA4D0)
_E = _w(0x4005BF0A, 0x8B145769)             # e, correctly rounded


@njit(**INLINE)
def _exp_tail(x, tail):
    """e^(x + tail) for |tail| below an ulp of x (exp, and pow's y log x in double-double);
    error < 1 ulp; overflow gives inf, underflow 0. fdlibm's e_exp, with k (x = k
    ln2 + r) rounded by adding 1.5 2^52 (ties to even instead of away from 0: |r| may
    exceed ln2/2 by an ulp, well inside the approximation's range) and its polynomial
    evaluated in Estrin's order: 40 % faster, still < 1 ulp."""
    hx = _high(x)
    ax = hx & 0x7FFFFFFF
    if ax >= 0x40862E42:                    # |x| >= 709.78...
        if ax >= 0x7FF00000:
            if x != x:
                return x
            return x if hx >= 0 else 0.0    # exp(+-inf) = inf, 0
        if x > _O_THRESHOLD:
            return _INF
        if x < _U_THRESHOLD:
            return 0.0
    elif ax < 0x3E300000:                   # |x| < 2^-28
        return 1.0 + (x + tail)
    if x == 1.0 and tail == 0.0:
        return _E                           # correctly rounded (the formula gives e + 1 ulp)
    kf = (x * _INVLN2 + _TOINT) - _TOINT    # nearest integer to x / ln2
    k = np.int64(kf)
    hi = x - kf * _LN2_HI                   # exact
    lo = kf * _LN2_LO - tail
    r = hi - lo
    t = r * r
    t2 = t * t
    c = r - t * ((_P1 + t * _P2) + t2 * ((_P3 + t * _P4) + t2 * _P5))
    y = 1.0 - ((lo - (r * c) / (2.0 - c)) - hi)
    if k >= -1021:
        if k == 1024:
            return y * 2.0 * _TWO1023
        return y * _words(0x3FF00000 + (k << 20), 0)
    return y * _words(0x3FF00000 + ((k + 1000) << 20), 0) * _TWOM1000


@njit(**SCALAR)
def exp(x):
    """e^x; error < 1 ulp; overflow gives inf, underflow 0."""
    return _exp_tail(x, 0.0)


_Q1 = _w(0xBFA11111, 0x111110F4)
_Q2 = _w(0x3F5A01A0, 0x19FE5585)
_Q3 = _w(0xBF14CE19, 0x9EAADBB7)
_Q4 = _w(0x3ED0CFCA, 0x86E65239)
_Q5 = _w(0xBE8AFDB7, 0x6E09C32D)


@njit(**SCALAR)
def expm1(x):
    """e^x - 1, accurate near 0; error < 1 ulp (fdlibm s_expm1)."""
    hx = _high(x)
    xsb = hx & 0x80000000
    hx &= 0x7FFFFFFF
    if hx >= 0x4043687A:                    # |x| >= 56 ln2
        if hx >= 0x40862E42:                # |x| >= 709.78...
            if hx >= 0x7FF00000:
                if x != x:
                    return x
                return x if xsb == 0 else -1.0
            if x > _O_THRESHOLD:
                return _INF
        if xsb != 0:
            return -1.0
    c = 0.0
    k = 0
    if hx > 0x3FD62E42:                     # |x| > 0.5 ln2
        if hx < 0x3FF0A2B2:                 # and |x| < 1.5 ln2
            if xsb == 0:
                hi = x - _LN2_HI
                lo = _LN2_LO
                k = 1
            else:
                hi = x + _LN2_HI
                lo = -_LN2_LO
                k = -1
        else:
            k = np.int64(_INVLN2 * x + (0.5 if xsb == 0 else -0.5))
            t = np.float64(k)
            hi = x - t * _LN2_HI
            lo = t * _LN2_LO
        x = hi - lo
        c = (hi - x) - lo
    elif hx < 0x3C900000:                   # |x| < 2^-54 (and +-0)
        return x
    hfx = 0.5 * x
    hxs = x * hfx
    r1 = 1.0 + hxs * (_Q1 + hxs * (_Q2 + hxs * (_Q3 + hxs * (_Q4 + hxs * _Q5))))
    t = 3.0 - r1 * hfx
    e = hxs * ((r1 - t) / (6.0 - x * t))
    if k == 0:
        return x - (x * e - hxs)
    e = x * (e - c) - c
    e -= hxs
    if k == -1:
        return 0.5 * (x - e) - 0.5
    if k == 1:
        if x < -0.25:
            return -2.0 * (e - (x + 0.5))
        return 1.0 + 2.0 * (x - e)
    if k <= -2 or k > 56:                   # exp(x) - 1 suffices
        y = 1.0 - (e - x)
        if k == 1024:
            y = y * 2.0 * _TWO1023
        else:
            y = y * _words(0x3FF00000 + (k << 20), 0)
        return y - 1.0
    if k < 20:
        t = _words(0x3FF00000 - (0x200000 >> k), 0)     # 1 - 2^-k
        y = t - (e - x)
        return y * _words(0x3FF00000 + (k << 20), 0)
    t = _words((0x3FF - k) << 20, 0)                    # 2^-k
    y = x - (e + t)
    y += 1.0
    return y * _words(0x3FF00000 + (k << 20), 0)


# ---------------------------------------------------------------- log
def _log_table():
    """c_j = 1 + j/256 for the cells of z in [sqrt(2)/2, sqrt(2)) (j = -75 .. 106), 1/c_j
    rounded, and log(c_j) as hi + lo with hi a multiple of 2^-32 (so that k ln2_hi + hi is
    exact), both from decimal arithmetic at 50 digits, correctly rounded to double: the same
    table on every machine."""
    from decimal import Decimal, localcontext
    cell, inv, hi, lo = [], [], [], []
    with localcontext() as ctx:
        ctx.prec = 50
        for j in range(_J_MIN, _J_MAX + 1):
            cj = 1.0 + j / 256.0
            ln = Decimal(cj).ln()
            h = float(round(ln * 2 ** 32)) / 2 ** 32
            cell.append(cj)
            inv.append(1.0 / cj)
            hi.append(h)
            lo.append(float(ln - Decimal(h)))
    return np.array(cell), np.array(inv), np.array(hi), np.array(lo)


_J_MIN = -75
_J_MAX = 106
_CELL, _INVC, _LOGC_HI, _LOGC_LO = _log_table()
_LN2_HI32 = _w(0x3FE62E42, 0xFEE00000)      # ln 2 to 32 bits: k ln2_hi exact for |k| < 2^21
_LN2_LO32 = _w(0x3DEA39EF, 0x35793C76)
_L3 = 1.0 / 3.0
_L5 = 1.0 / 5.0
_L6 = -1.0 / 6.0
_L7 = 1.0 / 7.0


@njit(**INLINE)
def _log_parts(x):
    """log(x) = hi + lo for finite x > 0 (lo below an ulp of hi, the pair good to ~2^-65
    relative): x = 2^k z with z in [sqrt(2)/2, sqrt(2)), z = c_j (1 + r) with c_j the
    centre of z's cell of width 1/256 (_log_table), so |r| < 2^-8.5 and log(1 + r) is a
    degree-7 series; z - c_j is exact (Sterbenz) and r is carried to double-double by an
    exact residual (c_j has 9 bits), no division."""
    hx = _high(x)
    k = 0
    if hx < 0x00100000:                     # subnormal: scale up
        k -= 54
        x *= _TWO54
        hx = _high(x)
    k += (hx >> 20) - 1023
    hx &= 0x000FFFFF
    i = (hx + 0x95F64) & 0x100000
    z = _set_high(x, hx | (i ^ 0x3FF00000))
    k += i >> 20
    below = i >> 20                         # 1: z in [sqrt(2)/2, 1), 0: z in [1, sqrt(2))
    j = ((hx + (0x800 << below)) >> (12 + below)) - (below << 7)    # z's cell, from its bits
    c = _CELL[j - _J_MIN]
    t = z - c                               # exact
    ic = _INVC[j - _J_MIN]
    r = t * ic
    rh = _clear_low(r)                      # 21 bits: rh c and (r - rh) c are exact
    rlo = ((t - rh * c) - (r - rh) * c) * ic
    r2 = r * r
    r4 = r2 * r2                            # Estrin's order: a shorter chain than Horner's
    series = r2 * (-0.5 + r * _L3) + r4 * ((-0.25 + r * _L5) + r2 * (_L6 + r * _L7))
    dk = np.float64(k)
    head = dk * _LN2_HI32 + _LOGC_HI[j - _J_MIN]      # exact
    tail = (rlo + series) + (dk * _LN2_LO32 + _LOGC_LO[j - _J_MIN])
    hi = head + r
    err = (head - (hi - (hi - head))) + (r - (hi - head))     # TwoSum: head + r = hi + err
    return hi, err + tail


@njit(**SCALAR)
def log(x):
    """Natural logarithm; error < 1 ulp (measured); log(0) = -inf, log(x < 0) = NaN. A table
    of 182 cells and a short series (_log_parts): no division, 2x faster than fdlibm's."""
    if not x > 0.0 or x == _INF:
        if x == 0.0:
            return -_INF
        return x if x != x or x == _INF else _NAN
    hi, lo = _log_parts(x)
    return hi + lo


# ---------------------------------------------------------------- atan, atan2
_ATANHI0 = _w(0x3FDDAC67, 0x0561BB4F)       # atan(0.5)
_ATANHI1 = _w(0x3FE921FB, 0x54442D18)       # atan(1)
_ATANHI2 = _w(0x3FEF730B, 0xD281F69B)       # atan(1.5)
_ATANHI3 = _w(0x3FF921FB, 0x54442D18)       # atan(inf)
_ATANLO0 = _w(0x3C7A2B7F, 0x222F65E2)
_ATANLO1 = _w(0x3C81A626, 0x33145C07)
_ATANLO2 = _w(0x3C700788, 0x7AF0CBBD)
_ATANLO3 = _w(0x3C91A626, 0x33145C07)
_AT0 = _w(0x3FD55555, 0x5555550D)
_AT1 = _w(0xBFC99999, 0x9998EBC4)
_AT2 = _w(0x3FC24924, 0x920083FF)
_AT3 = _w(0xBFBC71C6, 0xFE231671)
_AT4 = _w(0x3FB745CD, 0xC54C206E)
_AT5 = _w(0xBFB3B0F2, 0xAF749A6D)
_AT6 = _w(0x3FB10D66, 0xA0D03D51)
_AT7 = _w(0xBFADDE2D, 0x52DEFD9A)
_AT8 = _w(0x3FA97B4B, 0x24760DEB)
_AT9 = _w(0xBFA2B444, 0x2C6A6C2F)
_AT10 = _w(0x3F90AD3A, 0xE322DA11)


@njit(**SCALAR)
def atan(x):
    """arctan(x) in [-pi/2, pi/2]; error < 1 ulp (fdlibm s_atan)."""
    hx = _high(x)
    ix = hx & 0x7FFFFFFF
    if ix >= 0x44100000:                    # |x| >= 2^66
        if x != x:
            return x
        return _ATANHI3 + _ATANLO3 if hx > 0 else -_ATANHI3 - _ATANLO3
    if ix < 0x3FDC0000:                     # |x| < 0.4375
        if ix < 0x3E400000:                 # |x| < 2^-27
            return x
        z = x * x
        w = z * z
        s1 = z * (_AT0 + w * (_AT2 + w * (_AT4 + w * (_AT6 + w * (_AT8 + w * _AT10)))))
        s2 = w * (_AT1 + w * (_AT3 + w * (_AT5 + w * (_AT7 + w * _AT9))))
        return x - x * (s1 + s2)
    x = abs(x)
    if ix < 0x3FF30000:                     # |x| < 1.1875
        if ix < 0x3FE60000:                 # 7/16 <= |x| < 11/16
            hi = _ATANHI0
            lo = _ATANLO0
            x = (2.0 * x - 1.0) / (2.0 + x)
        else:                               # 11/16 <= |x| < 19/16
            hi = _ATANHI1
            lo = _ATANLO1
            x = (x - 1.0) / (x + 1.0)
    elif ix < 0x40038000:                   # |x| < 2.4375
        hi = _ATANHI2
        lo = _ATANLO2
        x = (x - 1.5) / (1.0 + 1.5 * x)
    else:                                   # 2.4375 <= |x| < 2^66
        hi = _ATANHI3
        lo = _ATANLO3
        x = -1.0 / x
    z = x * x
    w = z * z
    s1 = z * (_AT0 + w * (_AT2 + w * (_AT4 + w * (_AT6 + w * (_AT8 + w * _AT10)))))
    s2 = w * (_AT1 + w * (_AT3 + w * (_AT5 + w * (_AT7 + w * _AT9))))
    z = hi - ((x * (s1 + s2) - lo) - x)
    return -z if hx < 0 else z


def _dd(fraction):
    """A number as a double-double hi + lo (hi correctly rounded)."""
    hi = float(fraction)
    return hi, float(fraction - Fraction(hi))


# pi - atan(c) for the reduction points c = 0.5, 1, 1.5, inf, from fdlibm's pi and atan(c)
# in two parts each, as double-doubles
_PI_M_ATAN0 = _dd(Fraction(_PI) + Fraction(_PI_LO) - Fraction(_ATANHI0) - Fraction(_ATANLO0))
_PI_M_ATAN1 = _dd(Fraction(_PI) + Fraction(_PI_LO) - Fraction(_ATANHI1) - Fraction(_ATANLO1))
_PI_M_ATAN2 = _dd(Fraction(_PI) + Fraction(_PI_LO) - Fraction(_ATANHI2) - Fraction(_ATANLO2))
_PI_M_ATAN3 = _dd(Fraction(_PI) + Fraction(_PI_LO) - Fraction(_ATANHI3) - Fraction(_ATANLO3))


@njit(**SCALAR)
def _atan_quotient(ay, ax, from_pi):
    """atan(ay / ax), or pi - atan(ay / ax) if from_pi, for finite positive ay, ax with
    ay / ax < 2^62 (fdlibm's s_atan, refined). fdlibm's atan2 takes atan of the rounded
    quotient and subtracts the rounded atan from pi: up to 1.3 ulp off. Here the
    quotient's rounding error (from the exact residual ay - q ax, Dekker's product) enters
    atan's sum as (ay/ax - q) / (1 + q^2), and pi - atan(c) is a double-double constant
    taken before the last rounding: below 1 ulp."""
    if ax >= _TWO900 or ay >= _TWO900:      # keep the products below from overflowing
        ax *= _TWOM600
        ay *= _TWOM600
    elif ax < _TWOM900 and ay < _TWOM900:   # and the residual from underflowing
        ax *= _TWO600
        ay *= _TWO600
    q = ay / ax
    cs = 134217729.0 * q
    qh = cs - (cs - q)
    ql = q - qh
    cs = 134217729.0 * ax
    xh = cs - (cs - ax)
    xl = ax - xh
    ph = q * ax
    pl = ((qh * xh - ph) + qh * xl + ql * xh) + ql * xl
    d = (((ay - ph) - pl) / ax) / (1.0 + q * q)     # atan(ay/ax) - atan(q), first order

    ix = _high(q)
    if ix < 0x3E400000:                     # q < 2^-27
        if from_pi:
            return _PI - ((q + d) - _PI_LO)
        return q + d
    if ix < 0x3FDC0000:                     # q < 0.4375
        hi = 0.0
        lo = 0.0
        ch = _PI
        cl = _PI_LO
        t = q
    elif ix < 0x3FF30000:
        if ix < 0x3FE60000:                 # q < 11/16
            hi = _ATANHI0
            lo = _ATANLO0
            ch, cl = _PI_M_ATAN0
            t = (2.0 * q - 1.0) / (2.0 + q)
        else:                               # q < 19/16
            hi = _ATANHI1
            lo = _ATANLO1
            ch, cl = _PI_M_ATAN1
            t = (q - 1.0) / (q + 1.0)
    elif ix < 0x40038000:                   # q < 2.4375
        hi = _ATANHI2
        lo = _ATANLO2
        ch, cl = _PI_M_ATAN2
        t = (q - 1.5) / (1.0 + 1.5 * q)
    else:
        hi = _ATANHI3
        lo = _ATANLO3
        ch, cl = _PI_M_ATAN3
        t = -1.0 / q
    z = t * t
    w = z * z
    s1 = z * (_AT0 + w * (_AT2 + w * (_AT4 + w * (_AT6 + w * (_AT8 + w * _AT10)))))
    s2 = w * (_AT1 + w * (_AT3 + w * (_AT5 + w * (_AT7 + w * _AT9))))
    if from_pi:
        return ch - (t - ((t * (s1 + s2) - d) + cl))
    return hi - ((t * (s1 + s2) - (lo + d)) - t)


@njit(**SCALAR)
def atan2(y, x):
    """The angle of (x, y) in [-pi, pi], signed zeros and infinities as C99 / Python's
    math.atan2; error < 1 ulp (fdlibm e_atan2 with a refined quotient: _atan_quotient)."""
    if x != x:
        return x
    if y != y:
        return y
    hx = _high(x)
    ix = hx & 0x7FFFFFFF
    lx = _low(x)
    hy = _high(y)
    iy = hy & 0x7FFFFFFF
    ly = _low(y)
    if hx == 0x3FF00000 and lx == 0:        # x = 1
        return atan(y)
    m = ((hy >> 31) & 1) | ((hx >> 30) & 2)     # 2 sign(x) + sign(y)
    if (iy | ly) == 0:                      # y = +-0
        if m <= 1:
            return y
        return _PI if m == 2 else -_PI
    if (ix | lx) == 0:                      # x = +-0
        return -_PIO2_HI if hy < 0 else _PIO2_HI
    if ix == 0x7FF00000:                    # x = +-inf
        if iy == 0x7FF00000:
            if m == 0:
                return _PIO4_HI
            if m == 1:
                return -_PIO4_HI
            if m == 2:
                return 3.0 * _PIO4_HI
            return -3.0 * _PIO4_HI
        if m == 0:
            return 0.0
        if m == 1:
            return -0.0
        return _PI if m == 2 else -_PI
    if iy == 0x7FF00000:                    # y = +-inf
        return -_PIO2_HI if hy < 0 else _PIO2_HI
    k = (iy - ix) >> 20
    if k > 60:                              # |y/x| > 2^60
        z = _PIO2_HI + 0.5 * _PI_LO
        return -z if m & 1 else z
    if hx < 0:
        if k < -60:                         # 0 > |y|/x > -2^-60
            z = _PI - (0.0 - _PI_LO)
        else:
            z = _atan_quotient(abs(y), abs(x), True)
        return -z if m == 3 else z
    z = _atan_quotient(abs(y), abs(x), False)
    return -z if m == 1 else z


_TWO900 = _w(0x78300000)
_TWOM900 = _w(0x07B00000)
_TWO600 = _w(0x65700000)
_TWOM600 = _w(0x1A700000)


# ---------------------------------------------------------------- asin, acos
_PS0 = _w(0x3FC55555, 0x55555555)
_PS1 = _w(0xBFD4D612, 0x03EB6F7D)
_PS2 = _w(0x3FC9C155, 0x0E884455)
_PS3 = _w(0xBFA48228, 0xB5688F3B)
_PS4 = _w(0x3F49EFE0, 0x7501B288)
_PS5 = _w(0x3F023DE1, 0x0DFDF709)
_QS1 = _w(0xC0033A27, 0x1C8A2D4B)
_QS2 = _w(0x40002AE5, 0x9C598AC8)
_QS3 = _w(0xBFE6066C, 0x1B8D0159)
_QS4 = _w(0x3FB3B8C5, 0xB12E9282)


@njit(**SCALAR)
def _asin_r(t):
    """(asin(s) - s) / s^3 for t = s^2 <= 1/4, as p/q (fdlibm)."""
    p = t * (_PS0 + t * (_PS1 + t * (_PS2 + t * (_PS3 + t * (_PS4 + t * _PS5)))))
    q = 1.0 + t * (_QS1 + t * (_QS2 + t * (_QS3 + t * _QS4)))
    return p / q


@njit(**SCALAR)
def asin(x):
    """arcsin(x) in [-pi/2, pi/2]; NaN for |x| > 1; error < 1 ulp (fdlibm e_asin)."""
    hx = _high(x)
    ix = hx & 0x7FFFFFFF
    if ix >= 0x3FF00000:                    # |x| >= 1
        if ((ix - 0x3FF00000) | _low(x)) == 0:
            return x * _PIO2_HI + x * _PIO2_LO  # +-pi/2
        return x if x != x else _NAN
    if ix < 0x3FE00000:                     # |x| < 0.5
        if ix < 0x3E500000:                 # |x| < 2^-26
            return x
        return x + x * _asin_r(x * x)
    w = 1.0 - abs(x)
    t = w * 0.5
    r = _asin_r(t)
    s = math.sqrt(t)
    if ix >= 0x3FEF3333:                    # |x| > 0.975
        t = _PIO2_HI - (2.0 * (s + s * r) - _PIO2_LO)
    else:
        w = _clear_low(s)
        c = (t - w * w) / (s + w)
        p = 2.0 * s * r - (_PIO2_LO - 2.0 * c)
        q = _PIO4_HI - 2.0 * w
        t = _PIO4_HI - (p - q)
    return t if hx > 0 else -t


@njit(**SCALAR)
def acos(x):
    """arccos(x) in [0, pi]; NaN for |x| > 1; error < 1 ulp (fdlibm e_acos)."""
    hx = _high(x)
    ix = hx & 0x7FFFFFFF
    if ix >= 0x3FF00000:                    # |x| >= 1
        if ((ix - 0x3FF00000) | _low(x)) == 0:
            return 0.0 if hx > 0 else _PI + 2.0 * _PIO2_LO
        return x if x != x else _NAN
    if ix < 0x3FE00000:                     # |x| < 0.5
        if ix <= 0x3C600000:                # |x| < 2^-57
            return _PIO2_HI + _PIO2_LO
        return _PIO2_HI - (x - (_PIO2_LO - x * _asin_r(x * x)))
    if hx < 0:                              # x < -0.5
        z = (1.0 + x) * 0.5
        s = math.sqrt(z)
        w = _asin_r(z) * s - _PIO2_LO
        return _PI - 2.0 * (s + w)
    z = (1.0 - x) * 0.5                     # x > 0.5
    s = math.sqrt(z)
    df = _clear_low(s)
    c = (z - df * df) / (s + df)
    w = _asin_r(z) * s + c
    return 2.0 * (df + w)


# ---------------------------------------------------------------- pow
_SPLIT = 134217729.0                        # 2^27 + 1: Veltkamp's split into 26 + 27 bits


@njit(**INLINE)
def _split(a):
    t = _SPLIT * a
    h = t - (t - a)
    return h, a - h


@njit(**SCALAR)
def pow(x, y):
    """x**y for x >= 0 (and x = inf): exp(y log x) with log x in double-double
    (_log_parts) and the product y log x exact to double-double (Dekker), so the result is
    within about 1 ulp (measured); x < 0 gives NaN (the model raises no negative number to
    a power). pow(x, 0) = pow(1, y) = 1, pow(0, y > 0) = 0, pow(0, y < 0) = inf."""
    if y == 0.0 or x == 1.0:
        return 1.0
    if x != x or y != y:
        return x + y
    if not x > 0.0 or x == _INF:
        if x == 0.0:
            return 0.0 if y > 0.0 else _INF
        if x == _INF:
            return _INF if y > 0.0 else 0.0
        return _NAN
    hi, lo = _log_parts(x)
    p = y * hi
    if not abs(p) < 1000.0:                 # over- or underflows (or y is infinite)
        return exp(p)
    yh, yl = _split(y)
    hh, hl = _split(hi)
    err = ((yh * hh - p) + yh * hl + yl * hh) + yl * hl + y * lo
    return _exp_tail(p, err)


# ---------------------------------------------------------------- hypot
_TWO1022 = _w(0x7FD00000)


@njit(**SCALAR)
def hypot(x, y):
    """sqrt(x^2 + y^2) without undue overflow or underflow; error < 1 ulp; inf if either
    is infinite, even with a NaN (fdlibm e_hypot)."""
    ha = _high(x) & 0x7FFFFFFF
    hb = _high(y) & 0x7FFFFFFF
    if hb > ha:
        a = abs(y)
        b = abs(x)
        ha, hb = hb, ha
    else:
        a = abs(x)
        b = abs(y)
    if ha - hb > 0x3C00000:                 # a/b > 2^60
        if a == _INF or b == _INF:
            return _INF
        return a + b if a == a else a
    k = 0
    if ha > 0x5F300000:                     # a > 2^500
        if ha >= 0x7FF00000:                # inf or NaN
            if a == _INF or b == _INF:
                return _INF
            return a if a != a else b
        a = a * _TWOM600                    # exact
        b = b * _TWOM600
        hb -= 0x25800000
        k += 600
    if hb < 0x20B00000:                     # b < 2^-500
        if hb <= 0x000FFFFF:                # subnormal b or 0
            if b == 0.0:
                return a
            a = a * _TWO1022
            b = b * _TWO1022
            k -= 1022
            if b > a:
                a, b = b, a
        else:
            a = a * _TWO600
            b = b * _TWO600
            k -= 600
    w = a - b
    if w > b:
        t1 = _clear_low(a)
        t2 = a - t1
        w = math.sqrt(t1 * t1 - (b * (-b) - t2 * (a + t1)))
    else:
        a = a + a
        y1 = _clear_low(b)
        y2 = b - y1
        t1 = _clear_low(a)
        t2 = a - t1
        w = math.sqrt(t1 * y1 - (w * (-w) - (t1 * y2 + t2 * b)))
    if k != 0:
        return w * _words(0x3FF00000 + (k << 20), 0)
    return w



# ---------------------------------------------------------------- array versions
_UNARY = ("sin", "cos", "tan", "atan", "asin", "acos", "exp", "expm1", "log")
_BINARY = ("atan2", "pow", "hypot")


@njit(**KERNEL)
def _map(op, x, y, out):
    """out = f(x) (or f(x, y)) elementwise, f by its index in _UNARY + _BINARY: one
    compiled kernel for every array version, loaded from the cache once."""
    for i in range(out.shape[0]):
        a = x[i]
        if op == 0:
            out[i] = sin(a)
        elif op == 1:
            out[i] = cos(a)
        elif op == 2:
            out[i] = tan(a)
        elif op == 3:
            out[i] = atan(a)
        elif op == 4:
            out[i] = asin(a)
        elif op == 5:
            out[i] = acos(a)
        elif op == 6:
            out[i] = exp(a)
        elif op == 7:
            out[i] = expm1(a)
        elif op == 8:
            out[i] = log(a)
        elif op == 9:
            out[i] = atan2(a, y[i])
        elif op == 10:
            out[i] = pow(a, y[i])
        else:
            out[i] = hypot(a, y[i])


def _elementwise(name):
    op = (_UNARY + _BINARY).index(name)

    def apply(*args):
        arrays = np.broadcast_arrays(*[np.asarray(a, dtype=np.float64) for a in args])
        shape = arrays[0].shape
        flat = [np.ascontiguousarray(a).reshape(-1) for a in arrays]
        out = np.empty(flat[0].size)
        _map(op, flat[0], flat[-1], out)
        return out.reshape(shape) if shape else out[0]

    apply.__name__ = apply.__qualname__ = "v" + name
    apply.__doc__ = f"{name} elementwise on arrays or numbers, as the scalar {name}."
    return apply


for _name in _UNARY + _BINARY:
    globals()["v" + _name] = _elementwise(_name)


@njit(**KERNEL)
def _sincos_into(x, s, c):
    for i in range(x.shape[0]):
        s[i], c[i] = sincos(x[i])


def vsincos(x):
    """(sin(x), cos(x)) elementwise for an array or a number, as vsin(x), vcos(x)."""
    a = np.asarray(x, dtype=np.float64)
    flat = np.ascontiguousarray(a).reshape(-1)
    s = np.empty_like(flat)
    c = np.empty_like(flat)
    _sincos_into(flat, s, c)
    if a.ndim == 0:
        return s[0], c[0]
    return s.reshape(a.shape), c.reshape(a.shape)
