"""The IMEX integrators of the reduced solver (method = "ark548l2sa", "ark436l2sa"): the
pins' block Jacobian, agreement with the explicit pairs, convergence as the tolerance
tightens, and the stuck pins' stiffness no longer setting the step."""

import importlib

import numpy as np
import pytest

import trackbench as tb
from trackbench.model.core import indices as L
from trackbench.model.dynamics.rhs import rhs
from trackbench.solvers.common.pin_jacobian import SQRT_EPS, jacobian_work, pin_jacobian, ring_colours
from trackbench.solvers.registry import SOLVERS, run_function

S = importlib.import_module("trackbench.run.simulate")
CLOSED = {"track.layout": "closed", "preset": "damped", "contact.friction": 0.6,
          "drive.kind": "speed", "drive.target": 10.0}
IMPLICIT = ("ark548l2sa", "ark436l2sa")


@pytest.mark.parametrize("n, closed", [(6, True), (7, True), (8, True), (64, True), (9, False), (60, False)])
def test_pins_of_one_colour_are_three_apart(n, closed):
    colours = ring_colours(n, closed)
    assert sorted(b for row in colours for b in row if b >= 0) == list(range(n))
    for row in colours:
        pins = [b for b in row if b >= 0]
        for i, a in enumerate(pins):
            for b in pins[i + 1:]:
                d = abs(a - b)
                assert (min(d, n - d) if closed else d) >= 3, (a, b)


def _state(overrides, t):
    sc = tb.Scenario.from_dict({**overrides, "duration": t})
    eq = S.equilibrium(sc)
    ground, _ = S.build_ground(sc, eq)
    model = S.Model(sc, eq, ground)
    run = run_function("reduced", "dopri5")
    y = run(model, S.initial_state(sc, eq), SOLVERS["reduced"].controls(sc)).y[-1].copy()
    return model, y


def test_pin_blocks_are_the_jacobian_velocity_columns():
    """Each pin's block, from perturbing pins three apart together, equals the columns of the
    whole Jacobian taken one component at a time (the pins' coupling stays outside)."""
    model, y = _state(CLOSED, 0.02)
    m, w = model.arrays, model.work
    ny = y.size
    diag = np.empty(L.n_diag(model.nw, model.n_links))
    f0 = np.empty(ny)
    rhs(y, m, w, f0, diag)
    jw = jacobian_work(model, ny)
    n_rhs = pin_jacobian(y, f0, m, w, jw, diag)
    assert n_rhs == jw.colours.shape[0] * 2   # two velocity columns per colour, whatever the pins
    fp = np.empty(ny)
    worst = 0.0
    for b in range(0, jw.blk.shape[0], 5):
        for j in (2, 3):
            k = jw.blk[b, j]
            yp = y.copy()
            yp[k] += SQRT_EPS * max(abs(y[k]), jw.scale[j])   # the kernel's own perturbation
            rhs(yp, m, w, fp, diag)
            column = (fp[jw.blk[b]] - f0[jw.blk[b]]) / (yp[k] - y[k])
            scale = max(np.abs(column).max(), 1.0)
            worst = max(worst, np.abs(jw.jac[b, 2:, j] - column[2:]).max() / scale)
    assert worst < 1e-9


def _peaks(ds):
    return np.array([ds.peak_wheel_force_y.values.max(), float(ds.wheel_force_y.values.max()),
                     float(ds.chassis_y.values[-1]), float(ds.chassis_vx.values[-1])])


@pytest.fixture(scope="module")
def closed_reference():
    return tb.simulate(tb.Scenario.from_dict({**CLOSED, "duration": 0.06, "tolerance": 1e-10}))


@pytest.mark.parametrize("method", IMPLICIT)
def test_implicit_methods_converge_to_the_explicit_reference(method, closed_reference):
    ref = _peaks(closed_reference)
    dev = []
    for tol in (1e-6, 1e-8):
        sc = tb.Scenario.from_dict({**CLOSED, "duration": 0.06, "method": method, "tolerance": tol})
        ds = tb.simulate(sc)
        assert ds.attrs["status"] == "completed" and ds.attrs["method"] == method
        dev.append(np.abs(_peaks(ds) - ref).max())
    assert dev[1] < dev[0] or dev[1] < 1e-9
    assert dev[1] < 2e-3 * np.abs(ref).max()


def test_stuck_pins_no_longer_set_the_step():
    """Flat ground, loaded pins held by friction's regularised law: DOPRI5 is held to a few
    microseconds by their -mu p / (v_eps m) eigenvalues; the IMEX pair integrates them
    implicitly and steps at its accuracy."""
    flat = {**CLOSED, "terrain.kind": "flat", "duration": 0.1, "tolerance": 1e-6}
    explicit = tb.simulate(tb.Scenario.from_dict({**flat, "method": "dopri5"}))
    imex = tb.simulate(tb.Scenario.from_dict({**flat, "method": "ark548l2sa"}))
    assert imex.attrs["steps"] < explicit.attrs["steps"] / 3
    assert abs(float(imex.chassis_vx[-1]) - float(explicit.chassis_vx[-1])) < 1e-3


def test_the_paper_layout_runs_implicitly_too():
    paper = {"duration": 0.05, "tolerance": 1e-8}
    ref = tb.simulate(tb.Scenario.from_dict({**paper, "tolerance": 1e-10}))
    ds = tb.simulate(tb.Scenario.from_dict({**paper, "method": "ark548l2sa"}))
    assert abs(float(ds.chassis_y[-1]) - float(ref.chassis_y[-1])) < 1e-6
