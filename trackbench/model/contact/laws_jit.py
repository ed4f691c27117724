"""The normal-force laws of the penalty contacts compiled, and their dispatch by code
generated from the tables of laws.py (which has the formulas, their sources and the codes).

Each row of a table names its compiled function; elastic_force and damping_force (and the
flags needs_approach_speed and ramps_in) are compiled, when a kernel that calls them is
first compiled, into an if-chain over the rows as they stand then (LLVM inlines it: one
compare per row before the law's own arithmetic). The compiled kernels are cached in a
folder named by the package's compiled sources (trackbench/_jitcache.py), the tables
among them, so a row written in laws.py reaches them. A law added from outside
(DAMPING_LAWS.add) is only in kernels compiled after it, in a process whose
NUMBA_CACHE_DIR is its own: the shared folder holds kernels compiled without it, which
would be loaded instead, and must not take kernels compiled with it. Kernels without its
branch give NaN for its force: the run fails (at its equilibrium).
"""

import importlib
import math
import sys

from numba import njit
from numba.extending import overload

from ..core import fixed_math as fm
from ..core.jit import GENERATED, SCALAR
from .laws import DAMPING_LAWS, DAMPING_NONE, ELASTIC_LAWS

# The elastic laws (ELASTIC_LAWS): (k, n, d) -> (force, stored energy) at compression d > 0.


@njit(**SCALAR)
def linear(k, n, delta):
    """The paper's pad spring, K d."""
    return k * delta, 0.5 * k * delta ** 2


@njit(**SCALAR)
def power(k, n, delta):
    """K d^n, its energy K d^(n + 1) / (n + 1)."""
    f = k * fm.pow(delta, n)
    return f, f * delta / (n + 1.0)


# The damping laws (DAMPING_LAWS): the force before max(F, 0), from the elastic force f_el at
# compression d closing at d', v0 the approach speed at the contact's onset (1 for the laws
# that need none), c the viscous coefficient, chi the restitution factor, d_r the ramp depth.


@njit(**SCALAR)
def undamped(f_el, delta, delta_dot, v0, c, chi, ramp):
    """No damping."""
    return f_el


@njit(**SCALAR)
def viscous(f_el, delta, delta_dot, v0, c, chi, ramp):
    """A dashpot c d' beside the spring, ramped in over the depth d_r."""
    return f_el + c * min(delta / ramp, 1.0) * delta_dot


@njit(**SCALAR)
def hysteresis(f_el, delta, delta_dot, v0, c, chi, ramp):
    """Hunt & Crossley's hysteresis damping, F_el (1 + chi d'/v0), chi from the restitution."""
    return f_el * (1.0 + chi * delta_dot / v0)


def elastic_force(code, k, n, delta):
    """(force, stored energy) of the pad spring of ELASTIC_LAWS' law `code` at compression
    delta > 0. Compiled only: the dispatch over the table's rows."""
    raise NotImplementedError("compiled only")


def damping_force(code, f_el, delta, delta_dot, v0, c, chi, ramp):
    """The force of DAMPING_LAWS' law `code` before max(F, 0) (arguments: see the damping
    laws above). Compiled only: the dispatch over the table's rows."""
    raise NotImplementedError("compiled only")


def needs_approach_speed(code):
    """Does DAMPING_LAWS' law `code` need each contact's approach speed remembered from its
    onset (onsets.py)? Compiled only, from the rows' flags."""
    raise NotImplementedError("compiled only")


def ramps_in(code):
    """Does DAMPING_LAWS' law `code` ramp its dashpot in over d_r (a kink of the force where
    the event location ends steps)? Compiled only, from the rows' flags."""
    raise NotImplementedError("compiled only")


def elastic_dispatch(rows):
    """What elastic_force compiles to over these rows: (code, (k, n, delta)) -> (force, energy)."""
    return dispatch(rows, _no_elastic_law)


def damping_dispatch(rows):
    """What damping_force compiles to over these rows: (code, (f_el, delta, delta_dot, v0, c,
    chi, ramp)) -> force before max(F, 0)."""
    return dispatch(rows, _no_damping_law)


@overload(elastic_force, jit_options=GENERATED)
def _elastic_force(code, k, n, delta):
    law = elastic_dispatch(ELASTIC_LAWS.rows())
    return lambda code, k, n, delta: law(code, (k, n, delta))


@overload(damping_force, jit_options=GENERATED)
def _damping_force(code, f_el, delta, delta_dot, v0, c, chi, ramp):
    law = damping_dispatch(DAMPING_LAWS.rows())

    def damping(code, f_el, delta, delta_dot, v0, c, chi, ramp):
        return law(code, (f_el, delta, delta_dot, v0, c, chi, ramp))

    return damping


@overload(needs_approach_speed, jit_options=GENERATED)
def _needs_approach_speed(code):
    return among(tuple(r.code for r in DAMPING_LAWS.rows() if r.needs_approach_speed))


@overload(ramps_in, jit_options=GENERATED)
def _ramps_in(code):
    return among(tuple(r.code for r in DAMPING_LAWS.rows() if r.ramps_in))


def compiled_law(row):
    """A row's compiled function: its force, a name in this module, "package.module:function",
    or the function itself."""
    force = row.force
    if isinstance(force, str):
        module, _, name = force.rpartition(":")
        force = getattr(importlib.import_module(module) if module else sys.modules[__name__], name)
    return force


def dispatch(rows, unknown):
    """One compiled function of (code, args) that calls the compiled function of the row of
    that code with the tuple args: an if-chain over the rows in their order (LLVM inlines the
    links into one function); unknown(code, args) for a code without a row."""
    chosen = unknown
    for row in reversed(rows):
        chosen = _branch(row.code, compiled_law(row), chosen)
    return chosen


def _branch(code, law, otherwise):
    @njit(**GENERATED)
    def branch(which, args):
        if which == code:
            return law(*args)
        return otherwise(which, args)

    return branch


def among(codes):
    """A compiled (code) -> code in codes, the codes constants: an if-chain."""
    test = _none_of
    for code in codes:
        test = _either(code, test)
    return lambda code: test(code)


def _either(code, otherwise):
    @njit(**GENERATED)
    def either(which):
        return which == code or otherwise(which)

    return either


@njit(**SCALAR)
def _none_of(which):
    return False


@njit(**SCALAR)
def _no_elastic_law(which, args):
    """A code without a row (a law added after the kernels were compiled): NaN."""
    return math.nan, math.nan


@njit(**SCALAR)
def _no_damping_law(which, args):
    """A code without a row (a law added after the kernels were compiled): NaN."""
    return math.nan


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
    f_el, energy = elastic_force(code, k, n, delta)
    if damping == DAMPING_NONE:     # the paper's: nothing added, nothing dissipated
        return f_el, energy, 0.0
    f = max(damping_force(damping, f_el, delta, delta_dot, v0, c, chi, ramp), 0.0)
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
