"""atan, atan2, asin, acos (fdlibm) and hypot."""

import math
from fractions import Fraction

from numba import njit

from ..jit import SCALAR
from .bits import _INF, _NAN, _PI, _PI_LO, _PIO2_HI, _PIO2_LO, _PIO4_HI, _clear_low, _high, _low, _w, _words

# ---------------------------------------------------------------- atan, atan2
_ATANHI0 = _w(0x3FDDAC67, 0x0561BB4F)  # atan(0.5)
_ATANHI1 = _w(0x3FE921FB, 0x54442D18)  # atan(1)
_ATANHI2 = _w(0x3FEF730B, 0xD281F69B)  # atan(1.5)
_ATANHI3 = _w(0x3FF921FB, 0x54442D18)  # atan(inf)
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
    if ix >= 0x44100000:  # |x| >= 2^66
        if x != x:
            return x
        return _ATANHI3 + _ATANLO3 if hx > 0 else -_ATANHI3 - _ATANLO3
    if ix < 0x3FDC0000:  # |x| < 0.4375
        if ix < 0x3E400000:  # |x| < 2^-27
            return x
        z = x * x
        w = z * z
        s1 = z * (_AT0 + w * (_AT2 + w * (_AT4 + w * (_AT6 + w * (_AT8 + w * _AT10)))))
        s2 = w * (_AT1 + w * (_AT3 + w * (_AT5 + w * (_AT7 + w * _AT9))))
        return x - x * (s1 + s2)
    x = abs(x)
    if ix < 0x3FF30000:  # |x| < 1.1875
        if ix < 0x3FE60000:  # 7/16 <= |x| < 11/16
            hi = _ATANHI0
            lo = _ATANLO0
            x = (2.0 * x - 1.0) / (2.0 + x)
        else:  # 11/16 <= |x| < 19/16
            hi = _ATANHI1
            lo = _ATANLO1
            x = (x - 1.0) / (x + 1.0)
    elif ix < 0x40038000:  # |x| < 2.4375
        hi = _ATANHI2
        lo = _ATANLO2
        x = (x - 1.5) / (1.0 + 1.5 * x)
    else:  # 2.4375 <= |x| < 2^66
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
    if ax >= _TWO900 or ay >= _TWO900:  # keep the products below from overflowing
        ax *= _TWOM600
        ay *= _TWOM600
    elif ax < _TWOM900 and ay < _TWOM900:  # and the residual from underflowing
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
    d = (((ay - ph) - pl) / ax) / (1.0 + q * q)  # atan(ay/ax) - atan(q), first order

    ix = _high(q)
    if ix < 0x3E400000:  # q < 2^-27
        if from_pi:
            return _PI - ((q + d) - _PI_LO)
        return q + d
    if ix < 0x3FDC0000:  # q < 0.4375
        hi = 0.0
        lo = 0.0
        ch = _PI
        cl = _PI_LO
        t = q
    elif ix < 0x3FF30000:
        if ix < 0x3FE60000:  # q < 11/16
            hi = _ATANHI0
            lo = _ATANLO0
            ch, cl = _PI_M_ATAN0
            t = (2.0 * q - 1.0) / (2.0 + q)
        else:  # q < 19/16
            hi = _ATANHI1
            lo = _ATANLO1
            ch, cl = _PI_M_ATAN1
            t = (q - 1.0) / (q + 1.0)
    elif ix < 0x40038000:  # q < 2.4375
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
    if hx == 0x3FF00000 and lx == 0:  # x = 1
        return atan(y)
    m = ((hy >> 31) & 1) | ((hx >> 30) & 2)  # 2 sign(x) + sign(y)
    if (iy | ly) == 0:  # y = +-0
        if m <= 1:
            return y
        return _PI if m == 2 else -_PI
    if (ix | lx) == 0:  # x = +-0
        return -_PIO2_HI if hy < 0 else _PIO2_HI
    if ix == 0x7FF00000:  # x = +-inf
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
    if iy == 0x7FF00000:  # y = +-inf
        return -_PIO2_HI if hy < 0 else _PIO2_HI
    k = (iy - ix) >> 20
    if k > 60:  # |y/x| > 2^60
        z = _PIO2_HI + 0.5 * _PI_LO
        return -z if m & 1 else z
    if hx < 0:
        if k < -60:  # 0 > |y|/x > -2^-60
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
    if ix >= 0x3FF00000:  # |x| >= 1
        if ((ix - 0x3FF00000) | _low(x)) == 0:
            return x * _PIO2_HI + x * _PIO2_LO  # +-pi/2
        return x if x != x else _NAN
    if ix < 0x3FE00000:  # |x| < 0.5
        if ix < 0x3E500000:  # |x| < 2^-26
            return x
        return x + x * _asin_r(x * x)
    w = 1.0 - abs(x)
    t = w * 0.5
    r = _asin_r(t)
    s = math.sqrt(t)
    if ix >= 0x3FEF3333:  # |x| > 0.975
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
    if ix >= 0x3FF00000:  # |x| >= 1
        if ((ix - 0x3FF00000) | _low(x)) == 0:
            return 0.0 if hx > 0 else _PI + 2.0 * _PIO2_LO
        return x if x != x else _NAN
    if ix < 0x3FE00000:  # |x| < 0.5
        if ix <= 0x3C600000:  # |x| < 2^-57
            return _PIO2_HI + _PIO2_LO
        return _PIO2_HI - (x - (_PIO2_LO - x * _asin_r(x * x)))
    if hx < 0:  # x < -0.5
        z = (1.0 + x) * 0.5
        s = math.sqrt(z)
        w = _asin_r(z) * s - _PIO2_LO
        return _PI - 2.0 * (s + w)
    z = (1.0 - x) * 0.5  # x > 0.5
    s = math.sqrt(z)
    df = _clear_low(s)
    c = (z - df * df) / (s + df)
    w = _asin_r(z) * s + c
    return 2.0 * (df + w)


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
    if ha - hb > 0x3C00000:  # a/b > 2^60
        if a == _INF or b == _INF:
            return _INF
        return a + b if a == a else a
    k = 0
    if ha > 0x5F300000:  # a > 2^500
        if ha >= 0x7FF00000:  # inf or NaN
            if a == _INF or b == _INF:
                return _INF
            return a if a != a else b
        a = a * _TWOM600  # exact
        b = b * _TWOM600
        hb -= 0x25800000
        k += 600
    if hb < 0x20B00000:  # b < 2^-500
        if hb <= 0x000FFFFF:  # subnormal b or 0
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
