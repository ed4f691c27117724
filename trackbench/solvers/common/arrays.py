"""Array copies for the compiled loops, written as loops: numba compiles a slice
assignment between arrays together with the formatting of its shape-mismatch error
message, which costs seconds on every cold start (~4 s for the reduced solver)."""

from numba import njit

from ...model.core.jit import BORROW


@njit(**BORROW)
def copy_into(dst, offset, src):
    """dst[offset:offset + len(src)] = src (1-D)."""
    for k in range(src.shape[0]):
        dst[offset + k] = src[k]


@njit(**BORROW)
def set_row(a, i, v):
    """a[i, :] = v."""
    for k in range(v.shape[0]):
        a[i, k] = v[k]


@njit(**BORROW)
def copy_2d(dst, src):
    """dst[:, :] = src (same shape)."""
    for i in range(src.shape[0]):
        for k in range(src.shape[1]):
            dst[i, k] = src[i, k]
