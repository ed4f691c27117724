"""Soft soil: the preset soils, the check of `terrain.soil`, and the closed forms of
terramechanics the simulation is checked against (docs/model.md, "Beyond the paper: soft soil").

Plain Python and numpy only: scenario validation imports this module and must stay
fast, so no compiled kernel lives here.

Symbols (Wong, Theory of Ground Vehicles): z sinkage (m), b track width (m), p normal
pressure (Pa), j shear displacement (m), i slip (-), l contact length (m), A contact
area (m^2), W normal load (N).
"""

import difflib
import math
from numbers import Real

import numpy as np

RIGID = "rigid"

# the seven values of a soil table, in this order; units in SI
SOIL_KEYS = ("n", "k_c", "k_phi", "cohesion", "friction_angle", "shear_modulus",
             "unloading_stiffness")

# Sources of the numbers below:
#   [Wong]  J. Y. Wong, Theory of Ground Vehicles, table of Bekker and Mohr-Coulomb soil
#           values (as quoted in docs/model.md): n, k_c (kN/m^(n+1)), k_phi (kN/m^(n+2)),
#           c (kPa), phi (deg). Converted here to N and Pa (x 1e3), nothing else changed.
#   [Wong-K] Wong's guidance on the Janosi-Hanamoto shear deformation modulus K (as quoted
#           in docs/model.md): about 1 cm for firm sand, 2.5 cm for loose sand, 0.6 cm for clay.
#           Wong gives no K with the table, so each preset's choice is argued beside it;
#           the friction angle tells loose sand (~28 deg) from dense sand (31 deg and up).
#   [SCM-M113] Project Chrono, src/demos/vehicle/demo_M113/demo_VEH_M113_DefSoil.cpp: the
#           SCM terrain of its tracked-vehicle demo, elastic stiffness K_e = 2e8 Pa/m.
#   [SCM-LETE] Project Chrono, src/chrono_synchrono/agent/SynSCMTerrainAgent.h,
#           SCMParameters::InitializeParametersAsHard(): Wong's LETE sand values with
#           Janosi K = 1.2e-2 m and elastic stiffness K_e = 4e8 Pa/m.
# No measured per-soil unloading slope was found in public sources (Wong's repetitive-
# loading law k_u = k_0 + A_u z_u depends on the sinkage reached and could not be
# checked), so K_e is Chrono's value: its LETE sand preset for lete_sand, its tracked-
# vehicle demo for all the other soils. These are simulation-practice values, not
# measurements; K_e only has to be much steeper than the loading curve.
SOILS = {
    # Dry sand (Land Locomotion Laboratory)
    "dry_sand": {
        "n": 1.1,                       # [Wong]
        "k_c": 0.99e3,                  # [Wong] 0.99 kN/m^(n+1)
        "k_phi": 1528.43e3,             # [Wong] 1528.43 kN/m^(n+2)
        "cohesion": 1.04e3,             # [Wong] 1.04 kPa
        "friction_angle": 28.0,         # [Wong] deg
        "shear_modulus": 0.025,         # [Wong-K] loose sand: air-dry bin sand, phi only 28 deg
        "unloading_stiffness": 2e8,     # [SCM-M113]
    },
    # LETE sand (Wong)
    "lete_sand": {
        "n": 0.79,                      # [Wong]
        "k_c": 102e3,                   # [Wong] 102 kN/m^(n+1)
        "k_phi": 5301e3,                # [Wong] 5301 kN/m^(n+2)
        "cohesion": 1.3e3,              # [Wong] 1.3 kPa
        "friction_angle": 31.1,         # [Wong] deg
        "shear_modulus": 0.012,         # [Wong-K] firm sand, about 1 cm; 1.2 cm as [SCM-LETE]
        "unloading_stiffness": 4e8,     # [SCM-LETE], the one per-soil value found
    },
    # Clayey soil (Thailand), 38 % moisture
    "clayey_soil": {
        "n": 0.5,                       # [Wong]
        "k_c": 13.19e3,                 # [Wong] 13.19 kN/m^(n+1)
        "k_phi": 692.15e3,              # [Wong] 692.15 kN/m^(n+2)
        "cohesion": 4.14e3,             # [Wong] 4.14 kPa
        "friction_angle": 13.0,         # [Wong] deg
        "shear_modulus": 0.006,         # [Wong-K] clay
        "unloading_stiffness": 2e8,     # [SCM-M113]
    },
    # Heavy clay (Waterways Experiment Station), 40 % moisture
    "heavy_clay": {
        "n": 0.11,                      # [Wong]
        "k_c": 1.84e3,                  # [Wong] 1.84 kN/m^(n+1)
        "k_phi": 103.27e3,              # [Wong] 103.27 kN/m^(n+2)
        "cohesion": 20.69e3,            # [Wong] 20.69 kPa
        "friction_angle": 6.0,          # [Wong] deg
        "shear_modulus": 0.006,         # [Wong-K] clay
        "unloading_stiffness": 2e8,     # [SCM-M113]
    },
    # Upland sandy loam (Wong)
    "sandy_loam": {
        "n": 1.10,                      # [Wong]
        "k_c": 74.6e3,                  # [Wong] 74.6 kN/m^(n+1)
        "k_phi": 2080e3,                # [Wong] 2080 kN/m^(n+2)
        "cohesion": 3.3e3,              # [Wong] 3.3 kPa
        "friction_angle": 33.7,         # [Wong] deg
        "shear_modulus": 0.01,          # [Wong-K] firm sand: mostly sand, phi 33.7 deg is dense
        "unloading_stiffness": 2e8,     # [SCM-M113]
    },
}

