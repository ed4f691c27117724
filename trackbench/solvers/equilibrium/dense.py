"""Small dense linear algebra with a fixed order of operations (the static equilibrium's
Newton and Levenberg-Marquardt steps).

numpy.linalg and the @ product go through BLAS/LAPACK, whose kernels are chosen by the
CPU (OpenBLAS: Haswell, SkylakeX, Prescott, ...): each rounds its sums in its own order, and
the equilibrium, hence every result of a run, then differed in the last bits from one
machine to another. These loops are compiled without fastmath, so LLVM keeps every
operation's order (vectorising only across independent elements) and never fuses a
multiply and an add: the same bits on every machine. The systems are small (two unknowns
per pin, a few hundred at most), so textbook loops cost little beside the residuals.
"""

import math

import numpy as np
from numba import njit

from ...model.core.jit import KERNEL


@njit(**KERNEL)
def solve(A, b, x):
    """x = A^-1 b by Gaussian elimination with partial pivoting (A and b are not changed);
    False, x untouched, when a pivot is exactly zero (A singular)."""
    n = b.shape[0]
    lu = A.copy()
    y = b.copy()
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if abs(lu[i, k]) > abs(lu[p, k]):
                p = i
        if lu[p, k] == 0.0:
            return False
        if p != k:
            for j in range(n):
                lu[k, j], lu[p, j] = lu[p, j], lu[k, j]
            y[k], y[p] = y[p], y[k]
        for i in range(k + 1, n):
            f = lu[i, k] / lu[k, k]
            if f != 0.0:
                for j in range(k + 1, n):
                    lu[i, j] -= f * lu[k, j]
                y[i] -= f * y[k]
    for k in range(n - 1, -1, -1):
        s = y[k]
        for j in range(k + 1, n):
            s -= lu[k, j] * x[j]
        x[k] = s / lu[k, k]
    return True


@njit(**KERNEL)
def least_squares(A, b, x):
    """A least-squares solution of A x = b for a rank-deficient A: Householder QR with column
    pivoting, the columns below rank (|R_kk| <= eps max(m, n) |R_00|, LAPACK's default
    cutoff) left at zero: a basic solution (numpy's lstsq gives the minimum-norm one; both
    are Newton directions that reduce the residual)."""
    m, n = A.shape
    R = A.copy()
    y = b.copy()
    perm = np.arange(n)
    norms = np.zeros(n)
    for j in range(n):
        for i in range(m):
            norms[j] += R[i, j] * R[i, j]
    rank = 0
    tol = 0.0
    v = np.empty(m)
    for k in range(min(m, n)):
        p = k
        for j in range(k + 1, n):
            if norms[j] > norms[p]:
                p = j
        if p != k:
            for i in range(m):
                R[i, k], R[i, p] = R[i, p], R[i, k]
            norms[k], norms[p] = norms[p], norms[k]
            perm[k], perm[p] = perm[p], perm[k]
        alpha = _householder(R, k, v)
        if k == 0:
            tol = 2.220446049250313e-16 * max(m, n) * abs(alpha)
        if abs(alpha) <= tol:
            break
        _reflect(R, y, k, v)
        rank = k + 1
        for j in range(k + 1, n):
            norms[j] -= R[k, j] * R[k, j]
    z = np.zeros(n)
    for k in range(rank - 1, -1, -1):
        s = y[k]
        for j in range(k + 1, rank):
            s -= R[k, j] * z[j]
        z[k] = s / R[k, k]
    for j in range(n):
        x[perm[j]] = z[j]


@njit(**KERNEL)
def _householder(R, k, v):
    """The reflector v (rows k..m-1) that maps column k of R onto its diagonal; returns the
    new diagonal value (0 for a zero column)."""
    m = R.shape[0]
    s = 0.0
    for i in range(k, m):
        s += R[i, k] * R[i, k]
    norm = math.sqrt(s)
    if norm == 0.0:
        return 0.0
    alpha = -norm if R[k, k] >= 0.0 else norm
    for i in range(k, m):
        v[i] = R[i, k]
    v[k] -= alpha
    return alpha


@njit(**KERNEL)
def _reflect(R, y, k, v):
    """Apply I - 2 v v^T / (v^T v) to the columns k.. of R and to y (rows k..)."""
    m, n = R.shape
    vv = 0.0
    for i in range(k, m):
        vv += v[i] * v[i]
    for j in range(k, n):
        s = 0.0
        for i in range(k, m):
            s += v[i] * R[i, j]
        f = 2.0 * s / vv
        for i in range(k, m):
            R[i, j] -= f * v[i]
    s = 0.0
    for i in range(k, m):
        s += v[i] * y[i]
    f = 2.0 * s / vv
    for i in range(k, m):
        y[i] -= f * v[i]


@njit(**KERNEL)
def normal_equations(J, r, A, g):
    """A = J^T J and g = J^T r (the Gauss-Newton system), each sum in row order."""
    m, n = J.shape
    for a in range(n):
        for c in range(n):
            s = 0.0
            for i in range(m):
                s += J[i, a] * J[i, c]
            A[a, c] = s
        s = 0.0
        for i in range(m):
            s += J[i, a] * r[i]
        g[a] = s


@njit(**KERNEL)
def dot(a, b):
    """sum a_i b_i in index order."""
    s = 0.0
    for i in range(a.shape[0]):
        s += a[i] * b[i]
    return s
