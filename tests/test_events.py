"""The event location decides "in contact" exactly as the force kernels do: for random
states near contact, the pad energy summed over the pairs the event location finds in
contact (valid and gap > 0) equals the energy the kernels computed from their forces.
A pair judged differently (another side, wedge or segment rule) shows as a difference of
at least k gap^2 / 2."""

import numpy as np
import pytest

import trackbench as tb
from trackbench.model.contact.gaps import pin_cap_weight
from trackbench.model.contact.laws import GEOMETRY_CONTINUOUS
from trackbench.model.core import indices as L
from trackbench.model.core.bundles import EventWork
from trackbench.model.dynamics.reduced import reduced_rhs
from trackbench.model.vehicle.kinematics import place
from trackbench.run.simulate import Model, build_ground, equilibrium
from trackbench.solvers.common.events import _gap_end

GROUND_KINDS = (L.K_CORNER_LINK, L.K_CORNER_PIN, L.K_PIN_GROUND)


def _weight(kind, i, b, m, pins, probes, continuous):
    """How often the pair counts: a pin's cap (probes: each pin kind's probe positions) by
    gaps.pin_cap_weight; in the continuous geometry a pin meets the ground once (every
    candidate segment gives the same gap)."""
    if kind == L.K_PIN_GROUND:
        return 1 if not continuous or b == m.nbr[m.nbr_rows[kind] + i, 1] else 0
    if kind not in probes:
        return 1
    p = probes[kind][i]
    t0 = (pins[b] - pins[b - 1]) / np.linalg.norm(pins[b] - pins[b - 1])
    t1 = (pins[b + 1] - pins[b]) / np.linalg.norm(pins[b + 1] - pins[b])
    return pin_cap_weight(
        p[0], p[1], pins[b, 0], pins[b, 1], t0[0], t0[1], t1[0], t1[1], kind != L.K_CORNER_PIN, continuous
    )


def _event_energy(m, ev, pins, probes):
    """Pad energies (wheel side, ground side) over the pairs the event location calls
    active (its scratch ev placed at the state), each as often as it counts (_weight);
    pins: the pin positions with the one after the last."""
    continuous = m.par[L.P_CONTACT_GEOMETRY] == GEOMETRY_CONTINUOUS
    energy = {"wheel": 0.0, "ground": 0.0}
    for kind in range(L.N_KINDS):
        k = m.par[L.P_K_GROUND] if kind in GROUND_KINDS else m.par[L.P_K_WHEEL]
        for row in range(m.nbr_rows[kind], m.nbr_rows[kind + 1]):
            i = row - m.nbr_rows[kind]
            for j in range(m.nbr[row, L.NB_COUNT]):
                b = m.nbr[row, 1 + j]
                valid, gap = _gap_end(kind, i, b, 0, m, ev)
                if valid and gap > 0.0:
                    weight = _weight(kind, i, b, m, pins, probes, continuous)
                    energy["ground" if kind in GROUND_KINDS else "wheel"] += weight * 0.5 * k * gap * gap
    return energy


def _model(sc):
    eq = equilibrium(sc)
    return Model(sc, eq, build_ground(sc, eq)[0])


