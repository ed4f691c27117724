"""Soft soil: presets in SI, the check of `terrain.soil`, and the closed forms
(Bekker, Janosi-Hanamoto, Wong's track thrust). Fast: no simulation."""

import math
import subprocess
import sys

import numpy as np
import pytest

from trackbench.model.ground.soil import (
    SOIL_KEYS,
    SOILS,
    bekker_pressure,
    janosi_shear,
    resolve_soil,
    static_sinkage,
    wong_thrust,
)

PRESETS = ("dry_sand", "lete_sand", "clayey_soil", "heavy_clay", "sandy_loam")

# Wong's table (docs/model.md) in SI: n, k_c N/m^(n+1), k_phi N/m^(n+2), c Pa, phi deg
WONG_SI = {
    "dry_sand": (1.1, 990.0, 1.52843e6, 1040.0, 28.0),
    "lete_sand": (0.79, 1.02e5, 5.301e6, 1300.0, 31.1),
    "clayey_soil": (0.5, 13190.0, 6.9215e5, 4140.0, 13.0),
    "heavy_clay": (0.11, 1840.0, 1.0327e5, 20690.0, 6.0),
    "sandy_loam": (1.10, 74600.0, 2.08e6, 3300.0, 33.7),
}


def table(**changes):
    """A valid soil table (LETE sand) with some values changed or removed (None)."""
    t = dict(SOILS["lete_sand"])
    for k, v in changes.items():
        if v is None:
            t.pop(k)
        else:
            t[k] = v
    return t


# ---- presets ----


def test_presets_are_the_five_of_the_spec():
    assert tuple(SOILS) == PRESETS
    assert all(tuple(SOILS[name]) == SOIL_KEYS for name in PRESETS)


@pytest.mark.parametrize("name", PRESETS)
def test_preset_resolves_in_si_with_positive_moduli(name):
    soil = resolve_soil(name)
    assert (soil["n"], soil["k_c"], soil["k_phi"], soil["cohesion"], soil["friction_angle"]) == WONG_SI[name]
    assert soil["k_phi"] > 0 and soil["k_c"] >= 0 and soil["cohesion"] >= 0
    assert 0.005 <= soil["shear_modulus"] <= 0.025  # Wong: 0.6 cm (clay) .. 2.5 cm (loose sand)
    assert soil["unloading_stiffness"] >= 1e8  # Pa/m, Chrono SCM values
    assert resolve_soil(dict(soil)) == soil  # a preset passes the table check


def test_lete_sand_in_si():
    soil = resolve_soil("lete_sand")
    assert soil["k_phi"] == 5.301e6 and soil["k_c"] == 1.02e5 and soil["cohesion"] == 1.3e3


def test_preset_is_a_fresh_copy():
    soil = resolve_soil("dry_sand")
    soil["k_phi"] = -1.0
    assert SOILS["dry_sand"]["k_phi"] == 1.52843e6
    assert resolve_soil("dry_sand") is not resolve_soil("dry_sand")


def test_rigid_is_none():
    assert resolve_soil("rigid") is None


def test_table_resolves_to_floats():
    soil = resolve_soil(
        {
            "n": 1,
            "k_c": 0,
            "k_phi": 2_000_000,
            "cohesion": 0,
            "friction_angle": 0,
            "shear_modulus": 0.01,
            "unloading_stiffness": 200_000_000,
        }
    )
    assert all(type(v) is float for v in soil.values())
    assert tuple(soil) == SOIL_KEYS


def test_table_accepts_the_closed_bounds():
    resolve_soil(table(n=2.0, k_c=0.0, cohesion=0.0, friction_angle=0.0))
    resolve_soil(table(n=np.float64(1.5)))


def test_module_does_not_load_numba():
    code = "import sys, trackbench.model.ground.soil; assert 'numba' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


# ---- bad input: ValueError, one line, naming the culprit ----


def raises(value, *culprits):
    with pytest.raises(ValueError) as info:
        resolve_soil(value)
    message = str(info.value)
    assert "\n" not in message
    for c in culprits:
        assert c in message, message
    return message


