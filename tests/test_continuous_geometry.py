"""contact.geometry = "continuous": the contact energy is a continuous function of the
configuration (no jump from a link to a pin, nor from a ground segment to a corner), it
gives the paper's force where one link is touched away from its pins, the forces are the
gradient of that energy, and paper_step without damping conserves energy."""

import numpy as np
import pytest
from test_contacts import RHO, K, loads

from trackbench.model.core import indices as L

STEP = ((-1000, 0.0), (0.0, 0.0), (0.0, 0.1), (1000, 0.1))


def pad_energy(pins, wheels, ground=STEP[:1] + ((1000, 0.0),), geometry="continuous"):
    _, _, diag, _ = loads(pins, wheels, ground=ground, geometry=geometry)
    assert diag[L.D_STATUS] == 0
    return diag[L.D_E_PAD_WHEEL] + diag[L.D_E_PAD_GROUND]


def largest_jump(energy, xs):
    """The largest step of energy(x) that does not shrink as its interval does: each of
    the five largest steps on the grid xs is bisected down to 1e-10 m, keeping the half
    with the larger step (a smooth variation shrinks to ~0 J, a jump stays)."""
    e = np.array([energy(x) for x in xs])
    worst = 0.0
    for i in np.argsort(np.abs(np.diff(e)))[-5:]:
        a, b, ea, eb = xs[i], xs[i + 1], e[i], e[i + 1]
        while b - a > 1e-10:
            mid = 0.5 * (a + b)
            em = energy(mid)
            if abs(em - ea) > abs(eb - em):
                b, eb = mid, em
            else:
                a, ea = mid, em
        worst = max(worst, abs(eb - ea))
    return worst, e


def bent_track(rise):
    """Three pins, the middle one at x = 0, y = 0.5; the outer ones `rise` higher (a dip,
    concave towards a wheel above) or lower (a bump, convex towards it)."""
    return [[0.19, 0.5 + rise], [0.0, 0.5], [-0.19, 0.5 + rise]]


