"""The event location decides "in contact" exactly as the force kernels do: for random
states near contact, the pad energy summed over the pairs the event location finds in
contact (valid and gap > 0) equals the energy the kernels computed from their forces.
A pair judged differently (another side, wedge or segment rule) shows as a difference of
at least k gap^2 / 2."""

import numpy as np
import pytest

import trackbench as tb
from trackbench.model import layout as L
from trackbench.model.kinematics import place
from trackbench.model.reduced import reduced_rhs
from trackbench.simulate import Model, build_ground, equilibrium
from trackbench.solvers.events import _gap_end

GROUND_KINDS = (L.K_CORNER_LINK, L.K_CORNER_PIN, L.K_PIN_GROUND)


def _event_energy(m, w, par):
    """Pad energies (wheel side, ground side) over the pairs the event location calls active."""
    place_pins, place_wheels = w.apos.copy(), w.wc.copy()
    energy = {"wheel": 0.0, "ground": 0.0}
    for kind in range(L.N_KINDS):
        k = par[L.P_K_GROUND] if kind in GROUND_KINDS else par[L.P_K_WHEEL]
        for row in range(m.nbr_rows[kind], m.nbr_rows[kind + 1]):
            for j in range(m.nbr[row, L.NB_COUNT]):
                valid, gap = _gap_end(kind, row - m.nbr_rows[kind], m.nbr[row, 1 + j], place_pins, place_wheels, m)
                if valid and gap > 0.0:
                    energy["ground" if kind in GROUND_KINDS else "wheel"] += 0.5 * k * gap * gap
    return energy


@pytest.fixture(scope="module")
def model():
    sc = tb.Scenario.paper()
    eq = equilibrium(sc)
    return Model(sc, eq, build_ground(sc, eq)[0])


def test_event_contact_decision_equals_the_kernels(paper_run, model):
    ds = paper_run
    m, w = model.arrays, model.work
    nq = L.n_coordinates(model.nw, model.n_links)
    off = L.pin_offset(model.nw)
    rng = np.random.default_rng(7)
    checked = {"wheel": 0, "ground": 0}
    for i in rng.choice(ds.sizes["time"], 60, replace=False):
        for _ in range(5):
            y = np.zeros(2 * nq + 1)
            y[L.Q_X], y[L.Q_Y], y[L.Q_PITCH] = (float(ds[v][i]) for v in ("chassis_x", "chassis_y", "chassis_pitch"))
            y[L.Q_ARM:L.Q_ARM + model.nw] = ds.arm_angle.values[i]
            y[off:nq:2] = ds.pin_x.values[i, 1:-1]
            y[off + 1:nq:2] = ds.pin_y.values[i, 1:-1]
            y[off:nq] += rng.uniform(-0.01, 0.01, nq - off)   # within a pad's depth of every threshold
            d = np.zeros(L.n_diag(model.nw, model.n_links))
            reduced_rhs(y, m, w, np.zeros_like(y), d)
            if d[L.D_STATUS] != 0.0:
                continue   # a wheel or corner through the track: the run would stop here
            place(y[:nq], m.par, m.arms, m.ends, w.apos, w.wc, w.arm)
            e = _event_energy(m, w, m.par)
            assert e["wheel"] == pytest.approx(d[L.D_E_PAD_WHEEL], rel=1e-9, abs=1e-9)
            assert e["ground"] == pytest.approx(d[L.D_E_PAD_GROUND], rel=1e-9, abs=1e-9)
            checked["wheel"] += e["wheel"] > 0
            checked["ground"] += e["ground"] > 0
    assert checked["wheel"] > 100 and checked["ground"] > 100
