"""sin, cos, tan and sincos: fdlibm's kernels on [-pi/4, pi/4] and the reduction by pi/2
(Cody-Waite to 2^20 pi/2, Payne-Hanek beyond)."""

import numpy as np
from numba import njit

from ..jit import SCALAR
from .bits import _NAN, _PIO4_HI, _PIO4_LO, _clear_low, _high, _w
from .pio2 import _rem_pio2

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
    big = ix >= 0x3FE59428  # |x| >= 0.6744
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
    z = _clear_low(w)  # -1/(x + r) accurately
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
    if ix <= 0x3FE921FB:  # |x| ~<= pi/4
        if ix < 0x3E500000:  # |x| < 2^-26 (and +-0)
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
        if ix < 0x3E46A09E:  # |x| < 2^-27 sqrt(2)
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
            return x, 1.0  # 2^-27 sqrt(2) < 2^-26: sin is x as well
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
        if ix < 0x3E400000:  # |x| < 2^-27
            return x
        return _k_tan(x, 0.0, 1)
    if ix >= 0x7FF00000:
        return x if x != x else _NAN
    n, y0, y1 = _rem_pio2(x, hx)
    return _k_tan(y0, y1, 1 - ((n & 1) << 1))