def test_a_link_touched_away_from_its_pins_gives_the_papers_force():
    pins = [[0.38, 0.5], [0.19, 0.52], [0.0, 0.5], [-0.19, 0.5]]
    for w in ([0.30, 0.5 + 0.29], [0.09, 0.5 + 0.295], [-0.1, 0.5 + 0.285]):
        paper = loads(pins, [w])
        cont = loads(pins, [w], geometry="continuous")
        assert paper[1][0, 1] > 0.0
        for a, b in zip(paper[:3], cont[:3]):
            np.testing.assert_array_equal(a, b)
    # a corner under the middle of a link and a pin on a flat segment
    pins = [[0.38, 0.115], [0.19, 0.115], [0.0, 0.115]]
    for ground in (((-1000, 0.0), (0.25, 0.0), (0.25, 0.1), (1000, 0.1)), ((-1000, 0.1), (1000, 0.1))):
        paper, cont = (loads(pins, [[5.0, 5.0]], ground=ground, geometry=g) for g in ("paper", "continuous"))
        assert paper[2][L.D_GROUND_FY] > 0.0
        np.testing.assert_allclose(cont[0], paper[0], rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("rise", [0.02, 0.0, -0.02])
def test_wheel_energy_is_continuous_across_a_pin(rise):
    """A wheel centre 4 mm lower than touching the middle pin, slid across it over a dip, a
    straight track and a bump: in the dip the paper's energy jumps where the foot of the
    wheel centre leaves a link that is still compressed; the continuous one never jumps."""

    def energy(geometry):
        return lambda x: pad_energy(bent_track(rise), [[x, 0.5 + RHO - 0.004]], geometry=geometry)

    xs = np.linspace(-0.06, 0.06, 241)
    jump, e = largest_jump(energy("continuous"), xs)
    paper_jump, _ = largest_jump(energy("paper"), xs)
    print(f"rise {rise}: largest energy jump paper {paper_jump:.1f} J, continuous {jump:.1e} J")
    assert e[120] > 0.5 * K * 0.003**2  # in contact over the pin
    assert jump < 1e-3  # J
    if rise > 0:
        assert paper_jump > 100.0


def test_pin_energy_is_continuous_across_a_convex_corner():
    """A track pin 3 mm into its pad slid over the step's top corner (the links far from
    the corner): the paper drops the pin's segment contact where its foot leaves the top;
    the continuous geometry follows the round cap of the corner."""
    xs = np.linspace(-0.03, 0.03, 121)
    for g, jumps in (("paper", True), ("continuous", False)):
        jump, _ = largest_jump(
            lambda x: pad_energy(
                [[x + 0.25, 0.45], [x, 0.117], [x - 0.25, 0.45]], [[5.0, 5.0]], ground=STEP, geometry=g
            ),
            xs,
        )
        print(f"pin over a corner, {g}: largest energy jump {jump:.1e} J")
        assert (jump > 100.0) if jumps else (jump < 1e-3), g


def _configurations(rng):
    """Random wheel, pin and corner configurations near contact: bends both ways, the
    wheel and the step's corner near pins, pins near the corner."""
    for _ in range(40):
        rise = rng.uniform(-0.04, 0.04)
        pins = np.array(bent_track(rise)) + rng.uniform(-0.003, 0.003, (3, 2))
        w = [rng.uniform(-0.1, 0.1), 0.5 + RHO - rng.uniform(0.0005, 0.004) + rise * 0.3]
        yield pins, np.array([w]), ((-1000, 0.0), (1000, 0.0))
    for _ in range(40):
        x = rng.uniform(-0.05, 0.05)
        bend = rng.uniform(-0.03, 0.03)
        pins = np.array(
            [[x + 0.19, 0.115 + bend], [x, 0.115 + rng.uniform(-0.01, 0.0)], [x - 0.19, 0.115 + bend]]
        )
        yield pins, np.array([[5.0, 5.0]]), STEP


def test_forces_are_the_gradient_of_the_contact_energy():
    """-dE/dx by central differences equals the force on the wheel and on every pin: the
    continuous geometry is conservative (the paper's is not where its cases switch)."""
    rng = np.random.default_rng(3)
    h = 1e-7
    checked = 0
    for pins, wheels, ground in _configurations(rng):
        fpin, fwheel, diag, _ = loads(pins, wheels, ground=ground, geometry="continuous")
        if diag[L.D_STATUS] != 0 or diag[L.D_E_PAD_WHEEL] + diag[L.D_E_PAD_GROUND] == 0.0:
            continue
        bodies = [(pins, b, fpin[b]) for b in range(len(pins))] + [(wheels, 0, fwheel[0])]
        for arr, k, force in bodies:
            grad = np.zeros(2)
            for c in range(2):
                plus, minus = arr.copy(), arr.copy()
                plus[k, c] += h
                minus[k, c] -= h
                args = (plus, wheels) if arr is pins else (pins, plus)
                argm = (minus, wheels) if arr is pins else (pins, minus)
                grad[c] = (pad_energy(*args, ground=ground) - pad_energy(*argm, ground=ground)) / (2 * h)
            np.testing.assert_allclose(-grad, force, rtol=1e-5, atol=2e-3 * K * 1e-4)
        checked += 1
    assert checked > 50


def test_paper_step_conserves_energy(continuous_run):
    run = continuous_run
    assert run.attrs["status"] == "completed"
    e0 = float(run.attrs["initial_total_energy"])
    balance = run.energy_balance_error.values * e0
    print(
        f"continuous paper_step: largest jump {np.abs(np.diff(balance)).max():.3f} J, balance "
        f"{100 * np.abs(run.energy_balance_error.values).max():.2e} %"
    )
    assert np.abs(np.diff(balance)).max() < 1.0  # J, between steps
    assert np.abs(run.energy_balance_error.values).max() < 1e-4  # 0.01 %
    assert float(run.max_energy_residual) < 1e-6
    assert float(run.first_contact_time) == pytest.approx(0.0568, abs=1e-6)
