"""The solver seam (solvers/base.py): a solver sees the model's right-hand side, y0 and its
controls, never the scenario, and everything the rest of the package needs to know about it
is its registry entry (solvers/registry.py). A solver added at test time, by its entry alone,
validates, runs through trackbench.simulate, names its method in the outputs and streams."""

import ast
import math
import sys
import types
from pathlib import Path

import numpy as np
import pytest

import trackbench as tb
from trackbench.model.core import indices as L
from trackbench.run.simulate import controls
from trackbench.solvers import registry
from trackbench.solvers.base import Controls, allocate_outputs, trimmed
from trackbench.status import SUCCESSFUL

SOLVERS_DIR = Path(__file__).resolve().parents[1] / "trackbench" / "solvers"
FLAT = {"terrain": {"kind": "flat"}, "duration": 0.05, "output_interval": 1e-3}

# ------------------------------------------------------------------ a toy solver, in this module
H_TOY = 1e-4   # s: the toy's largest step (a fixed step, a whole number of them a sample)


def run(model, y0, controls):
    """Classical RK4 at a fixed step in plain numpy over the model's right-hand side: no error
    control, no events, no peaks (a toy: it shows the seam, it does not meet the contract)."""
    from trackbench.model.dynamics.rhs import rhs

    out = allocate_outputs(controls, model, y0.size)
    per_sample = max(1, math.ceil(controls.dt_out / H_TOY - 1e-9))
    h = controls.dt_out / per_sample
    diag = np.empty(out.diag.shape[1])

    def f(y):
        ydot = np.empty_like(y)
        rhs(y, model.arrays, model.work, ydot, diag)
        return ydot

    y = y0.copy()
    f(y)
    out.y[0], out.diag[0] = y, diag
    for i in range(1, controls.n_samples):
        for _ in range(per_sample):
            k1 = f(y)
            k2 = f(y + 0.5 * h * k1)
            k3 = f(y + 0.5 * h * k2)
            k4 = f(y + h * k3)
            y = y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        f(y)   # the sample's forces and energies
        out.y[i], out.diag[i] = y, diag
    n = controls.n_samples
    st = out.stats
    st[L.S_STATUS], st[L.S_T_FINAL], st[L.S_N_OUT] = SUCCESSFUL, (n - 1) * controls.dt_out, n
    st[L.S_STEPS], st[L.S_RHS] = (n - 1) * per_sample, (n - 1) * (4 * per_sample + 1) + 1
    st[L.S_H_MIN] = st[L.S_H_MAX] = h
    st[L.S_E0] = out.diag[0, [L.D_E_KINETIC, L.D_E_TORSION, L.D_E_TENSION, L.D_E_PAD_WHEEL,
                              L.D_E_PAD_GROUND]].sum()
    return trimmed(controls, out, {"toy_substeps": ((), per_sample, "1", "RK4 steps a sample")})


TOY = registry.SolverEntry("toy", __name__, (), "classical RK4 at a fixed step (a test's toy)",
                           label="toy-rk4")


def _relay_module():
    """A solver module wrapping the reduced solver's dopri5 (it streams: it takes a sink)."""
    mod = types.ModuleType("toy_relay")

    def relay_run(model, y0, ctl, sink=None):
        from trackbench.solvers.rk import rk_run
        assert ctl.method == "dopri5" and isinstance(ctl, Controls)
        return rk_run.run(model, y0, ctl, sink)

    mod.run = relay_run
    return mod


RELAY = registry.SolverEntry("relay", "toy_relay", ("dopri5",), "dopri5, relayed (a test's toy)",
                             closed_track=True, extended_models=True, streams=True)


@pytest.fixture
def toys(monkeypatch):
    """The toy entries registered (the registry is the only place touched)."""
    monkeypatch.setitem(registry.SOLVERS, TOY.name, TOY)
    monkeypatch.setitem(registry.SOLVERS, RELAY.name, RELAY)
    monkeypatch.setitem(sys.modules, "toy_relay", _relay_module())


