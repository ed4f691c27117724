"""The contact laws in a drop test (tests/drop.py): a pin meets a pad at 1 m/s. And a law
added here, not in the package: a row and a function, and it is a law like the others."""

import hashlib
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from drop import drop, restitution_law_closed_form, viscous_closed_form
from numba import njit

import trackbench as tb
from trackbench.model.contact.laws import DAMPING_LAWS, DampingLaw, damping_ratio_for_restitution
from trackbench.model.core.jit import SCALAR
from trackbench.scenario.presets import PAD_RESTITUTION

E = (0.2, 0.5, 0.75, 0.9)


@pytest.mark.parametrize("e", E)
def test_viscous_law_matches_its_closed_form(e):
    zeta = damping_ratio_for_restitution(e)
    assert drop("viscous", zeta=zeta, ramp=1e-9) == pytest.approx(viscous_closed_form(zeta), rel=0.01)


@pytest.mark.parametrize("law", ["hunt_crossley", "lankarani_nikravesh", "flores"])
@pytest.mark.parametrize("e", E)
def test_restitution_laws_match_the_energy_integral_for_any_exponent(law, e):
    want = restitution_law_closed_form(DAMPING_LAWS[law].coefficient(e))
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


# A law added by a test, with nothing in the package edited: Hunt & Crossley's form with its
# rate term squared, F = K d^n (1 + chi u |u|), u = d'/v0 (made up for this test). Its
# restitution is exact at any speed and exponent: with E = K d^(n+1)/(n+1), m v0^2 u du =
# -(1 + chi u |u|) dE; the ln(1 + chi)/(2 chi) m v0^2 stored at full compression comes back
# as -ln(1 - chi e^2)/(2 chi) m v0^2, so e = 1/sqrt(1 + chi), and the force never pulls.


@njit(**SCALAR)
def quadratic_hysteresis(f_el, delta, delta_dot, v0, c, chi, ramp):
    u = delta_dot / v0
    return f_el * (1.0 + chi * u * abs(u))


def quadratic_chi(e):
    return 1.0 / (e * e) - 1.0


QUADRATIC = DampingLaw(
    "quadratic_hysteresis", 90, formula="K d^n (1 + chi (d'/v0) |d'/v0|)", force=quadratic_hysteresis,
    parameter="contact.restitution", coefficient=quadratic_chi, needs_approach_speed=True,
    source="made up for tests/test_contact_laws.py",
)


@pytest.fixture
def quadratic():
    """QUADRATIC in the table for one test (no kernel is compiled meanwhile: one compiled
    now would take its branch into the shared cache)."""
    DAMPING_LAWS.add(QUADRATIC)
    yield QUADRATIC
    DAMPING_LAWS.remove(QUADRATIC.name)


def test_added_law_is_a_scenario_value_with_its_needs(quadratic):
    from trackbench.model.core import indices as L
    from trackbench.model.vehicle.parameters import pack

    sc = tb.Scenario.paper(**{"contact.damping": quadratic.name, "contact.restitution": 0.6})
    par, _, _ = pack(sc["vehicle"], sc["track"], sc["gravity"], sc["contact"])
    assert par[L.P_CONTACT_DAMPING] == 90 and par[L.P_RESTITUTION_FACTOR] == quadratic_chi(0.6)
    with pytest.raises(tb.ScenarioError, match="needs contact.restitution"):
        tb.Scenario.paper(**{"contact.damping": quadratic.name})
    with pytest.raises(tb.ScenarioError, match="sprocket teeth"):   # it needs the approach speed
        tb.Scenario.paper(**{"contact.damping": quadratic.name, "contact.restitution": 0.6,
                             "track.layout": "closed"})
    with pytest.raises(tb.ScenarioError, match=f"one of none, .*flores, {quadratic.name}"):
        tb.Scenario.paper(**{"contact.damping": "quadratic"})
    with pytest.raises(ValueError, match="a name and a code of its own"):
        DAMPING_LAWS.add(QUADRATIC._replace(name="other"))


