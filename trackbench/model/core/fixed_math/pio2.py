"""The reduction of an angle by pi/2: x = n pi/2 + (y0 + y1), |y0 + y1| <= pi/4, the
remainder in double-double (fdlibm's three-part Cody-Waite constants to 2^20 pi/2, our own
Payne-Hanek on the digits of 2/pi beyond)."""

import numpy as np
from numba import njit

from ..jit import SCALAR
from .bits import _PIO2_HI, _PIO2_LO, _TWO24, _bits, _double, _high, _w, _words

_INVPIO2 = _w(0x3FE45F30, 0x6DC9C883)
_PIO2_1 = _w(0x3FF921FB, 0x54400000)  # first 33 bits of pi/2
_PIO2_1T = _w(0x3DD0B461, 0x1A626331)  # pi/2 - _PIO2_1
_PIO2_2 = _w(0x3DD0B461, 0x1A600000)  # second 33 bits
_PIO2_2T = _w(0x3BA3198A, 0x2E037073)
_PIO2_3 = _w(0x3BA3198A, 0x2E000000)  # third 33 bits
_PIO2_3T = _w(0x397B839A, 0x252049C1)
_TOINT = 1.5 * 2.0**52
_2PIO2_1, _2PIO2_1T = 2 * _PIO2_1, 2 * _PIO2_1T
_3PIO2_1, _3PIO2_1T = 3 * _PIO2_1, 3 * _PIO2_1T
_4PIO2_1, _4PIO2_1T = 4 * _PIO2_1, 4 * _PIO2_1T

# fdlibm's 2/pi in 24-bit digits: 2/pi = sum ipio2[i] * 2^(-24 (i+1)); enough for doubles.
_IPIO2 = np.array(
    [
        0xA2F983,
        0x6E4E44,
        0x1529FC,
        0x2757D1,
        0xF534DD,
        0xC0DB62,
        0x95993C,
        0x439041,
        0xFE5163,
        0xABDEBB,
        0xC561B7,
        0x246E3A,
        0x424DD2,
        0xE00649,
        0x2EEA09,
        0xD1921C,
        0xFE1DEB,
        0x1CB129,
        0xA73EE8,
        0x8235F5,
        0x2EBB44,
        0x84E99C,
        0x7026B4,
        0x5F7E41,
        0x3991D6,
        0x398353,
        0x39F49C,
        0x845F8B,
        0xBDF928,
        0x3B1FF8,
        0x97FFDE,
        0x05980F,
        0xEF2F11,
        0x8B5A0A,
        0x6D1F6D,
        0x367ECF,
        0x27CB09,
        0xB74F46,
        0x3F669E,
        0x5FEA2D,
        0x7527BA,
        0xC7EBE5,
        0xF17B3D,
        0x0739F7,
        0x8A5292,
        0xEA6BFB,
        0x5FB11F,
        0x8D5D08,
        0x560330,
        0x46FC7B,
        0x6BABF0,
        0xCFBC20,
        0x9AF436,
        0x1DA9E3,
        0x91615E,
        0xE61B08,
        0x659985,
        0x5F14A0,
        0x68408D,
        0xFFD880,
        0x4D7327,
        0x310606,
        0x1556CA,
        0x73A8C9,
        0x60E27B,
        0xC08C6B,
    ],
    dtype=np.int64,
)
_NDIGITS = 9  # 24-bit digits kept below the top one: the fraction to ~2^-190 (need ~2^-130)


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
    z = _double(_bits(ax) - (e0 << 52))  # |x| 2^-e0, in [2^23, 2^24)
    t0 = np.int64(z)
    z = (z - t0) * _TWO24
    t1 = np.int64(z)
    z = (z - t1) * _TWO24
    t2 = np.int64(z)
    jv = (e0 - 3) // 24
    if jv < 0:
        jv = 0
    q0 = e0 - 24 * (jv + 1)  # weight of digit jv is 2^q0, -27 <= q0 <= 2
    p = 24 - q0  # fraction bits in the top value below

    c = np.int64(0)  # pass 1: carry into digit 1
    for m in range(_NDIGITS, 1, -1):
        c = (_pio2_digit(jv + m, t0, t1, t2) + c) >> 24
    v = _pio2_digit(jv + 1, t0, t1, t2) + c
    d1 = v & 0xFFFFFF
    d0 = _pio2_digit(jv, t0, t1, t2) + (v >> 24)
    top = ((d0 & ((np.int64(1) << (3 - q0)) - 1)) << 24) | d1  # (x 2/pi mod 8) 2^p, truncated
    n = top >> p
    f1 = top & ((np.int64(1) << p) - 1)
    neg = (f1 >> (p - 1)) & 1  # fraction >= 1/2: use fraction - 1
    if neg:
        n += 1
        f1 = ((np.int64(1) << p) - 1) - f1

    # pass 2: the fraction (or 1 - fraction, digit by digit complemented) as hi + lo
    scale = _words(0x3FF00000 - ((p + 24 * (_NDIGITS - 1)) << 20), 0)
    hi = scale if neg else 0.0  # the +1 of the complement, at the last digit
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
    w = fn * _PIO2_1T  # first round good to 85 bits
    j = ix >> 20
    y0 = r - w
    i = j - ((_high(y0) >> 20) & 0x7FF)
    if i > 16:  # second round, good to 118 bits
        t = r
        w = fn * _PIO2_2
        r = t - w
        w = fn * _PIO2_2T - ((t - r) - w)
        y0 = r - w
        i = j - ((_high(y0) >> 20) & 0x7FF)
        if i > 49:  # third round, 151 bits
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
    if ix <= 0x400F6A7A:  # |x| ~<= 5pi/4
        if (ix & 0xFFFFF) == 0x921FB:  # |x| ~= pi/2 or 2pi/2: cancellation
            return _rem_pio2_medium(x, ix)
        if ix <= 0x4002D97C:  # |x| ~<= 3pi/4
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
    if ix <= 0x401C463B:  # |x| ~<= 9pi/4
        if ix <= 0x4015FDBC:  # |x| ~<= 7pi/4
            if ix == 0x4012D97C:  # |x| ~= 3pi/2
                return _rem_pio2_medium(x, ix)
            if hx > 0:
                z = x - _3PIO2_1
                y0 = z - _3PIO2_1T
                return 3, y0, (z - y0) - _3PIO2_1T
            z = x + _3PIO2_1
            y0 = z + _3PIO2_1T
            return -3, y0, (z - y0) + _3PIO2_1T
        if ix == 0x401921FB:  # |x| ~= 4pi/2
            return _rem_pio2_medium(x, ix)
        if hx > 0:
            z = x - _4PIO2_1
            y0 = z - _4PIO2_1T
            return 4, y0, (z - y0) - _4PIO2_1T
        z = x + _4PIO2_1
        y0 = z + _4PIO2_1T
        return -4, y0, (z - y0) + _4PIO2_1T
    if ix < 0x413921FB:  # |x| ~< 2^20 pi/2
        return _rem_pio2_medium(x, ix)
    return _rem_pio2_large(x)
