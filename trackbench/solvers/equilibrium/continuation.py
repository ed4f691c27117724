"""The static equilibrium's outer method: a power law (contact or Bekker's soil) reached by
continuation from the linear law, Newton's method rounded where it stalls, and the error
that names what to check when no equilibrium is found."""

import math

import numpy as np

from ...model.core import fixed_math as fm
from ...model.core import indices as L
from ...status import EquilibriumError
from .newton import newton, newton_rounded, rounded


def soil_sinkage_guess(P, pins):
    """A first guess of the sinkage into soft soil: the weight spread evenly over the pins
    of the ground run (0 on rigid ground)."""
    if P.par[L.P_SOIL] == 0.0:
        return 0.0
    return uniform_sinkage(P, max(int(np.sum(pins[:, 1] < pins[:, 1].min() + 0.01)), 1))


def chain(P, u, target, max_iter, exponent, stiffnesses, d, solve, step=0.05):
    """Newton's method for a power law F = k x^n (no stiffness at x = 0, where Newton's
    method starts) through a chain of laws k d^(n - m) x^m, m from 1 to n in steps of about
    `step`, each solution starting the next: d, a depth the law reaches under the weight,
    keeps the forces of every law of the chain alike. `exponent` and `stiffnesses` are the
    P_* indices of n and of the k's that share it; ``solve`` is one link's solver."""
    par = P.par
    n, k = par[exponent], [par[i] for i in stiffnesses]
    it, norm = 0, np.inf
    for m in np.linspace(1.0, n, 1 + int(math.ceil(abs(n - 1.0) / step))):
        par[exponent] = m
        for i, ki in zip(stiffnesses, k):
            par[i] = ki * fm.pow(d, n - m)
        u, norm, j = solve(P, u, target if m == n else 1e-6 * P.weight, max_iter)
        it += j
    par[exponent] = n
    for i, ki in zip(stiffnesses, k):
        par[i] = ki  # exactly the scenario's law again
    return u, norm, it


def continuation(P, u, target, max_iter):
    """The contact power law (n != 1) by continuation; d, a wheel's compression under an
    equal share of the weight."""
    n = P.par[L.P_CONTACT_EXPONENT]
    if n == 1.0:
        return newton(P, u, target, max_iter)
    d = fm.pow(P.weight / (P.nw * P.par[L.P_K_WHEEL]), 1.0 / n)
    return chain(P, u, target, max_iter, L.P_CONTACT_EXPONENT, (L.P_K_WHEEL, L.P_K_GROUND), d, newton)


def uniform_sinkage(P, pins_on_soil):
    """Bekker's sinkage under the weight spread evenly over that many pins' areas."""
    p = P.weight / (pins_on_soil * P.par[L.P_PIN_AREA])
    return fm.pow(p / P.par[L.P_SOIL_K], 1.0 / P.par[L.P_SOIL_N])


def soil_continuation(P, u, target, max_iter):
    """Soft soil with Bekker's n != 1 by continuation, each link rounded where Newton's
    method stalls; d, the sinkage under the weight spread over half the links."""
    z0 = uniform_sinkage(P, max(int(P.n_links) // 2, 1))
    return chain(P, u, target, max_iter, L.P_SOIL_N, (L.P_SOIL_K,), z0, newton_rounded)


def solve_static(P, u, max_iter, tol_rel, failure, check):
    """Newton's method (by continuation for a power law or Bekker's soil), rounded where it
    stalls; the solution and the iteration count, or EquilibriumError above 1e-6 of the weight."""
    target = tol_rel * P.weight
    if P.par[L.P_SOIL] != 0.0 and P.par[L.P_SOIL_N] != 1.0:
        u, norm, it = soil_continuation(P, u, target, max_iter)
    else:
        u, norm, it = continuation(P, u, target, max_iter)
    u, norm, it = rounded(P, u, norm, it, target, max_iter)
    if not np.isfinite(norm) or norm > 1e-6 * P.weight:
        on = max(int(np.count_nonzero(P.work.sink > 0.0)), 1)
        if P.par[L.P_SOIL] != 0.0 and uniform_sinkage(P, on) > P.par[L.P_PAD_GROUND]:  # a soil too soft
            check = (
                f"the soil: spread evenly over the {on} pins on it, the weight sinks the track "
                f"{uniform_sinkage(P, on):.3g} m (Bekker); a wider track.width or a firmer soil sinks less"
            )
        raise EquilibriumError(
            f"{failure}: force residual {norm:.3g} N after {it} Newton iterations (needs < "
            f"{1e-6 * P.weight:.3g} N); check {check}"
        )
    return u, it
