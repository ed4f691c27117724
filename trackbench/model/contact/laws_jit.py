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
def bristle(f_max, k, c, z, v_t):
    """(friction force, dz/dt) of a bristle, a tangential spring k with a dashpot c, deflected
    by z on a contact pressed with mu p = f_max whose pin slides at v_t. Sticking, the pin
    rides on spring and dashpot: -k z - c v_t, and z follows the pin (dz/dt = v_t). Beyond
    mu p either way the bristle slips: the force is mu p, and z moves so that spring and
    dashpot carry just that, -k z - c dz/dt = -+mu p. Both are one Lipschitz-continuous
    function of (z, v_t, f_max); off the ground (f_max = 0) the spring relaxes through its
    dashpot, dz/dt = -k z / c. The stiffest rate is k / c (sliding) or the stick frequency
    sqrt(k / m_pin), both below the pads' own, where the regularised law's slope mu p / v_eps
    is a stiff damper."""
    f = -k * z - c * v_t
    if f > f_max:
        return f_max, -(k * z + f_max) / c
    if f < -f_max:
        return -f_max, -(k * z - f_max) / c
    return f, v_t
