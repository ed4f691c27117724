"""Bristle friction between the track's pins and rigid ground, compiled: each pin on the
ground holds a bristle, a tangential spring with a dashpot to an anchor (ModelArrays.touchdown)
that stays where the pin touched down while the bristle carries less than mu p, and is dragged
along while the pin slides (the force then at mu p). The anchor moves only after an accepted
step (remember_grip), so a rejected step leaves no trace, and it moves so that the force at the
step's end stays what the step ended with (the next step starts from that derivative); within a
step the force is the spring's and the dashpot's, capped at mu p (laws_jit.bristle), a
continuous function of the state. A pin on two segments at once (the paper's geometry at a
concave corner) holds its bristle on the first; the regularised law acts on the other."""

import math

from numba import njit

from ..contact.laws import FRICTION_BRISTLE
from ..contact.laws_jit import bristle
from ..core.indices import (
    G_FORCE,
    G_LIMIT,
    G_SPEED,
    G_TX,
    G_TY,
    P_BRISTLE_C,
    P_BRISTLE_K,
    P_FRICTION,
    P_FRICTION_LAW,
    P_SOIL,
)
from ..core.jit import BORROW, INLINE


@njit(**INLINE)
def uses_bristle(par):
    """On soft soil the soil's shear replaces friction and the anchors are the soil's."""
    return par[P_FRICTION] > 0.0 and par[P_FRICTION_LAW] == FRICTION_BRISTLE and par[P_SOIL] == 0.0


@njit(**INLINE)
def bristle_stretch(b, apos, anchor, tx, ty):
    """How far pin b is from its anchor along the ground's unit tangent (0: no anchor yet,
    the pin touched down in this step)."""
    if anchor[b, 0] != anchor[b, 0]:
        return 0.0
    return (apos[b, 0] - anchor[b, 0]) * tx + (apos[b, 1] - anchor[b, 1]) * ty


@njit(**INLINE)
def pin_grip(b, apos, avel, t, p, par, anchor, grip):
    """(friction force along the unit tangent t, its dissipated power) of pin b pressed on
    the ground with normal force p; keeps the slip limit and t in grip for remember_grip."""
    tx, ty = t
    k = par[P_BRISTLE_K]
    limit = par[P_FRICTION] * p / k
    v_t = avel[b, 0] * tx + avel[b, 1] * ty
    f = bristle(limit, k, par[P_BRISTLE_C], bristle_stretch(b, apos, anchor, tx, ty), v_t)
    grip[b, G_LIMIT] = limit
    grip[b, G_TX] = tx
    grip[b, G_TY] = ty
    grip[b, G_FORCE] = f
    grip[b, G_SPEED] = v_t
    return f, -f * v_t


@njit(**BORROW)
def remember_grip(m, w):
    """After an accepted step (w: the evaluation at its end): a pin that touched down anchors
    its bristle where it is; one whose force is at mu p (sliding) drags its anchor to where
    spring and dashpot give that force, -k_t d - c v_t = f, so the force stays f; one that
    left the ground forgets its anchor."""
    if not uses_bristle(m.par):
        return
    anchor, grip = m.touchdown, w.grip
    for b in range(grip.shape[0]):
        limit = grip[b, G_LIMIT]
        if limit != limit:
            anchor[b, 0] = math.nan
            anchor[b, 1] = math.nan
        elif anchor[b, 0] != anchor[b, 0]:
            anchor[b, 0] = w.apos[b, 0]
            anchor[b, 1] = w.apos[b, 1]
        else:
            k, f = m.par[P_BRISTLE_K], grip[b, G_FORCE]
            if abs(f) >= k * limit:      # capped (laws_jit.bristle returns k limit exactly)
                d = bristle_stretch(b, w.apos, anchor, grip[b, G_TX], grip[b, G_TY])
                slide = d - (-f - m.par[P_BRISTLE_C] * grip[b, G_SPEED]) / k
                anchor[b, 0] += slide * grip[b, G_TX]
                anchor[b, 1] += slide * grip[b, G_TY]
