"""The array versions (vsin, ..., vsincos) of the scalar functions: one compiled loop
behind them all."""

import numpy as np
from numba import njit

from ..jit import KERNEL
from .arc import acos, asin, atan, atan2, hypot
from .exp_log import exp, expm1, log, pow
from .trig import cos, sin, sincos, tan

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
