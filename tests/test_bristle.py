"""The bristle friction law (contact.friction_law = "bristle"): its deflections are states of
the ODE (docs/model.md, "Beyond the paper: ground friction"), so a run converges as the
tolerance tightens."""

import numpy as np
import pytest

import trackbench as tb
from trackbench.model.core import indices as L
from trackbench.model.ground.terrain import build_ground
from trackbench.outputs.quantities import SUMMARY, values
from trackbench.run.assemble import Model, equilibrium, initial_state

K, C, F_MAX = 2e7, 4e4, 2e4
DRIVEN = {
    "track.layout": "closed",
    "preset": "damped",
    "contact.friction": 0.6,
    "contact.friction_law": "bristle",
    "drive.kind": "speed",
    "drive.target": 10.0,
}


def test_bristle_law_sticks_slips_and_relaxes():
    """Sticking: spring and dashpot, z follows the pin; beyond mu p either way: mu p, and z
    moves so that spring and dashpot carry it; off the ground (mu p = 0) the spring relaxes
    through its dashpot."""
    from trackbench.model.contact.laws_jit import bristle

    assert bristle(F_MAX, K, C, 1e-4, 0.0) == pytest.approx((-2e3, 0.0))  # stuck: the spring
    assert bristle(F_MAX, K, C, 1e-4, 0.01) == pytest.approx((-2e3 - 400.0, 0.01))  # and its dashpot
    for z, v, f_want in ((5e-3, 0.0, -F_MAX), (-5e-3, 0.0, F_MAX), (0.0, -10.0, F_MAX), (0.0, 10.0, -F_MAX)):
        f, rate = bristle(F_MAX, K, C, z, v)
        assert f == f_want  # mu p exactly
        assert -K * z - C * rate == pytest.approx(f, rel=1e-12)  # z moves so that the bristle carries it
    assert bristle(F_MAX, K, C, F_MAX / K, 10.0)[1] == pytest.approx(
        0.0, abs=1e-12
    )  # steady slide: z = mu p / k
    assert bristle(0.0, K, C, 1e-4, 1.0) == pytest.approx((0.0, -K * 1e-4 / C))  # off the ground
    v_slip = -(F_MAX + K * 1e-4) / C  # where it starts to slip: continuous across
    below, above = (
        bristle(F_MAX, K, C, 1e-4, v_slip * (1 - 1e-9)),
        bristle(F_MAX, K, C, 1e-4, v_slip * (1 + 1e-9)),
    )
    assert below == pytest.approx(above, rel=1e-6)


def _model(overrides):
    sc = tb.Scenario.from_dict({**DRIVEN, **overrides})
    eq = equilibrium(sc)
    return sc, eq, Model(sc, eq, build_ground(sc, eq)[0])


def test_bristle_states_follow_the_extras_and_start_at_rest():
    sc, eq, model = _model({})
    n, nq = model.n_links, model.nq
    assert model.has_bristles and model.n_bristles == n
    assert model.ny == L.n_state(nq, n) == L.n_state(nq) + n
    assert [L.bristle_state(nq, b) for b in (1, n)] == [2 * nq + L.N_Y_EXTRA, 2 * nq + L.N_Y_EXTRA + n - 1]
    y0 = initial_state(sc, eq)
    assert y0.size == model.ny and not y0[L.bristle_state(nq, 1) :].any()  # z = 0 at rest
    for other in ({"contact.friction_law": "regularised"}, {"terrain.soil": "lete_sand"}):
        sc, eq, model = _model(other)  # the regularised law, soft soil: the layout without bristles
        assert not model.has_bristles and model.ny == L.n_state(model.nq) == initial_state(sc, eq).size
    sc, eq, model = _model({"track.layout": "paper", "drive.kind": "none"})
    assert model.n_bristles == model.n_links - 1  # the paper's free pins


def test_a_bristle_rate_depends_on_its_own_pin_alone():
    """dz_b/dt depends on pin b's position and velocity and z_b only (an implicit method's
    per-pin Jacobian blocks rely on it); the rhs writes every bristle's rate."""
    from trackbench.model.dynamics.closed_track_jit import closed_rhs

    sc, eq, model = _model({"speed": 1.0, "drive.target": 1.0})
    m, w, nq = model.arrays, model.work, model.nq
    y = initial_state(sc, eq)
    first = L.bristle_state(nq, 1)
    rng = np.random.default_rng(5)
    y[first:] = rng.uniform(-2e-4, 2e-4, model.n_bristles)
    d = np.zeros(L.n_diag(model.nw, model.n_links))
    ydot = np.full_like(y, np.nan)
    closed_rhs(y, m, w, ydot, d)
    assert np.isfinite(ydot).all()
    on_ground = [b for b in range(1, model.n_links + 1) if w.grip[b, L.G_FORCE] != 0.0]
    assert len(on_ground) >= 5
    b = on_ground[len(on_ground) // 2]
    seen = set()
    for k in (L.bristle_state(nq, b), L.q_pin(model.nw, b) + 1, nq + L.q_pin(model.nw, b)):
        y1 = y.copy()
        y1[k] += 1e-5  # z_b, pin b's height, its velocity along x
        ydot1 = np.empty_like(y)
        closed_rhs(y1, m, w, ydot1, d)
        changed = set((np.flatnonzero(ydot1[first:] != ydot[first:]) + 1).tolist())
        assert changed <= {b}
        seen |= changed
    assert seen == {b}


PEAKS = [q for q in SUMMARY if q.kind == "peak"]


def _peaks(overrides):
    ds = tb.simulate(
        tb.Scenario.from_dict({**DRIVEN, "duration": 0.15, "output_interval": 1e-3, **overrides})
    )
    assert ds.attrs["status"] == "completed"
    assert float(abs(ds.energy_residual).max()) < 1e-6  # the bristles' energy is accounted for
    v = values(ds, times=False)
    return {c: v[c] for q in PEAKS for c in q.present(list(v))}


def test_bristle_peaks_converge_with_the_tolerance():
    """The paper's step with the closed track: every summary peak at tolerance 1e-8 within 1 %
    of 1e-10's, and with the pins nudged by 1e-9 m (with the anchors the old law moved between
    steps they spread 30-50 %)."""
    fine = _peaks({"tolerance": 1e-10})
    assert len(fine) >= 10
    for other in ({"tolerance": 1e-8}, {"perturbation": 1e-9, "seed": 1}):
        got = _peaks(other)
        for c, v in fine.items():
            assert got[c] == pytest.approx(v, rel=0.01), (other, c)


def test_the_imex_pairs_carry_the_bristles():
    """The additive pairs take the model's layout too (their error test and dense output
    include the deflections; the pins' Jacobian blocks leave them explicit)."""
    ds = tb.simulate(
        tb.Scenario.from_dict({**DRIVEN, "duration": 0.02, "output_interval": 1e-3, "method": "ark436l2sa"})
    )
    assert ds.attrs["status"] == "completed"
    assert float(abs(ds.energy_residual).max()) < 1e-6
    assert np.nanmax(np.abs(ds.bristle_deflection.values)) > 1e-5