SOIL_CHOICES = (RIGID, *SOILS)

# key -> (low, low included, high, high included, what is allowed)
_BOUNDS = {
    "n": (0.0, False, 2.0, True, "a number in (0, 2]"),
    "k_c": (0.0, True, math.inf, False, "a number >= 0 (N/m^(n+1))"),
    "k_phi": (0.0, False, math.inf, False, "a number > 0 (N/m^(n+2))"),
    "cohesion": (0.0, True, math.inf, False, "a number >= 0 (Pa)"),
    "friction_angle": (0.0, True, 60.0, False, "a number in [0, 60) (deg)"),
    "shear_modulus": (0.0, False, math.inf, False, "a number > 0 (m)"),
    "unloading_stiffness": (0.0, False, math.inf, False, "a number > 0 (Pa/m)"),
}


def resolve_soil(value, where="terrain.soil"):
    """None for "rigid", a fresh copy of a preset, or a checked table as floats.
    Anything else raises ValueError, one line naming the culprit and what is allowed."""
    if isinstance(value, str):
        return _preset(value, where)
    if isinstance(value, dict):
        return _table(value, where)
    raise ValueError(f"{where} = {value!r} is not allowed: expected {_allowed_soils()} "
                     f"or a table of {', '.join(SOIL_KEYS)}")


def _allowed_soils():
    return ", ".join(SOIL_CHOICES)


def _preset(name, where):
    if name == RIGID:
        return None
    if name in SOILS:
        return dict(SOILS[name])
    close = difflib.get_close_matches(name, SOIL_CHOICES, n=3, cutoff=0.5)
    hint = f" did you mean {', '.join(close)}?" if close else ""
    raise ValueError(f"{where} = {name!r} is not a soil:{hint} allowed: {_allowed_soils()}")


def _table(table, where):
    unknown = [k for k in table if k not in SOIL_KEYS]
    if unknown:
        key = unknown[0]
        close = difflib.get_close_matches(str(key), SOIL_KEYS, n=2, cutoff=0.5)
        hint = f" did you mean {', '.join(close)}?" if close else ""
        raise ValueError(f"{where}.{key} is not a soil value:{hint} allowed: {', '.join(SOIL_KEYS)}")
    missing = [k for k in SOIL_KEYS if k not in table]
    if missing:
        raise ValueError(f"{where} is missing {', '.join(missing)}: a soil table needs "
                         f"{', '.join(SOIL_KEYS)}")
    return {k: _soil_value(k, table[k], where) for k in SOIL_KEYS}


