"""The ride metrics' filters and sums, compiled (the metrics, their coefficients and their
checks: ride_metrics.py).

A cascade of second-order sections in direct form I, one section over the whole signal
after the other, each from rest; every sum runs over the samples in order. No fastmath
(model/core/jit.py), so every operation rounds alike on every machine and the metrics are
the same to the last bit wherever they are computed."""

from numba import njit

from trackbench.model.core.jit import KERNEL


@njit(**KERNEL)
def sos_filter(sos, x, y):
    """y = the cascade of sections sos (rows b0 b1 b2 a0 a1 a2, a0 = 1: scipy's layout) applied
    to x, every section starting from rest (zero input and output before the first sample)."""
    n = x.shape[0]
    for i in range(n):
        y[i] = x[i]
    for s in range(sos.shape[0]):
        b0 = sos[s, 0]
        b1 = sos[s, 1]
        b2 = sos[s, 2]
        a1 = sos[s, 4]
        a2 = sos[s, 5]
        u1 = 0.0
        u2 = 0.0
        v1 = 0.0
        v2 = 0.0
        for i in range(n):
            u = y[i]
            v = b0 * u + b1 * u1 + b2 * u2 - a1 * v1 - a2 * v2
            u2 = u1
            u1 = u
            v2 = v1
            v1 = v
            y[i] = v


@njit(**KERNEL)
def sum_of_squares(y, start):
    """y[start]^2 + y[start + 1]^2 + ..., in that order."""
    total = 0.0
    for i in range(start, y.shape[0]):
        total += y[i] * y[i]
    return total


@njit(**KERNEL)
def sum_of_fourth_powers(y, start):
    """y[start]^4 + y[start + 1]^4 + ..., in that order (each as (y y)(y y))."""
    total = 0.0
    for i in range(start, y.shape[0]):
        sq = y[i] * y[i]
        total += sq * sq
    return total


@njit(**KERNEL)
def max_abs(y, start):
    """max |y[i]| for i >= start."""
    peak = 0.0
    for i in range(start, y.shape[0]):
        v = abs(y[i])
        if v > peak:
            peak = v
    return peak
