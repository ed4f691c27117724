"""The road arms beyond the paper: bump stops and the torsion bars' free angle (the ride height)."""

import math

import numpy as np
import pytest

import trackbench as tb
from trackbench.model.core import indices as L
from trackbench.model.dynamics.equilibrium import StaticProblem
from trackbench.model.vehicle.parameters import GRAVITY, paper_track, paper_vehicle
from trackbench.scenario import ScenarioError
from trackbench.solvers.equilibrium.static import solve_equilibrium


def _degrees(phi):
    """Arm angles phi as degrees below the chassis x axis (vehicle.arm_angle's convention)."""
    return np.degrees(np.asarray(phi) + math.pi)


@pytest.mark.parametrize("over, words", [
    ({"vehicle.jounce_stop_angle": 46.0}, "vehicle.jounce_stop_angle = 46 deg (wheel 1) must lie below"),
    ({"vehicle.rebound_stop_angle": [50.0, 50.0, 44.0, 50.0, 50.0]},
     "vehicle.rebound_stop_angle = 44 deg (wheel 3) must lie above"),
    ({"vehicle.bump_stop_stiffness": 1e6}, "vehicle.bump_stop_stiffness is set but no stop"),
    ({"vehicle.bump_stop_stiffness": -1.0}, "vehicle.bump_stop_stiffness = -1.0 is not allowed"),
    ({"vehicle.torsion_free_angle": [50.0, 50.0]},
     "vehicle.torsion_free_angle has 2 values for 5 road wheels"),
    ({"vehicle.jounce_stop_angle": "low"}, "vehicle.jounce_stop_angle = 'low' is not allowed"),
])
def test_bad_arm_values_fail_in_one_line(over, words):
    with pytest.raises(ScenarioError) as e:
        tb.Scenario.paper(**over)
    msg = str(e.value)
    assert "\n" not in msg and words in msg, msg


def test_vehicle_files_may_set_the_arm_options():
    from trackbench.model.vehicle.parameters import ARM_OPTIONS
    from trackbench.vehicles.loader import OPTIONAL_NAMES

    assert OPTIONAL_NAMES == {f"vehicle.{k}" for k in ARM_OPTIONS}


def test_without_the_new_keys_the_scenario_is_the_papers():
    sc = tb.Scenario.paper()
    assert not any(k in sc["vehicle"] for k in ("jounce_stop_angle", "rebound_stop_angle",
                                                 "bump_stop_stiffness", "torsion_free_angle"))


def test_a_bump_stop_pushes_the_arm_back_and_keeps_the_energy():
    """The paper's step: wheel 1 swings some 21 deg up (to 24 deg below the x axis). A jounce
    stop at 35 deg, 100 times the torsion bar's stiffness, holds it within 3 deg of the stop;
    its energy counted with the torsion bars', the work-based residual stays as small."""
    base = {"duration": 0.25}
    free = tb.simulate(tb.Scenario.paper(**base))
    stopped = tb.simulate(tb.Scenario.paper(**base, **{"vehicle.jounce_stop_angle": 35.0,
                                                       "vehicle.rebound_stop_angle": 60.0,
                                                       "vehicle.bump_stop_stiffness": 100 * 191000.0}))
    a_free = _degrees(free["arm_angle"].values[:, 0]).min()
    a_stop = _degrees(stopped["arm_angle"].values[:, 0]).min()
    print(f"wheel 1 at most {a_free:.2f} deg without, {a_stop:.2f} deg with the stop")
    assert a_free < 30.0 and 32.0 < a_stop < 35.0 and 35.0 - a_stop < (35.0 - a_free) / 3
    r_free = np.abs(free["energy_residual"].values).max()
    r_stop = np.abs(stopped["energy_residual"].values).max()
    print(f"energy residual {r_free:.2e} without, {r_stop:.2e} with")
    assert r_stop < max(10 * r_free, 1e-6)


def test_stops_not_reached_change_nothing():
    """Stops the arms never reach: the run is the paper's bit for bit (the stop's branch acts
    beyond a stop only)."""
    a = tb.simulate(tb.Scenario.paper(duration=0.05))
    b = tb.simulate(tb.Scenario.paper(duration=0.05, **{"vehicle.jounce_stop_angle": 1.0,
                                                        "vehicle.rebound_stop_angle": 89.0,
                                                        "vehicle.bump_stop_stiffness": 1e6}))
    for name in ("chassis_y", "arm_angle", "pin_y"):
        assert np.array_equal(a[name].values, b[name].values), name


def test_the_free_angle_sets_the_rest_angle_by_the_moment_balance():
    """With the free angles given, the arms rest where each torsion bar, twisted from its free
    angle, balances its arm's moment: held there, the arms need exactly those free angles; and
    the free angles the paper's arms need at 45 deg give back 45 deg."""
    v, tr = paper_vehicle(), paper_track()
    held = solve_equilibrium(v, tr, GRAVITY)
    back = solve_equilibrium({**v, "torsion_free_angle": list(_degrees(held.phi0))}, tr, GRAVITY)
    assert np.allclose(_degrees(back.q[L.Q_ARM:L.Q_ARM + 5]), 45.0, atol=1e-9, rtol=0.0)
    assert abs(back.chassis_height - held.chassis_height) < 1e-9

    freed = solve_equilibrium({**v, "torsion_free_angle": 60.0}, tr, GRAVITY)
    phi = freed.q[L.Q_ARM:L.Q_ARM + 5]
    assert np.all(_degrees(phi) < 60.0) and freed.residual < 1e-9 * freed.weight
    # the loads' moment about each pivot with the arms held there: k_t (phi - phi0) = moment
    held_there = StaticProblem({**v, "arm_angle": list(_degrees(phi))}, tr, GRAVITY)
    u = np.concatenate([[freed.q[L.Q_Y], freed.q[L.Q_PITCH]], freed.q[L.pin_offset(5):]])
    _, _, moment = held_there.residual(u)
    twist = v["torsion_stiffness"] * (phi - (math.radians(60.0) - math.pi))
    assert np.allclose(twist, moment, rtol=0.0, atol=1e-6 * np.abs(moment).max()), (twist, moment)
    assert np.allclose(freed.preload, -twist)


def test_a_scenario_with_a_free_angle_runs_from_its_rest():
    """Through the scenario: the run starts at rest where the free angle puts the arms, its
    torsion bars at the given free angles."""
    sc = tb.Scenario.paper(duration=0.02, terrain={"kind": "flat"}, speed=0.0,
                           **{"vehicle.torsion_free_angle": 60.0})
    ds = tb.simulate(sc)
    a = _degrees(ds["arm_angle"].values)
    assert np.all(a < 60.0) and np.ptp(a, axis=0).max() < 1e-3