def test_added_law_is_gone_with_its_row():
    with pytest.raises(tb.ScenarioError, match="contact.damping = 'quadratic_hysteresis' is not allowed"):
        tb.Scenario.paper(**{"contact.damping": QUADRATIC.name, "contact.restitution": 0.6})


def test_added_law_through_the_compiled_dispatch():
    """The dispatch damping_force compiles to, over the table with the row: the new law's
    force to the last bit, the package's laws as normal_force (compiled without it) has
    them; that normal_force gives NaN for the code it has no branch for."""
    from trackbench.model.contact.laws_jit import damping_dispatch, normal_force

    force = damping_dispatch(DAMPING_LAWS.rows() + (QUADRATIC,))
    k, delta, v0, c, chi, ramp = 1e8, 1e-4, 0.8, 2e3, 0.7, 2e-4
    f_el = k * delta    # the linear law's
    for rate in (0.3, -0.5):
        u = rate / v0
        assert force(90, (f_el, delta, rate, v0, c, chi, ramp)) == f_el * (1.0 + chi * u * abs(u))
        for law in DAMPING_LAWS.rows():
            want = normal_force((0, law.code, k, 1.0, c, chi, ramp), delta, rate, v0)[0]
            assert max(force(law.code, (f_el, delta, rate, v0, c, chi, ramp)), 0.0) == want
    assert math.isnan(normal_force((0, 90, k, 1.0, c, chi, ramp), delta, 0.3, v0)[0])


def test_a_row_names_its_function_or_holds_it():
    from trackbench.model.contact.laws_jit import compiled_law, hysteresis

    assert compiled_law(DAMPING_LAWS["flores"]) is hysteresis
    assert compiled_law(QUADRATIC) is quadratic_hysteresis
    by_path = QUADRATIC._replace(force="test_contact_laws:quadratic_hysteresis")
    assert compiled_law(by_path) is sys.modules["test_contact_laws"].quadratic_hysteresis


ADDED_RUN = """
import json, sys
sys.path.insert(0, sys.argv[1])
from test_contact_laws import QUADRATIC
from trackbench.model.contact.laws import DAMPING_LAWS
DAMPING_LAWS.add(QUADRATIC)   # before any kernel is compiled in this process
import trackbench as tb
from drop import drop
out = {"drop": [drop(QUADRATIC.name, e=0.6), drop(QUADRATIC.name, e=0.6, n=1.5, k=1e8 / 4.5e-4 ** 0.5)]}
ds = tb.simulate(tb.Scenario.paper(**{"contact.damping": QUADRATIC.name, "contact.restitution": 0.75,
                                      "duration": 0.12}))
out.update(status=ds.attrs["status"], residual=float(ds.max_energy_residual),
           dissipated=float(ds.energy_dissipated[-1]))
print(json.dumps(out))
"""


def test_added_law_runs_in_the_kernels(tmp_path):
    """The row added before the kernels are compiled, in a process of its own: normal_force
    (the drop test) and a run of the vehicle over paper_step's first impacts take it, with its
    approach-speed memory. Its kernels are cached apart (compiled once, about a minute), in a
    subfolder of the package's cache folder named by this file's source."""
    here = Path(__file__).resolve()
    shared = os.environ.get("NUMBA_CACHE_DIR")
    digest = hashlib.sha1(here.read_bytes()).hexdigest()[:12]
    cache = Path(shared) / f"added-law-{digest}" if shared else tmp_path
    path = os.pathsep.join(p for p in (str(here.parents[1]), os.environ.get("PYTHONPATH")) if p)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=path)
    run = subprocess.run([sys.executable, "-c", ADDED_RUN, str(here.parent)], env=env, capture_output=True,
                         text=True)
    assert run.returncode == 0, run.stderr[-3000:]
    out = json.loads(run.stdout.splitlines()[-1])
    assert out["drop"] == pytest.approx([0.6, 0.6], abs=1e-3)
    assert out["status"] == "completed"
    assert out["residual"] < 1e-6 and out["dissipated"] > 0.0
