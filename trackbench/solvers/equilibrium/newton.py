"""Newton's method with a finite-difference Jacobian and a backtracking line search, and
Levenberg-Marquardt steps where it stalls at a contact that opens or closes under its step
(on any problem with residual(u) and jacobian(u): model/dynamics/equilibrium.py)."""

import numpy as np

from . import dense


def newton(P, u, target, max_iter):
    """Newton iteration with a finite-difference Jacobian and a backtracking line search;
    returns (u, residual norm, iterations)."""
    r, _, _ = P.residual(u)
    norm = np.abs(r).max()
    it = 0
    while norm > target and it < max_iter:
        it += 1
        J = P.jacobian(u)
        du = np.empty(u.size)
        if not dense.solve(J, -r, du):  # e.g. the closed loop before its pins press on the teeth
            dense.least_squares(J, -r, du)
        lam = 1.0
        while True:
            un = u + lam * du
            rn, _, _ = P.residual(un)
            nn = np.abs(rn).max()
            if nn < norm or lam < 1e-4:
                break
            lam *= 0.5
        if nn >= norm:  # no descent even for a tiny step: stuck
            break
        u, r, norm = un, rn, nn
    return u, norm, it


def levenberg_marquardt(P, u, target, max_iter):
    """Where Newton's method stalls at a contact that opens or closes under its step:
    Levenberg-Marquardt steps on the sum of squared residuals (the damping grows until a
    step lowers it); returns (u, max residual, iterations)."""
    r, _, _ = P.residual(u)
    it = 0
    lam = 1e-3
    while np.abs(r).max() > target and it < max_iter:
        it += 1
        J = P.jacobian(u)
        A = np.empty((u.size, u.size))
        g = np.empty(u.size)
        dense.normal_equations(J, r, A, g)
        d = np.diag(A).copy() + 1e-30
        du = np.empty(u.size)
        for _ in range(30):
            if not dense.solve(A + lam * np.diag(d), -g, du):
                du[:] = 0.0
            rn, _, _ = P.residual(u + du)
            if dense.dot(rn, rn) < dense.dot(r, r):
                u, r = u + du, rn
                lam = max(lam / 5.0, 1e-9)
                break
            lam *= 4.0
        else:
            break
    return u, np.abs(r).max(), it


def rounded(P, u, norm, it, target, max_iter):
    """Where Newton's method stalled (a contact opening under its step, soft soil's infinite
    stiffness at the surface for n < 1): Levenberg-Marquardt steps, then Newton again."""
    for _ in range(4):
        if norm <= target:
            break
        u, norm, k = levenberg_marquardt(P, u, target, 20)
        it += k
        u, norm, k = newton(P, u, target, max_iter)
        it += k
    return u, norm, it


def newton_rounded(P, u, target, max_iter):
    u, norm, it = newton(P, u, target, max_iter)
    return rounded(P, u, norm, it, target, max_iter)
