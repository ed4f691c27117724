"""Normal-force laws of the penalty contacts, written once for every contact kind
(wheel-track, ground-track, corner-track), by name in two tables: ELASTIC_LAWS, the pad's
spring (contact.law), and DAMPING_LAWS, the damping term added to it (contact.damping).
A row holds what the rest of the code asks of a law: its name and code, its formula and
source, the scenario value its coefficient comes from, whether it needs each contact's
approach speed remembered, and its compiled function; laws_jit.py compiles the dispatch
by code from the rows.

delta (d) is the pad compression (> 0 in contact), d' its rate (> 0 closing), v0 the
approach speed remembered from the contact's onset, c the viscous coefficient of the
contact kind (2 zeta sqrt(k m_pin): docs/model.md), chi the restitution factor of the
laws by restitution, d_r the viscous dashpot's ramp depth. The total force never pulls:
max(F, 0).

A new law is its compiled function (in laws_jit.py, beside its kin) and its row here,
with a code of its own, and its test. A law defined outside the package (a test, a
plug-in) is added with DAMPING_LAWS.add(row), its force the function itself: the
scenario checks take it at once, the kernels only if compiled after it, into a cache of
their own (laws_jit.py says why).

Plain Python: scenario validation reads the tables without a compiler.
"""

import math
from collections.abc import Callable
from typing import NamedTuple

from ..core.indices import P_FRICTION, P_FRICTION_LAW, P_SOIL


class ElasticLaw(NamedTuple):
    """A row of ELASTIC_LAWS: the pad's spring."""

    name: str           # contact.law
    code: int           # par[P_CONTACT_LAW]
    formula: str        # F_el(d)
    source: str
    force: object       # compiled (k, n, d) -> (F_el, stored energy): a name in laws_jit.py,
                        # "package.module:function", or the function
    parameter: str = ""  # the scenario value its exponent n comes from (else n = 1)


class DampingLaw(NamedTuple):
    """A row of DAMPING_LAWS: the damping term added to the elastic force F_el."""

    name: str           # contact.damping
    code: int           # par[P_CONTACT_DAMPING]
    formula: str        # F(d, d')
    source: str
    force: object       # compiled (F_el, d, d', v0, c, chi, d_r) -> F before max(F, 0): a
                        # name in laws_jit.py, "package.module:function", or the function
    parameter: str = ""  # the scenario value its coefficient comes from: contact.damping_ratio
                         # (c = 2 zeta sqrt(k m_pin), per contact kind) or contact.restitution
    coefficient: Callable[[float], float] | None = None  # chi(e), for the laws by restitution
    needs_approach_speed: bool = False  # v0 remembered per contact pair from its onset (onsets.py;
                                        # the event location ends a step at each new onset)
    ramps_in: bool = False   # its dashpot ramps in over d_r: the ramp's end is a kink of the
                             # force, where the event location ends steps as at an onset


class LawTable:
    """Laws by name (the scenario's value), each with a code of its own (the parameter
    vector's), in the order they were written. Iterating gives the names; str() the
    allowed values as scenario validation prints them."""

    def __init__(self, parameter, rows):
        self.parameter = parameter
        self._rows = {}
        for row in rows:
            self.add(row)

    def add(self, row):
        """One law more, checked for a name and a code of its own."""
        if not isinstance(row.code, int) or row.code < 0:
            raise ValueError(f"{self.parameter} = {row.name!r}: the code must be an integer >= 0")
        for other in self._rows.values():
            if other.name == row.name or other.code == row.code:
                raise ValueError(
                    f"{self.parameter} = {row.name!r} (code {row.code}) clashes with {other.name!r} "
                    f"(code {other.code}): a law needs a name and a code of its own"
                )
        self._rows[row.name] = row

    def remove(self, name):
        """Take a law added with add() out again (a test's)."""
        del self._rows[name]

    def __getitem__(self, name):
        return self._rows[name]

    def __contains__(self, name):
        return name in self._rows

    def __iter__(self):
        return iter(self._rows)

    def __len__(self):
        return len(self._rows)

    def rows(self):
        return tuple(self._rows.values())

    def names(self, **flags):
        """The names of the laws whose fields equal flags (e.g. needs_approach_speed=False)."""
        return [r.name for r in self._rows.values() if all(getattr(r, k) == v for k, v in flags.items())]

    def __str__(self):
        return "one of " + ", ".join(self._rows)


# chi(e) of the laws by restitution: Hunt & Crossley's form F = K d^n (1 + chi d'/v0), whose
# authors differ in chi, each chosen so that an impact at v0 rebounds at about e v0
def hunt_crossley(e):
    return 1.5 * (1.0 - e)


def lankarani_nikravesh(e):
    return 0.75 * (1.0 - e * e)


def flores(e):
    return 8.0 * (1.0 - e) / (5.0 * e)


ELASTIC_LAWS = LawTable("contact.law", [
    ElasticLaw(
        "linear", 0, formula="K d", force="linear",
        source="Lee (KSME Int. J., 2000), Eqs. (4), (6): the paper's pads",
    ),
    ElasticLaw(
        "power", 1, formula="K d^n", force="power", parameter="contact.exponent",
        source="Hertz (J. reine angew. Math. 92, 1882): n = 3/2 for two spheres",
    ),
])

DAMPING_LAWS = LawTable("contact.damping", [
    DampingLaw(
        "none", 0, formula="K d^n", force="undamped",
        source="Lee (2000): the paper's pads give back all they store",
    ),
    DampingLaw(
        "viscous", 1, formula="K d^n + c min(d / d_r, 1) d'", force="viscous",
        parameter="contact.damping_ratio", ramps_in=True,
        source="Kelvin-Voigt's spring and dashpot, the dashpot ramped in over d_r as in ADAMS' IMPACT "
        "function so that the force does not jump at first touch",
    ),
    DampingLaw(
        "hunt_crossley", 2, formula="K d^n (1 + 3(1 - e)/2 d'/v0)", force="hysteresis",
        parameter="contact.restitution", coefficient=hunt_crossley, needs_approach_speed=True,
        source="Hunt & Crossley (J. Appl. Mech. 42, 1975)",
    ),
    DampingLaw(
        "lankarani_nikravesh", 3, formula="K d^n (1 + 3(1 - e^2)/4 d'/v0)", force="hysteresis",
        parameter="contact.restitution", coefficient=lankarani_nikravesh, needs_approach_speed=True,
        source="Lankarani & Nikravesh (J. Mech. Des. 112, 1990)",
    ),
    DampingLaw(
        "flores", 4, formula="K d^n (1 + 8(1 - e)/(5 e) d'/v0)", force="hysteresis",
        parameter="contact.restitution", coefficient=flores, needs_approach_speed=True,
        source="Flores et al. (Mech. Mach. Theory 46, 2011)",
    ),
])

# The paper's laws, which the kernels treat apart: its linear undamped spring takes no call
# (track_contacts._pad), and no damping adds nothing and dissipates nothing. The sprocket
# teeth have their own dashpot, the viscous law's (model/dynamics/closed_track_jit.py).
LAW_LINEAR = ELASTIC_LAWS["linear"].code
DAMPING_NONE = DAMPING_LAWS["none"].code
DAMPING_VISCOUS = DAMPING_LAWS["viscous"].code

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


def damping_ratio_for_restitution(e):
    """zeta of a linear spring-dashpot that rebounds with restitution e (docs/model.md)."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    le = fm.log(e)
    return -le / math.sqrt(math.pi * math.pi + le * le)
