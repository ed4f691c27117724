"""Lee's accelerated iteration for the Lagrange multipliers (paper Eqs. 15-20, A1-A6).

    lambda <- lambda - alpha A_n v / ||C||_inf                         (15)
    alpha = 2 / (w_n + eps_n)                                          (16)
    C = dt^2/6 G (position), dt/2 G (velocity), G (acceleration)       (17)-(19)
    G = Phi_q M^-1 Phi_q^T

A_n depends on C only through C_1 = C / ||C||_inf, which is the same matrix at all
three levels (the factors of Eqs. 17-19 cancel), so one A_n per configuration serves
them all; only ||C||_inf differs. Recursion (A1)-(A5), with b_n = eps_(n-1) + w_(n-1):
C_n = C_(n-1) (b_n I - C_(n-1)), A_n = (b_n I - C_(n-1)) A_(n-1), w_n = b_n^2 / 4,
eps_n = eps_(n-1) w_(n-1). w_n shrinks doubly exponentially (about 1e-192 at n = 10,
underflow beyond), so this code carries C_n, A_n, eps_n divided by w_n at every level:
alpha_n A_n = 2 / (w_n + eps_n) A_n = 2 / (1 + eps_n / w_n) (A_n / w_n) is unchanged,
i.e. the update is exactly the paper's, only its floating-point scaling differs.
eps-bar-1 (the assumed smallest eigenvalue of C_1) comes from Eq. (20): J plain
iterations (n = 1, alpha = 1.9), eps1 = min_m (1 - ||v^m||_2 / ||v^(m-1)||_2) / alpha.
"""

import math

from numba import njit

from ...model.core.indices_jit import z_pin
from ...model.core.jit import BORROW
from ...model.dynamics.absolute import add_phi_qt, gamma, phi_q_times


@njit(**BORROW)
def inf_norm(G):
    g = 0.0
    for i in range(G.shape[0]):
        r = 0.0
        for j in range(G.shape[1]):
            r += abs(G[i, j])
        g = max(g, r)
    return g


@njit(**BORROW)
def _product_over(X, Y, q, tmp, out):
    """out = X Y / q (out may be X or Y: the product goes through tmp)."""
    m = X.shape[0]
    for i in range(m):
        for j in range(m):
            acc = 0.0
            for k in range(m):
                acc += X[i, k] * Y[k, j]
            tmp[i, j] = acc
    for i in range(m):
        for j in range(m):
            out[i, j] = tmp[i, j] / q


@njit(**BORROW)
def accel_matrix(G, n, eps1, An, Cn, T, tmp):
    """Fill An (= A_n / w_n) for C_1 = G / ||G||_inf; returns (alpha_n, ||G||_inf)."""
    m = G.shape[0]
    gn = inf_norm(G)
    for i in range(m):
        for j in range(m):
            Cn[i, j] = G[i, j] / gn
            An[i, j] = 1.0 if i == j else 0.0
    eps = eps1
    for _ in range(2, n + 1):
        b = eps + 1.0              # b_n = eps_(n-1) + w_(n-1), w_(n-1) = 1 after scaling
        q = 0.25 * b * b           # w_n
        for i in range(m):
            for j in range(m):
                T[i, j] = (b if i == j else 0.0) - Cn[i, j]
        _product_over(T, An, q, tmp, An)    # A_n = T A_(n-1)
        _product_over(Cn, T, q, tmp, Cn)    # C_n = C_(n-1) T
        eps = eps / q              # eps_n = eps_(n-1) w_(n-1), scaled by 1 / w_n
    return 2.0 / (1.0 + eps), gn


@njit(**BORROW)
def update(lam, An, v, scale):
    """Eq. (15): lam -= scale * A_n v (scale = alpha / ||C||_inf)."""
    m = lam.shape[0]
    for i in range(m):
        acc = 0.0
        for j in range(m):
            acc += An[i, j] * v[j]
        lam[i] -= scale * acc


@njit(**BORROW)
def max_abs(v):
    e = 0.0
    for i in range(v.shape[0]):
        e = max(e, abs(v[i]))
    return e


