"""exp, expm1, log and pow: fdlibm's exp and expm1, a table-driven log, pow as exp(y log x)
in double-double."""

import numpy as np
from numba import njit

from ..jit import INLINE, SCALAR
from .bits import _INF, _NAN, _TWO54, _TWO1023, _TWOM1000, _clear_low, _high, _set_high, _w, _words
from .pio2 import _TOINT

# ---------------------------------------------------------------- exp, expm1
_O_THRESHOLD = _w(0x40862E42, 0xFEFA39EF)  # 709.78...
_U_THRESHOLD = _w(0xC0874910, 0xD52D3051)  # -745.13...
_LN2_HI = _w(0x3FE62E42, 0xFEE00000)
_LN2_LO = _w(0x3DEA39EF, 0x35793C76)
_INVLN2 = _w(0x3FF71547, 0x652B82FE)
_P1 = _w(0x3FC55555, 0x5555553E)
_P2 = _w(0xBF66C16C, 0x16BEBD93)
_P3 = _w(0x3F11566A, 0xAF25DE2C)
_P4 = _w(0xBEBBBD41, 0xC5D26BF1)
_P5 = _w(0x3E663769, 0x72BEA4D0)
_E = _w(0x4005BF0A, 0x8B145769)  # e, correctly rounded


@njit(**INLINE)
def _exp_tail(x, tail):
    """e^(x + tail) for |tail| below an ulp of x (exp, and pow's y log x in double-double);
    error < 1 ulp; overflow gives inf, underflow 0. fdlibm's e_exp, with k (x = k
    ln2 + r) rounded by adding 1.5 2^52 (ties to even instead of away from 0: |r| may
    exceed ln2/2 by an ulp, well inside the approximation's range) and its polynomial
    evaluated in Estrin's order: 40 % faster, still < 1 ulp."""
    hx = _high(x)
    ax = hx & 0x7FFFFFFF
    if ax >= 0x40862E42:  # |x| >= 709.78...
        if ax >= 0x7FF00000:
            if x != x:
                return x
            return x if hx >= 0 else 0.0  # exp(+-inf) = inf, 0
        if x > _O_THRESHOLD:
            return _INF
        if x < _U_THRESHOLD:
            return 0.0
    elif ax < 0x3E300000:  # |x| < 2^-28
        return 1.0 + (x + tail)
    if x == 1.0 and tail == 0.0:
        return _E  # correctly rounded (the formula gives e + 1 ulp)
    kf = (x * _INVLN2 + _TOINT) - _TOINT  # nearest integer to x / ln2
    k = np.int64(kf)
    hi = x - kf * _LN2_HI  # exact
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
    if hx >= 0x4043687A:  # |x| >= 56 ln2
        if hx >= 0x40862E42:  # |x| >= 709.78...
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
    if hx > 0x3FD62E42:  # |x| > 0.5 ln2
        if hx < 0x3FF0A2B2:  # and |x| < 1.5 ln2
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
    elif hx < 0x3C900000:  # |x| < 2^-54 (and +-0)
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
    if k <= -2 or k > 56:  # exp(x) - 1 suffices
        y = 1.0 - (e - x)
        if k == 1024:
            y = y * 2.0 * _TWO1023
        else:
            y = y * _words(0x3FF00000 + (k << 20), 0)
        return y - 1.0
    if k < 20:
        t = _words(0x3FF00000 - (0x200000 >> k), 0)  # 1 - 2^-k
        y = t - (e - x)
        return y * _words(0x3FF00000 + (k << 20), 0)
    t = _words((0x3FF - k) << 20, 0)  # 2^-k
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
            h = float(round(ln * 2**32)) / 2**32
            cell.append(cj)
            inv.append(1.0 / cj)
            hi.append(h)
            lo.append(float(ln - Decimal(h)))
    return np.array(cell), np.array(inv), np.array(hi), np.array(lo)


_J_MIN = -75
_J_MAX = 106
_CELL, _INVC, _LOGC_HI, _LOGC_LO = _log_table()
_LN2_HI32 = _w(0x3FE62E42, 0xFEE00000)  # ln 2 to 32 bits: k ln2_hi exact for |k| < 2^21
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
    if hx < 0x00100000:  # subnormal: scale up
        k -= 54
        x *= _TWO54
        hx = _high(x)
    k += (hx >> 20) - 1023
    hx &= 0x000FFFFF
    i = (hx + 0x95F64) & 0x100000
    z = _set_high(x, hx | (i ^ 0x3FF00000))
    k += i >> 20
    below = i >> 20  # 1: z in [sqrt(2)/2, 1), 0: z in [1, sqrt(2))
    j = ((hx + (0x800 << below)) >> (12 + below)) - (below << 7)  # z's cell, from its bits
    c = _CELL[j - _J_MIN]
    t = z - c  # exact
    ic = _INVC[j - _J_MIN]
    r = t * ic
    rh = _clear_low(r)  # 21 bits: rh c and (r - rh) c are exact
    rlo = ((t - rh * c) - (r - rh) * c) * ic
    r2 = r * r
    r4 = r2 * r2  # Estrin's order: a shorter chain than Horner's
    series = r2 * (-0.5 + r * _L3) + r4 * ((-0.25 + r * _L5) + r2 * (_L6 + r * _L7))
    dk = np.float64(k)
    head = dk * _LN2_HI32 + _LOGC_HI[j - _J_MIN]  # exact
    tail = (rlo + series) + (dk * _LN2_LO32 + _LOGC_LO[j - _J_MIN])
    hi = head + r
    err = (head - (hi - (hi - head))) + (r - (hi - head))  # TwoSum: head + r = hi + err
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


# ---------------------------------------------------------------- pow
_SPLIT = 134217729.0  # 2^27 + 1: Veltkamp's split into 26 + 27 bits


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
    if not abs(p) < 1000.0:  # over- or underflows (or y is infinite)
        return exp(p)
    yh, yl = _split(y)
    hh, hl = _split(hi)
    err = ((yh * hh - p) + yh * hl + yl * hh) + yl * hl + y * lo
    return _exp_tail(p, err)
