"""Normal-force laws of the penalty contacts, written once for every contact kind
(wheel-track, ground-track, corner-track): an elastic law (the paper's linear spring or
a power law K delta^n) and an optional damping term.

delta is the pad compression (> 0 in contact), delta_dot its rate (> 0 closing), v0 the
approach speed remembered from the contact's onset (the laws that need it), c the
viscous coefficient of the contact kind (2 zeta sqrt(k m_pin): docs/model.md). The
total force never pulls: max(F, 0).

Coefficients (docs/model.md, "Beyond the paper: dissipation"):
- Hunt & Crossley (J. Appl. Mech. 42, 1975):      F = K d^n (1 + 3(1 - e)/2 d'/v0)
- Lankarani & Nikravesh (J. Mech. Des. 112, 1990): F = K d^n (1 + 3(1 - e^2)/4 d'/v0)
- Flores et al. (Mech. Mach. Theory 46, 2011):     F = K d^n (1 + 8(1 - e)/(5 e) d'/v0)
- viscous (memoryless):  F = K d^n + c min(d / d_r, 1) d', the dashpot ramped in over
  the depth d_r (as ADAMS' IMPACT function) so the force does not jump at first touch.

This module holds the laws' names, codes and coefficients (plain Python: scenario
validation needs them without a compiler); the compiled law is laws_jit.py.
"""

import math

from ..core.indices import P_FRICTION, P_FRICTION_LAW, P_SOIL

# contact.law
LAW_LINEAR = 0
LAW_POWER = 1
LAWS = {"linear": LAW_LINEAR, "power": LAW_POWER}

# contact.damping
DAMPING_NONE = 0
DAMPING_VISCOUS = 1
DAMPING_HUNT_CROSSLEY = 2
DAMPING_LANKARANI_NIKRAVESH = 3
DAMPING_FLORES = 4
DAMPINGS = {"none": DAMPING_NONE, "viscous": DAMPING_VISCOUS, "hunt_crossley": DAMPING_HUNT_CROSSLEY,
            "lankarani_nikravesh": DAMPING_LANKARANI_NIKRAVESH, "flores": DAMPING_FLORES}

# contact.geometry: how a wheel or a ground corner meets the track near a pin
GEOMETRY_PAPER = 0        # docs/model.md: a link where the foot lies on it, else the pin in the convex wedge
GEOMETRY_CONTINUOUS = 1   # the union of link pads with round caps at the pins (gaps.pin_cap_weight)
GEOMETRIES = {"paper": GEOMETRY_PAPER, "continuous": GEOMETRY_CONTINUOUS}

# Friction between the track's pins and rigid ground (docs/model.md, "Beyond the paper: ground friction")
FRICTION_REGULARISED = 0  # -mu p v_t / sqrt(v_t^2 + v_eps^2): no memory, stiff in stick
FRICTION_BRISTLE = 1      # a tangential spring and dashpot whose deflection slips at mu p (a state)
FRICTION_LAWS = {"regularised": FRICTION_REGULARISED, "bristle": FRICTION_BRISTLE}
BRISTLE_DAMPING_RATIO = 1.0   # the bristle's dashpot: critical for one pin on its spring


def bristle_active(par):
    """The bristle law acts (and the state holds a bristle deflection per free pin): friction
    on rigid ground with contact.friction_law = "bristle" (on soft soil the soil's shear
    replaces friction). Compiled as model/ground/grip.uses_bristle."""
    return par[P_FRICTION] > 0.0 and par[P_FRICTION_LAW] == FRICTION_BRISTLE and par[P_SOIL] == 0.0


def restitution_factor(damping, e):
    """The factor chi of F = K d^n (1 + chi d'/v0) for a restitution-based law."""
    if damping == DAMPING_HUNT_CROSSLEY:
        return 1.5 * (1.0 - e)
    if damping == DAMPING_LANKARANI_NIKRAVESH:
        return 0.75 * (1.0 - e * e)
    if damping == DAMPING_FLORES:
        return 8.0 * (1.0 - e) / (5.0 * e)
    return 0.0


def damping_ratio_for_restitution(e):
    """zeta of a linear spring-dashpot that rebounds with restitution e (docs/model.md)."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    le = fm.log(e)
    return -le / math.sqrt(math.pi * math.pi + le * le)
