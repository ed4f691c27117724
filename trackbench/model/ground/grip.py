"""Bristle friction between the track's pins and rigid ground, compiled: each free pin holds
a bristle, a tangential spring k_t with a dashpot c, whose deflection z along the ground is a
state of the ODE (indices.bristle_state: after the extras of y). The law (laws_jit.bristle):
sticking, the force is -k_t z - c v_t and z follows the pin; beyond mu p the bristle slips,
the force is mu p and z moves so that spring and dashpot carry it; off the ground it relaxes
through its dashpot. Its rate depends on the pin's own position, velocity and z alone.

The right-hand side copies z into Work.grip with every pin as if off the ground
(start_bristles), the pins' ground kernel evaluates the law for each pin's first ground
contact (pin_grip; at a concave corner the regularised law acts on the others), and
bristle_rates writes dz/dt into ydot with the bristles' stored energy and dissipated power."""

from numba import njit

from ..contact.laws import bristle_active
from ..contact.laws_jit import bristle
from ..core.indices import (
    D_DISSIPATION,
    D_E_PAD_GROUND,
    G_DEFLECTION,
    G_FORCE,
    G_RATE,
    G_SPEED,
    P_BRISTLE_C,
    P_BRISTLE_K,
    P_FRICTION,
)
from ..core.indices_jit import bristle_state
from ..core.jit import BORROW, INLINE

uses_bristle = njit(**INLINE)(bristle_active)

# m: a bristle off the ground relaxed below this stops relaxing. Its rate, k_t z / c < 1e-97
# m/s, is far below any tolerance, and the stop keeps subnormal numbers (z^2 below 1e-308
# after ~0.7 s in the air, z itself later), which some CPUs compute ~100x slower, out of
# every evaluation.
Z_RELAXED = 1e-100


@njit(**BORROW)
def start_bristles(y, nq, last, par, grip):
    """Before the loads: each free pin's deflection from y, and the pin as if off the ground
    (no force; its bristle relaxes through its dashpot, laws_jit.bristle with mu p = 0, down to
    Z_RELAXED) until pin_grip finds its ground contact."""
    k, c = par[P_BRISTLE_K], par[P_BRISTLE_C]
    for b in range(1, last + 1):
        z = y[bristle_state(nq, b)]
        rate = 0.0
        if abs(z) > Z_RELAXED:
            _, rate = bristle(0.0, k, c, z, 0.0)
        grip[b, G_DEFLECTION] = z
        grip[b, G_FORCE] = 0.0
        grip[b, G_SPEED] = 0.0
        grip[b, G_RATE] = rate


@njit(**INLINE)
def pin_grip(b, avel, t, p, par, grip):
    """The friction force along the unit tangent t on pin b pressed on the ground with normal
    force p; the force, the pin's speed along t and dz/dt into grip."""
    tx, ty = t
    v_t = avel[b, 0] * tx + avel[b, 1] * ty
    f, rate = bristle(par[P_FRICTION] * p, par[P_BRISTLE_K], par[P_BRISTLE_C], grip[b, G_DEFLECTION], v_t)
    grip[b, G_FORCE] = f
    grip[b, G_SPEED] = v_t
    grip[b, G_RATE] = rate
    return f


@njit(**BORROW)
def bristle_rates(ydot, nq, last, par, grip, diag):
    """dz/dt of every free pin's bristle into ydot (after the loads); its stored energy
    k_t z^2 / 2 joins the ground pads' and its dissipated power, -f v_t - k_t z dz/dt (the
    power the pin puts in less what the spring stores: the dashpot's c (dz/dt)^2 and the
    slip's mu p |v_t - dz/dt|), the dampers'."""
    k = par[P_BRISTLE_K]
    energy = 0.0
    dissipation = 0.0
    for b in range(1, last + 1):
        z = grip[b, G_DEFLECTION]
        rate = grip[b, G_RATE]
        ydot[bristle_state(nq, b)] = rate
        energy += 0.5 * k * z * z
        dissipation += -grip[b, G_FORCE] * grip[b, G_SPEED] - k * z * rate
    diag[D_E_PAD_GROUND] += energy
    diag[D_DISSIPATION] += dissipation
