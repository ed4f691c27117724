"""The words of a double and the constants the elementary functions share (plain
bit manipulation: exact on every machine)."""

import struct

import numpy as np
from numba import njit

from ..jit import INLINE


def _w(hi, lo=0):
    """The double whose high and low 32-bit words are hi and lo."""
    return struct.unpack("<d", struct.pack("<Q", (hi << 32) | lo))[0]


_NAN = _w(0x7FF80000)  # the one NaN made here (x86 and ARM would differ in sign)
_INF = _w(0x7FF00000)
_TWO24 = 16777216.0
_TWOM1021 = _w(0x00200000)
_TWO54 = _w(0x43500000)
_TWOM1000 = _w(0x01700000)  # 2^-1000
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
    return (z * _words(0x3FF00000 + ((n + 200) << 20), 0)) * _words(0x33700000, 0)  # * 2^-200