def test_misspelt_preset_suggests_the_closest():
    msg = raises(
        "lete_snd", "terrain.soil", "'lete_snd'", "did you mean lete_sand", "allowed: rigid, dry_sand"
    )
    assert msg.startswith("terrain.soil = 'lete_snd' is not a soil")


def test_unknown_preset_lists_the_allowed():
    raises(
        "granite", "'granite'", "rigid", "dry_sand", "lete_sand", "clayey_soil", "heavy_clay", "sandy_loam"
    )


@pytest.mark.parametrize("value", [42, None, 1.5, ["dry_sand"], ("rigid",)])
def test_neither_name_nor_table(value):
    raises(value, "terrain.soil", repr(value))


@pytest.mark.parametrize("key", SOIL_KEYS)
def test_missing_key(key):
    raises(table(**{key: None}), "terrain.soil", "missing", key)


def test_unknown_key_suggests_the_closest():
    t = table(k_phi=None)
    t["kphi"] = 5.301e6
    raises(t, "terrain.soil.kphi", "did you mean k_phi")


def test_unknown_key_without_missing_one():
    raises(table(density=1600.0), "terrain.soil.density", "allowed: n, k_c")


@pytest.mark.parametrize("bad", ["5e6", None, True, [1.0], 1j, float("nan"), float("inf")])
@pytest.mark.parametrize("key", SOIL_KEYS)
def test_non_numbers(key, bad):
    t = table()
    t[key] = bad
    raises(t, f"terrain.soil.{key}")


@pytest.mark.parametrize(
    "key,bad",
    [
        ("k_phi", 0.0),
        ("k_phi", -1e6),
        ("shear_modulus", 0.0),
        ("shear_modulus", -0.01),
        ("unloading_stiffness", 0.0),
        ("unloading_stiffness", -2e8),
        ("k_c", -1.0),
        ("cohesion", -1.0),
        ("friction_angle", -1.0),
        ("friction_angle", 60.0),
        ("friction_angle", 75.0),
        ("n", 0.0),
        ("n", -0.5),
        ("n", 2.5),
    ],
)
def test_out_of_range(key, bad):
    raises(table(**{key: bad}), f"terrain.soil.{key} = {bad!r}", "expected")


# ---- Bekker pressure-sinkage ----


@pytest.mark.parametrize("name", PRESETS)
def test_static_sinkage_inverts_bekker_pressure(name):
    soil = resolve_soil(name)
    p = np.array([1e3, 3e4, 1e5, 5e5])
    for b in (0.1, 0.3, 0.6):
        z = static_sinkage(p, soil, b)
        assert np.all(z > 0)
        np.testing.assert_allclose(bekker_pressure(z, soil, b), p, rtol=1e-12, atol=0)
        np.testing.assert_allclose(
            static_sinkage(bekker_pressure(z, soil, b), soil, b), z, rtol=1e-12, atol=0
        )


def test_bekker_pressure_by_hand():
    soil = resolve_soil("sandy_loam")
    # (74.6e3 / 0.5 + 2080e3) * 0.04^1.1
    assert bekker_pressure(0.04, soil, 0.5) == pytest.approx((149.2e3 + 2080e3) * 0.04**1.1, rel=1e-14)
    assert isinstance(bekker_pressure(0.04, soil, 0.5), float)


def test_no_pressure_above_the_surface_no_sinkage_without_pressure():
    soil = resolve_soil("heavy_clay")
    np.testing.assert_array_equal(bekker_pressure(np.array([-0.1, 0.0]), soil, 0.3), [0.0, 0.0])
    np.testing.assert_array_equal(static_sinkage(np.array([-5e3, 0.0]), soil, 0.3), [0.0, 0.0])


def test_track_width():
    soil = resolve_soil("lete_sand")
    # Bekker's size effect (k_c > 0): under the same pressure a wider plate sinks deeper ...
    assert static_sinkage(5e4, soil, 0.6) > static_sinkage(5e4, soil, 0.3)
    # ... but under the same load (per unit length) a wider track sinks less
    assert static_sinkage(1.5e4 / 0.6, soil, 0.6) < static_sinkage(1.5e4 / 0.3, soil, 0.3)


# ---- Janosi-Hanamoto shear ----