@njit(**BORROW)
def norm2(v):
    s = 0.0
    for i in range(v.shape[0]):
        s += v[i] * v[i]
    return math.sqrt(s)


@njit(**BORROW)
def accel_error(F, geo, zd, minv, lam, nbody, zdd, gam, v):
    """zdd (body part) = M^-1 (F - Phi_q^T lam); v = Eq. (14) error = gamma - Phi_q zdd."""
    for k in range(nbody):
        zdd[k] = F[k]
    add_phi_qt(geo, lam, -1.0, zdd)
    for k in range(nbody):
        zdd[k] *= minv[k]
    phi_q_times(geo, zdd, v)
    for i in range(v.shape[0]):
        v[i] = gam[i] - v[i]


@njit(**BORROW)
def acceleration_level(F, geo, zd, minv, lam, itm, tol, max_it, scratch):
    """Step 4: iterate lam with the acceleration error Eq. (14) (C = G, Eq. 19).
    itm = (A_n, alpha, ||G||_inf); scratch = (zdd, gamma, v): zdd holds the body part of
    the acceleration on return. Returns (iterations, final max |v|); -1 if not converged."""
    An, alpha, gn = itm
    zdd, gam, v = scratch
    nbody = z_pin(geo.shape[0])
    gamma(zd, geo, gam)
    for it in range(max_it + 1):
        accel_error(F, geo, zd, minv, lam, nbody, zdd, gam, v)
        err = max_abs(v)
        if err <= tol:
            return it, err
        if not math.isfinite(err):
            break
        update(lam, An, v, alpha / gn)
    return -1, err


@njit(**BORROW)
def estimate_eps1(F, geo, zd, minv, lam, gn, n_iter, nbody, zdd, gam, v):
    """Eq. (20): n_iter plain iterations (n = 1, alpha = 1.9) at the acceleration level;
    returns eps-bar-1 (clipped to (0, 1])."""
    alpha = 1.9
    gamma(zd, geo, gam)
    accel_error(F, geo, zd, minv, lam, nbody, zdd, gam, v)
    prev = norm2(v)
    est = 1.0
    for _ in range(n_iter):
        for i in range(lam.shape[0]):  # A_1 = I
            lam[i] -= alpha / gn * v[i]
        accel_error(F, geo, zd, minv, lam, nbody, zdd, gam, v)
        cur = norm2(v)
        if prev > 0.0 and cur > 0.0:
            est = min(est, (1.0 - cur / prev) / alpha)
        prev = cur
    return min(1.0, max(est, 1e-6))


@njit(**BORROW)
def velocity_level(zd, geo_end, geos, bp, c, h, minv, lam, itm, tol, max_it, scratch):
    """Step 3: with the stage forces of step 1 held, the body velocity at t + h depends on
    the end value lam of the multipliers (linear over the step) through
    zd = zd_1 - h sum_j bp_j c_j M^-1 Phi_q(Z_j)^T (lam - lam_1). Iterate lam with the
    velocity error Eq. (13) (C = h/2 G, Eq. 18); zd is updated in place.
    itm = (A_n, alpha, ||G||_inf); scratch = (dl, u, v). Returns (iterations, final max |v|)."""
    An, alpha, gn = itm
    dl, u, v = scratch
    nbody = z_pin(geo_end.shape[0])
    ns = bp.shape[0]
    m = lam.shape[0]
    scale = alpha / (0.5 * h * gn)
    for it in range(max_it + 1):
        phi_q_times(geo_end, zd, v)
        for i in range(m):
            v[i] = -v[i]
        err = max_abs(v)
        if err <= tol:
            return it, err
        if not math.isfinite(err):
            break
        for i in range(m):
            dl[i] = 0.0
        update(dl, An, v, scale)      # dl = change of lam
        for i in range(m):
            lam[i] += dl[i]
        for k in range(nbody):
            u[k] = 0.0
        for j in range(ns):
            w = h * bp[j] * c[j]
            if w != 0.0:
                add_phi_qt(geos[j], dl, -w, u)
        for k in range(nbody):
            zd[k] += minv[k] * u[k]
    return -1, err
