"""The normal-force law of every penalty contact, compiled (laws.py has the
formulas, their sources and the codes)."""

import math

from numba import njit

from ..core import fixed_math as fm
from ..core.jit import SCALAR
from .laws import DAMPING_NONE, DAMPING_VISCOUS, LAW_POWER


@njit(**SCALAR)
def elastic(law, k, n, delta):
    """(force, stored energy) of the pad spring at compression delta > 0."""
    if law == LAW_POWER:
        f = k * fm.pow(delta, n)
        return f, f * delta / (n + 1.0)
    return k * delta, 0.5 * k * delta ** 2


@njit(**SCALAR)
def friction(mu, v_eps, p, v_t):
    """Regularised Coulomb friction of a contact pressed with normal force p, sliding at
    v_t: the force along the sliding direction, -mu p v_t / sqrt(v_t^2 + v_eps^2) (it
    reaches mu p well above v_eps; a body held on a slope creeps at a speed of order v_eps)."""
    return -mu * p * v_t / math.sqrt(v_t * v_t + v_eps * v_eps)


@njit(**SCALAR)
def normal_force(law, delta, delta_dot, v0):
    """(force, stored energy, dissipated power) of one contact at compression delta > 0
    closing at delta_dot, v0 its approach speed at onset. law = (elastic law code, damping
    code, k, exponent n, viscous coefficient c, restitution factor chi, ramp depth d_r)."""
    code, damping, k, n, c, chi, ramp = law
    f_el, energy = elastic(code, k, n, delta)
    if damping == DAMPING_NONE:
        return f_el, energy, 0.0
    if damping == DAMPING_VISCOUS:
        f = f_el + c * min(delta / ramp, 1.0) * delta_dot
    else:
        f = f_el * (1.0 + chi * delta_dot / v0)
    f = max(f, 0.0)
    return f, energy, (f - f_el) * delta_dot


@njit(**SCALAR)
def bristle(limit, k, c, d, v_t):
    """Bristle friction of a contact whose bristle (a tangential spring k with a dashpot c
    to an anchor on the ground) is stretched by d and slides at v_t: -k d - c v_t, never
    beyond the Coulomb force mu p = k limit. In stick the pin rides on the spring, whose
    frequency an explicit step resolves, where the regularised law's slope mu p / v_eps
    is a stiff damper; the anchor slips (model/ground/grip.py) where the spring exceeds mu p."""
    f_max = k * limit
    return min(max(-k * d - c * v_t, -f_max), f_max)