# ------------------------------------------------------------------------------------ the seam


def _imports(path):
    """The absolute module names a file imports (relative imports resolved)."""
    package = ["trackbench", *path.relative_to(SOLVERS_DIR.parent).parent.parts]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            yield ".".join(base + ([node.module] if node.module else []))


def test_solvers_import_neither_the_scenario_nor_the_run_layer():
    bad = [
        f"{p.relative_to(SOLVERS_DIR.parent)}: {m}"
        for p in sorted(SOLVERS_DIR.rglob("*.py"))
        for m in _imports(p)
        if m.startswith(("trackbench.scenario", "trackbench.run"))
    ]
    assert not bad, bad


def test_the_controls_are_built_once_from_the_scenario_by_the_entry():
    sc = tb.Scenario.from_dict({"solver": "lee", "lee.accel_order": 7, "max_steps": 1234})
    c = controls(sc)
    assert c.method == "lee-rkn" and c.settings == dict(sc["lee"]) and c.settings["accel_order"] == 7
    assert (c.t_end, c.dt_out, c.rtol, c.atol, c.max_steps) == (0.5, 1e-4, 1e-9, 1e-9, 1234)
    assert c.n_samples == 5001 and c.h_max == 1e-4 and c.h0 == 1e-5
    assert tuple(c.loop_control) == (c.t_end, c.dt_out, c.rtol, c.atol, c.h0, c.h_max, c.h_min,
                                     c.max_steps, c.n_samples, c.pi_beta)
    r = controls(tb.Scenario.from_dict({"method": "dop853"}))
    assert r.method == "dop853" and r.settings == {}
    # the step controller: the plain one on the paper's layout (its golden runs), the PI one
    # (Hairer's DOPRI5 exponent) on the closed track
    assert c.pi_beta == r.pi_beta == 0.0
    assert controls(tb.Scenario.from_dict({"track.layout": "closed"})).pi_beta == 0.04


def test_a_solvers_own_settings_are_its_entrys():
    """lee.* (defaults, rules, units) come from the lee entry's Settings: the scenario's
    parameter table reads them, the study files take the table by the registry's name."""
    from trackbench.scenario import RULES, UNITS, paper_step
    from trackbench.study.spec.study_file import flatten_axes

    lee = registry.SOLVERS["lee"]
    assert lee.settings == "lee" and registry.settings_tables() == ("lee",)
    assert paper_step()["lee"] == {s.key: s.default for s in lee.setting_rules}
    for s in lee.setting_rules:
        assert RULES[f"lee.{s.key}"] == s.rule and UNITS.get(f"lee.{s.key}", "") == s.unit
    assert flatten_axes({"lee": {"accel_order": [5, 10]}}) == {"lee.accel_order": [5, 10]}


# ------------------------------------------------------------------- a solver added by its entry


def test_an_unregistered_solver_is_refused():
    with pytest.raises(tb.ScenarioError, match="solver = 'toy' is not allowed: expected one of reduced, lee"):
        tb.Scenario.from_dict({"solver": "toy"})


def test_validation_reads_the_entry(toys):
    tb.Scenario.from_dict({"solver": "toy"})
    with pytest.raises(tb.ScenarioError, match="solver = 'toy' runs the paper's model only, but "
                       "contact.friction is set; use solver = 'reduced' or solver = 'relay'"):
        tb.Scenario.from_dict({"solver": "toy", "contact.friction": 0.5})
    with pytest.raises(tb.ScenarioError, match="solver = 'toy' runs the paper's track layout only; "
                       "use solver = 'reduced', solver = 'relay'"):
        tb.Scenario.from_dict({"solver": "toy", "track.layout": "closed"})
    with pytest.raises(tb.ScenarioError, match="method = 'dop853' is not allowed: expected one of dopri5"):
        tb.Scenario.from_dict({"solver": "relay", "method": "dop853"})