@pytest.mark.parametrize("geometry", ["paper", "continuous"])
def test_event_contact_decision_equals_the_kernels(geometry, request):
    ds = request.getfixturevalue("paper_run" if geometry == "paper" else "continuous_run")
    model = _model(tb.Scenario.paper(**{"contact.geometry": geometry}))
    m, w = model.arrays, model.work
    nq = L.n_coordinates(model.nw, model.n_links)
    off = L.pin_offset(model.nw)
    rng = np.random.default_rng(7)
    checked = {"wheel": 0, "ground": 0}
    for i in rng.choice(ds.sizes["time"], 60, replace=False):
        for _ in range(5):
            y = np.zeros(model.ny)
            y[L.Q_X], y[L.Q_Y], y[L.Q_PITCH] = (
                float(ds[v][i]) for v in ("chassis_x", "chassis_y", "chassis_pitch")
            )
            y[L.Q_ARM : L.Q_ARM + model.nw] = ds.arm_angle.values[i]
            y[off:nq:2] = ds.pin_x.values[i, 1:-1]
            y[off + 1 : nq : 2] = ds.pin_y.values[i, 1:-1]
            y[off:nq] += rng.uniform(-0.01, 0.01, nq - off)  # within a pad's depth of every threshold
            d = np.zeros(L.n_diag(model.nw, model.n_links))
            reduced_rhs(y, m, w, np.zeros_like(y), d)
            if d[L.D_STATUS] != 0.0:
                continue  # a wheel or corner through the track: the run would stop here
            place(y[:nq], m.par, m.arms, m.ends, w.apos, w.wc, w.arm)
            ev = EventWork(w.apos, w.apos, w.wc, w.wc, w.arm)
            e = _event_energy(m, ev, w.apos, {L.K_WHEEL_PIN: w.wc, L.K_CORNER_PIN: m.corners})
            assert e["wheel"] == pytest.approx(d[L.D_E_PAD_WHEEL], rel=1e-9, abs=1e-9)
            assert e["ground"] == pytest.approx(d[L.D_E_PAD_GROUND], rel=1e-9, abs=1e-9)
            checked["wheel"] += e["wheel"] > 0
            checked["ground"] += e["ground"] > 0
    assert checked["wheel"] > 100 and checked["ground"] > 100


def test_closed_event_contact_decision_equals_the_kernels():
    """The closed layout: road wheels, idler, ground and the sprocket's teeth as the event
    location sees them (its scratch placed by loop.place_closed) carry the kernels' pad
    energies, pins moved within a pad's depth of every threshold."""
    from trackbench.model.core.bundles import event_arrays
    from trackbench.model.dynamics.closed_track_jit import closed_rhs, place_closed
    from trackbench.model.vehicle.teeth_jit import tooth_shape
    from trackbench.run.simulate import initial_state
    from trackbench.solvers.common.events import _teeth_gap

    sc = tb.Scenario.from_dict({"track.layout": "closed"})
    eq = equilibrium(sc)
    model = _model(sc)
    m, w = model.arrays, model.work
    y0 = initial_state(sc, eq)
    nq, n = model.nq, model.n_links
    off = L.pin_offset(model.nw)
    i_s = L.q_sprocket(model.nw, n)
    ev = event_arrays(model.nw, n, m.guides.shape[0])
    rng = np.random.default_rng(3)
    checked = {"wheel": 0, "ground": 0, "teeth": 0}
    for _ in range(40):
        y = y0.copy()
        y[off : off + 2 * n] += rng.uniform(-0.01, 0.01, 2 * n)
        y[i_s] += rng.uniform(-0.05, 0.05)
        d = np.zeros(L.n_diag(model.nw, n))
        closed_rhs(y, m, w, np.zeros_like(y), d)
        if d[L.D_STATUS] != 0.0:
            continue
        place_closed(y[:nq], m, ev.pins0, ev.wheels0, ev.arm, ev.guides0)
        pins = np.vstack([ev.pins0, ev.pins0[1]])  # pin 1 after pin n_links
        energy = _event_energy(
            m, ev, pins, {L.K_WHEEL_PIN: ev.wheels0, L.K_GUIDE_PIN: ev.guides0, L.K_CORNER_PIN: m.corners}
        )
        teeth = 0.0
        for b in range(1, n + 1):
            g = _teeth_gap(
                ev.pins0[b, 0],
                ev.pins0[b, 1],
                (y[L.Q_X], y[L.Q_Y], y[L.Q_PITCH], y[i_s]),
                m.loop,
                tooth_shape(m.loop),
            )
            teeth += 0.5 * m.loop[L.LP_TOOTH_STIFFNESS] * g * g if g > 0.0 else 0.0
        assert energy["wheel"] + teeth == pytest.approx(d[L.D_E_PAD_WHEEL], rel=1e-9, abs=1e-9)
        assert energy["ground"] == pytest.approx(d[L.D_E_PAD_GROUND], rel=1e-9, abs=1e-9)
        checked["wheel"] += energy["wheel"] > 0
        checked["ground"] += energy["ground"] > 0
        checked["teeth"] += teeth > 0
    assert min(checked.values()) > 20