def test_janosi_limits():
    soil = resolve_soil("clayey_soil")
    p = 4e4
    strength = 4140.0 + p * math.tan(math.radians(13.0))
    assert janosi_shear(p, 0.0, soil) == 0.0
    assert janosi_shear(p, 100 * 0.006, soil) == pytest.approx(strength, rel=1e-14)
    assert janosi_shear(p, 0.006, soil) == pytest.approx(strength * (1 - math.exp(-1)), rel=1e-14)
    # small j: the initial slope is strength / K
    assert janosi_shear(p, 1e-9, soil) == pytest.approx(strength * 1e-9 / 0.006, rel=1e-6)


def test_janosi_is_odd_in_j_and_ignores_tension():
    soil = resolve_soil("dry_sand")
    j = np.array([0.001, 0.01, 0.1])
    np.testing.assert_array_equal(janosi_shear(2e4, -j, soil), -janosi_shear(2e4, j, soil))
    np.testing.assert_array_equal(janosi_shear(-2e4, j, soil), janosi_shear(0.0, j, soil))
    assert janosi_shear(0.0, 10.0, soil) == pytest.approx(1040.0, rel=1e-14)  # cohesion alone


# ---- Wong's tractive effort of a track ----


def simple_soil(**kw):
    return resolve_soil(
        {
            "n": 1.0,
            "k_c": 0.0,
            "k_phi": 1e6,
            "cohesion": 1000.0,
            "friction_angle": 45.0,
            "shear_modulus": 0.05,
            "unloading_stiffness": 2e8,
            **kw,
        }
    )


def test_wong_thrust_by_hand():
    # A = 1 m^2, W = 10 kN, l = 2 m, i = 0.05, K = 0.05 m: i l / K = 2
    # (A c + W tan 45) = 11000 N; 1 - (1 - e^-2)/2 = 1 - 0.8646647167633873/2 = 0.5676676416183064
    assert wong_thrust(1.0, 1e4, 2.0, 0.05, simple_soil()) == pytest.approx(6244.34405780137, rel=1e-13)


def test_wong_thrust_tends_to_the_shear_strength():
    soil = resolve_soil("lete_sand")
    area, weight, length = 1.8, 1.2e5, 3.0
    strength = area * 1300.0 + weight * math.tan(math.radians(31.1))
    for slip in (0.1, 0.5, 1.0):
        x = slip * length / 0.012
        f = wong_thrust(area, weight, length, slip, soil)
        assert f < strength
        assert 1 - f / strength == pytest.approx(1 / x, rel=1e-9)  # 1 - F/F_max -> K / (i l)
    big = simple_soil(shear_modulus=1e-9)
    assert wong_thrust(1.0, 1e4, 2.0, 1.0, big) == pytest.approx(11000.0, rel=1e-8)


def test_wong_thrust_tends_to_zero_with_slip():
    soil = simple_soil()
    slip = np.array([0.0, 1e-12, 1e-9, 1e-6, 1e-4])
    f = wong_thrust(1.0, 1e4, 2.0, slip, soil)
    assert f[0] == 0.0
    # small slip, x = i l / K: F ~ F_max (x/2 - x^2/6)
    x = slip[1:] * 2.0 / 0.05
    np.testing.assert_allclose(f[1:], 11000.0 * (x / 2 - x**2 / 6), rtol=1e-5)
    assert np.all(np.diff(f) > 0)


def test_wong_thrust_accurate_across_the_series_switch():
    soil = simple_soil()  # x = slip * 2 / 0.05 = 40 slip
    x = np.geomspace(1e-10, 1.0, 201)
    f = wong_thrust(1.0, 1e4, 2.0, x / 40.0, soil)
    exact = [math.fsum((-1) ** (k + 1) * xi**k / math.factorial(k + 1) for k in range(1, 40)) for xi in x]
    np.testing.assert_allclose(f, 11000.0 * np.array(exact), rtol=1e-11, atol=0)


@pytest.mark.parametrize("slip", [-0.1, 1.5])
def test_wong_thrust_slip_outside_0_1(slip):
    with pytest.raises(ValueError, match="slip"):
        wong_thrust(1.0, 1e4, 2.0, slip, simple_soil())