def test_the_pins_tolerance_only_with_a_method_that_honours_it(toys, monkeypatch):
    """tolerance_pin_velocity is refused, in one line naming it and the methods that honour it,
    where the method ignores it; which methods honour it is their entry's pin_tolerance_methods."""
    assert registry.pin_tolerance_methods() == ("ros34pw2",)
    tb.Scenario.from_dict({"method": "ros34pw2", "tolerance_pin_velocity": 1e-5})
    for over in ({}, {"method": "ark548l2sa"}, {"solver": "lee"}, {"solver": "relay"}):
        with pytest.raises(tb.ScenarioError) as e:
            tb.Scenario.from_dict({**over, "tolerance_pin_velocity": 1e-5})
        text = str(e.value)
        assert "\n" not in text
        assert text.startswith("tolerance_pin_velocity is honoured only by method = 'ros34pw2'; "), text
    assert "method 'lee-rkn' ignores it" in str(pytest.raises(
        tb.ScenarioError, tb.Scenario.from_dict, {"solver": "lee", "tolerance_pin_velocity": 1e-5}).value)
    honours = registry.SolverEntry("relay", "toy_relay", ("dopri5",), "a relay that honours it",
                                   closed_track=True, extended_models=True, streams=True,
                                   pin_tolerance_methods=("dopri5",))
    monkeypatch.setitem(registry.SOLVERS, "relay", honours)
    tb.Scenario.from_dict({"solver": "relay", "tolerance_pin_velocity": 1e-5})
    with pytest.raises(tb.ScenarioError, match="honoured only by method = 'dopri5', 'ros34pw2'; "
                       "solver = 'reduced' with method 'dopri5' ignores it"):
        tb.Scenario.from_dict({"tolerance_pin_velocity": 1e-5})


def test_a_toy_solver_runs_through_simulate(toys):
    """The toy RK4 (fixed step 1e-4 s) follows dopri5 on flat ground; the outputs name it."""
    ds = tb.simulate(tb.Scenario.from_dict({**FLAT, "solver": "toy"}))
    ref = tb.simulate(tb.Scenario.from_dict(FLAT))
    assert ds.attrs["status"] == "completed"
    assert (ds.attrs["solver"], ds.attrs["method"]) == ("toy", "toy-rk4") and int(ds.toy_substeps) == 10
    assert ds.attrs["steps"] == 500 and ds.sizes["time"] == ref.sizes["time"] == 51
    for name in ("chassis_x", "chassis_y", "pin_y"):
        assert np.abs(ds[name].values - ref[name].values).max() < 1e-5, name
    assert np.abs(ds.wheel_force_y.values - ref.wheel_force_y.values).max() < 1e-3 * np.abs(
        ref.wheel_force_y.values).max()


def test_a_relayed_solver_streams_and_keeps_the_bits(toys, tmp_path):
    """Streaming asks the entry (streams, and its controls' samples): the relay is streamed
    to its file in two chunks, and its arrays are the reduced solver's bit for bit."""
    import xarray as xr

    from trackbench.run.stream import stream_run, streamable

    long = {**FLAT, "duration": 0.5, "output_interval": 1e-4}   # 5001 samples: two chunks
    toy, relay = (tb.Scenario.from_dict({**long, "solver": s}) for s in ("toy", "relay"))
    assert streamable(relay) and not streamable(toy)
    path, ok = stream_run(relay, tmp_path / "run.nc", tmp_path / "run.failed.nc")
    ref = tb.simulate(tb.Scenario.from_dict(long))
    assert ok
    with xr.open_dataset(path) as f:
        assert (f.attrs["solver"], f.attrs["method"]) == ("relay", "dopri5")
        for name in ("chassis_y", "wheel_force_y", "pin_x"):
            assert np.array_equal(f[name].values, ref[name].values), name