def _soil_value(key, value, where):
    lo, lo_in, hi, hi_in, allowed = _BOUNDS[key]
    bad = ValueError(f"{where}.{key} = {value!r} is not allowed: expected {allowed}")
    # bool is an int in Python; a True in a soil table is a mistake, not 1.0
    if isinstance(value, bool) or not isinstance(value, Real):
        raise bad
    x = float(value)
    above = x >= lo if lo_in else x > lo
    below = x <= hi if hi_in else x < hi
    if not (math.isfinite(x) and above and below):
        raise bad
    return x


# ---- closed forms (numpy arrays or floats in, the same out) ----

def _out(a):
    a = np.asarray(a, dtype=float)
    return a if a.ndim else float(a)


def sinkage_modulus(soil, b):
    """k_c / b + k_phi: Bekker's modulus of a plate (track) of width b."""
    return soil["k_c"] / b + soil["k_phi"]


def bekker_pressure(z, soil, b):
    """p = (k_c / b + k_phi) z^n on first loading; no pressure above the surface."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    z = np.asarray(z, dtype=float)
    return _out(sinkage_modulus(soil, b) * fm.vpow(np.maximum(z, 0.0), soil["n"]))


def static_sinkage(p, soil, b):
    """z = (p / (k_c / b + k_phi))^(1/n): the sinkage under a uniform pressure p (the
    inverse of bekker_pressure); a pressure <= 0 does not sink the track."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    p = np.asarray(p, dtype=float)
    return _out(fm.vpow(np.maximum(p, 0.0) / sinkage_modulus(soil, b), 1.0 / soil["n"]))


def janosi_shear(p, j, soil):
    """tau = (c + p tan phi)(1 - exp(-j / K)), Janosi-Hanamoto. The stress follows the
    sign of the shear displacement j (odd in j: slipping back reverses it); a tensile p
    adds no friction, so p is taken >= 0."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    p = np.maximum(np.asarray(p, dtype=float), 0.0)
    j = np.asarray(j, dtype=float)
    strength = soil["cohesion"] + p * fm.tan(math.radians(soil["friction_angle"]))
    return _out(np.sign(j) * strength * -fm.vexpm1(-np.abs(j) / soil["shear_modulus"]))


def wong_thrust(area, weight, length, slip, soil):
    """F = (A c + W tan phi)[1 - K/(i l)(1 - exp(-i l / K))]: Wong's tractive effort of a
    track of contact length l and area A under a uniform pressure, carrying W, at slip i
    in [0, 1] (i = 0 gives the limit 0)."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    slip = np.asarray(slip, dtype=float)
    if np.any((slip < 0.0) | (slip > 1.0)):
        raise ValueError(f"slip = {slip.tolist()!r} is not allowed: expected 0 <= slip <= 1")
    strength = area * soil["cohesion"] + weight * fm.tan(math.radians(soil["friction_angle"]))
    x = slip * np.asarray(length, dtype=float) / soil["shear_modulus"]   # j at the rear, over K
    return _out(strength * _mobilised(x))


def _mobilised(x):
    """1 - (1 - exp(-x)) / x, the share of the shear strength a uniformly loaded track
    mobilises; its series below x = 1e-3, where the closed form cancels."""
    from ..core import fixed_math as fm  # numba: loaded when first needed
    x = np.asarray(x, dtype=float)
    small = x < 1e-3
    xs = np.where(small, 1.0, x)            # keep the closed form away from x = 0
    closed = (xs + fm.vexpm1(-xs)) / xs
    series = x * (0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0)))
    return np.where(small, series, closed)
