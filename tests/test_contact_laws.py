"""The contact laws in a drop test (tests/drop.py): a pin meets a pad at 1 m/s."""

import math

import numpy as np
import pytest
from drop import drop, restitution_law_closed_form, viscous_closed_form

import trackbench as tb
from trackbench.model.contact.laws import DAMPINGS, damping_ratio_for_restitution, restitution_factor
from trackbench.scenario.presets import PAD_RESTITUTION

E = (0.2, 0.5, 0.75, 0.9)


@pytest.mark.parametrize("e", E)
def test_viscous_law_matches_its_closed_form(e):
    zeta = damping_ratio_for_restitution(e)
    assert drop("viscous", zeta=zeta, ramp=1e-9) == pytest.approx(viscous_closed_form(zeta), rel=0.01)


@pytest.mark.parametrize("law", ["hunt_crossley", "lankarani_nikravesh", "flores"])
@pytest.mark.parametrize("e", E)
def test_restitution_laws_match_the_energy_integral_for_any_exponent(law, e):
    want = restitution_law_closed_form(restitution_factor(DAMPINGS[law], e))
    assert drop(law, e=e, n=1.0) == pytest.approx(want, abs=1e-3)
    assert drop(law, e=e, n=1.5, k=1e8 / math.sqrt(4.5e-4)) == pytest.approx(want, abs=1e-3)


def test_damped_preset_rebounds_with_the_restitution_it_states():
    sc = tb.Scenario.paper(preset="damped")
    got = drop("viscous", zeta=sc["contact.damping_ratio"], ramp=sc["contact.damping_ramp"])
    assert got == pytest.approx(PAD_RESTITUTION, rel=0.02)


def test_no_damping_is_elastic_and_force_never_pulls():
    assert drop("none") == pytest.approx(1.0, abs=1e-6)
    # a strongly damped viscous contact would pull on the way out; it lets go instead
    assert drop("viscous", zeta=0.9, ramp=1e-9) > 0.0


@pytest.mark.parametrize("k", [1e8, 3.16e9])
def test_power_law_vehicle_starts_from_equilibrium(k):
    """A power law has no stiffness at zero compression, where the equilibrium's Newton
    iteration starts: it is reached by continuation from the linear law."""
    from trackbench.run.simulate import equilibrium

    sc = tb.Scenario.paper(
        **{
            "contact.law": "power",
            "contact.exponent": 1.5,
            "track.wheel_stiffness": k,
            "track.ground_stiffness": k,
        }
    )
    eq = equilibrium(sc)
    assert eq.residual < 1e-6 * eq.weight
    assert eq.ground_force == pytest.approx(eq.weight, rel=1e-9)
    # softer pads than the paper's at these loads (compressions of 0.5-5 mm instead of 0.4 mm)
    linear = equilibrium(tb.Scenario.paper())
    assert eq.q[1] < linear.q[1]  # the chassis sits lower


@pytest.fixture(scope="module")
def sliding():
    """The paper's vehicle on flat ground with ground friction mu = 0.3: its track is bolted to
    the chassis, so the whole bottom run slides over the ground at the vehicle's speed."""
    return tb.simulate(
        tb.Scenario.paper(**{"terrain": {"kind": "flat"}, "contact.friction": 0.3, "duration": 0.3})
    )


def test_sliding_track_feels_coulomb_friction(sliding):
    ds = sliding
    assert ds.attrs["status"] == "completed"
    late = ds.time.values > 0.01
    fx, fy = ds.ground_force_x.values[late], ds.ground_force_y.values[late]
    # every pin slides at ~10 m/s >> friction_velocity: friction is mu times the normal force
    np.testing.assert_allclose(fx / fy, -0.3, rtol=1e-4)
    assert float(ds.chassis_vx[-1]) < float(ds.chassis_vx[0]) - 0.3 * 9.81 * 0.3 * 0.7
    # the work-based residual closes with friction's work; friction dissipates
    assert float(ds.max_energy_residual) < 1e-6
    assert float(ds.energy_dissipated[-1]) > 1e5


def test_regularised_friction_law():
    from trackbench.model.contact.laws_jit import friction

    assert friction(0.5, 0.01, 1000.0, 10.0) == pytest.approx(-500.0, rel=1e-6)
    assert friction(0.5, 0.01, 1000.0, -10.0) == pytest.approx(500.0, rel=1e-6)
    assert friction(0.5, 0.01, 1000.0, 0.0) == 0.0
    assert abs(friction(0.5, 0.01, 1000.0, 0.001)) < 0.1 * 500.0  # below v_eps: a viscous law


def test_bristle_sliding_track_feels_coulomb_friction():
    """Every pin sliding at ~10 m/s: the bristle law gives mu p exactly, like the regularised
    law far above v_eps."""
    ds = tb.simulate(
        tb.Scenario.paper(
            **{
                "terrain": {"kind": "flat"},
                "contact.friction": 0.3,
                "contact.friction_law": "bristle",
                "duration": 0.05,
            }
        )
    )
    late = ds.time.values > 0.01
    np.testing.assert_allclose(
        ds.ground_force_x.values[late] / ds.ground_force_y.values[late], -0.3, rtol=1e-9
    )
    assert float(abs(ds.energy_residual).max()) < 1e-6
