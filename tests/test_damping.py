"""Dissipation on the vehicle: the damped preset, link and shock-absorber dampers, the
restitution laws' approach-speed memory, bad input. Runs are short where the physics
allows; the 0.5 s paper_step runs are shared through module fixtures."""

import numpy as np
import pytest

import trackbench as tb
from trackbench.scenario import ScenarioError

DAMPED = {"preset": "damped"}
PEAKS = [
    "peak_ground_force_y",
    "peak_link_tension",
    "min_link_tension",
    "peak_chassis_ay",
    "min_chassis_ay",
    "min_chassis_vx",
]


@pytest.fixture(scope="module")
def damped_runs():
    """The damped preset on paper_step at four tolerances and five 1e-9 m nudges."""
    runs = [tb.simulate(tb.Scenario.paper(tolerance=tol, **DAMPED)) for tol in (1e-8, 1e-9, 1e-10, 1e-11)]
    runs += [tb.simulate(tb.Scenario.paper(perturbation=1e-9, seed=s, **DAMPED)) for s in range(1, 6)]
    return runs


def test_damped_peaks_are_reproducible(damped_runs):
    """The paper model's chaos is gone: every summary peak within 1 % over tolerances and nudges."""
    values = {k: [float(ds[k]) for ds in damped_runs] for k in PEAKS}
    for i in range(5):
        values[f"wheel {i + 1}"] = [float(ds.peak_wheel_force_y[i]) for ds in damped_runs]
    spread = {k: (max(v) - min(v)) / abs(np.median(v)) for k, v in values.items()}
    print({k: f"{100 * s:.3f} %" for k, s in spread.items()})
    assert max(spread.values()) < 0.01, spread
    assert all(ds.attrs["status"] == "completed" for ds in damped_runs)


def test_damped_energy_closes(damped_runs):
    ds = damped_runs[1]
    assert float(ds.max_energy_residual) < 1e-6  # dampers' work is in the residual
    dissipated = float(ds.energy_dissipated[-1])
    assert dissipated > 0.0
    # balance + dissipated stays near its start: what the paper's balance loses, the dampers took
    closed = ds.energy_balance.values + ds.energy_dissipated.values
    assert np.max(np.abs(closed - closed[0])) < 0.2 * dissipated


def test_dampers_do_not_act_on_rigid_motion():
    sc = tb.Scenario.paper(terrain={"kind": "flat"}, duration=0.5, **DAMPED)
    ds = tb.simulate(sc)
    assert ds.attrs["status"] == "completed"
    dx = ds.chassis_x.values - ds.chassis_x.values[0] - 10.0 * ds.time.values
    moved = [
        np.abs(dx).max(),
        np.abs(ds.chassis_y - ds.chassis_y[0]).max(),
        np.abs(ds.pin_y - ds.pin_y[0]).max(),
        np.abs(ds.arm_angle - ds.arm_angle[0]).max(),
    ]
    assert max(float(v) for v in moved) < 1e-7, moved
    assert float(ds.energy_dissipated[-1]) < 1e-6


@pytest.mark.parametrize("law", ["hunt_crossley", "lankarani_nikravesh", "flores"])
def test_restitution_laws_on_the_vehicle(law):
    """A law with approach-speed memory crosses the step's first impact with the energy
    closing; a tighter tolerance and a smaller first step (more rejected attempts, whose
    memory must leave no trace) give the same early peak."""
    kw = {"contact.damping": law, "contact.restitution": 0.75, "duration": 0.12}
    a = tb.simulate(tb.Scenario.paper(**kw))
    b = tb.simulate(tb.Scenario.paper(tolerance=1e-10, **kw))
    assert a.attrs["status"] == b.attrs["status"] == "completed"
    assert float(a.max_energy_residual) < 1e-6
    assert float(a.peak_wheel_force_y[0]) == pytest.approx(float(b.peak_wheel_force_y[0]), rel=1e-4)
    assert float(a.energy_dissipated[-1]) > 0.0


@pytest.mark.parametrize(
    "bad, words",
    [
        ({"contact.damping": "viscous"}, "contact.damping_ratio"),
        ({"contact.damping": "hunt_crossley"}, "contact.restitution"),
        ({"contact.damping": "flores", "contact.restitution": 1.5}, "contact.restitution"),
        ({"contact.damping": "flores", "contact.restitution": 0.0}, "contact.restitution"),
        ({"contact.damping_ratio": -0.1}, "contact.damping_ratio"),
        ({"track.link_damping": -5.0}, "track.link_damping"),
        ({"vehicle.arm_damping": [100.0, 0.0]}, "vehicle.arm_damping"),
        ({"vehicle.arm_damping": [100.0, -1.0, 0.0, 0.0, 0.0]}, "vehicle.arm_damping[1]"),
        ({"preset": "soft"}, "preset"),
        ({"preset": "damped", "solver": "lee"}, "solver = 'lee'"),
        ({"contact.geometry": "smooth"}, "contact.geometry"),
        ({"contact.geometry": "continuous", "solver": "lee"}, "contact.geometry"),
        ({"contact.friction": -0.1}, "contact.friction"),
        ({"contact.friction_velocity": 0.0}, "contact.friction_velocity"),
        ({"contact.friction": 0.5, "solver": "lee"}, "contact.friction"),
        ({"contact.friction_law": "stribeck"}, "one of regularised, bristle"),
        ({"contact.friction_stiffness": 0.0}, "contact.friction_stiffness"),
    ],
)
def test_bad_damping_input_is_one_line(bad, words):
    with pytest.raises(ScenarioError) as e:
        tb.Scenario.from_dict(bad)
    assert words in str(e.value) and "\n" not in str(e.value)


def test_preset_fills_in_and_explicit_values_win():
    sc = tb.Scenario.paper(**DAMPED)
    assert sc["contact.damping"] == "viscous" and sc["track.link_damping"] > 0
    assert [a > 0 for a in sc["vehicle.arm_damping"]] == [True, True, False, False, True]
    own = tb.Scenario.paper(preset="damped", **{"track.link_damping": 10.0})
    assert own["track.link_damping"] == 10.0 and own["contact.damping"] == "viscous"
    back = own.with_overrides({"preset": "paper"})
    assert back["contact.damping"] == "none" and back["track.link_damping"] == 10.0
    six = tb.Scenario.paper(preset="damped", **{"vehicle.n_wheels": 4, "vehicle.pivot_spacing": 1.0})
    assert len(six["vehicle.arm_damping"]) == 4
