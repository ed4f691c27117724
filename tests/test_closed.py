"""The closed track: sprocket, idler and tensioner, rollers, drive (model/closed.py,
model/loop.py, model/sprocket.py, model/drive.py)."""

import importlib
import json
import math

import numpy as np
import pytest

import trackbench as tb
from trackbench.model.core import indices as L
from trackbench.model.vehicle.drive import drive_torque
from trackbench.model.vehicle.teeth import profile
from trackbench.model.vehicle.teeth_jit import pin_on_sprocket
from trackbench.outputs.quantities import accounted_balance
from trackbench.scenario import ScenarioError

S = importlib.import_module("trackbench.run.simulate")

FLAT = {"track.layout": "closed", "terrain": {"kind": "flat"}}


@pytest.fixture(scope="module")
def rest():
    sc = tb.Scenario.from_dict(
        {**FLAT, "drive.kind": "speed", "drive.target": 0.0, "speed": 0.0, "duration": 0.02}
    )
    return sc, S.equilibrium(sc)


def test_rest_ground_carries_the_weight(rest):
    _, eq = rest
    assert eq.residual < 1e-6 * eq.weight
    assert abs(eq.ground_force - eq.weight) < 1e-9 * eq.weight


def _world(sc, eq, body):
    th = eq.q[L.Q_PITCH]
    c, s = math.cos(th), math.sin(th)
    return np.array([eq.q[L.Q_X] + c * body[0] - s * body[1], eq.q[L.Q_Y] + s * body[0] + c * body[1]])


def test_rest_span_tensions_balance_the_tensioner(rest):
    """The tensioner's force along the guide equals the two free spans' tensions resolved
    along it (docs/model.md: within 2 %)."""
    sc, eq = rest
    g = S.closed_parts(sc)[0]
    th = eq.q[L.Q_PITCH]
    u = np.array(
        [
            math.cos(th) * g.guide[0] - math.sin(th) * g.guide[1],
            math.sin(th) * g.guide[0] + math.cos(th) * g.guide[1],
        ]
    )
    centre = _world(sc, eq, g.idler + eq.info["idler_slide"] * g.guide)
    pins = eq.info["pins"]  # pins 1..n; link b joins pins b and b+1, link 0 pin n and pin 1
    n = len(pins)
    reach = math.hypot(sc["idler.radius"] + sc["track.pad_wheel"], 0.5 * sc["track.link_length"])
    near = np.hypot(*(pins - centre).T) < reach + 5e-3
    # the wrap: the longest run of neighbouring pins on the idler
    start = int(np.argmin(near))  # a pin off the idler: runs do not wrap round
    best, run = (0, 0), 0
    for j in range(1, n + 1):
        b = (start + j) % n
        run = run + 1 if near[b] else 0
        if run > best[0]:
            best = (run, b)
    wrapped = np.zeros(n, bool)
    wrapped[[(best[1] - j) % n for j in range(best[0])]] = True
    pull = 0.0
    spans = 0
    for b in range(n):  # link b: pin row b (pins[b - 1]) -> pin row b + 1 (pins[b])
        wa, wz = wrapped[b - 1], wrapped[b]
        if wa != wz:
            # the next link along the free span: out of contact, its tension the span's
            k = (b + 1) % n if wa else (b - 1) % n
            a, z = pins[k - 1], pins[k]
            d = (z - a) if wa else (a - z)  # away from the idler along the span
            pull += eq.tension[k] * (d @ u) / np.hypot(*d)
            spans += 1
    assert spans == 2
    force = eq.info["idler_force"]
    assert force > 0.0
    assert abs(force + pull) < 0.02 * force


def test_rest_stays_at_rest(rest):
    """From the equilibrium, with the speed drive holding 0 m/s, nothing moves."""
    sc, eq = rest
    ds = tb.simulate(sc)
    assert ds.attrs["status"] == "completed"
    assert float(np.ptp(ds.chassis_y.values)) < 1e-9
    assert float(abs(ds.sprocket_speed).max()) < 1e-6
    assert float(abs(ds.energy_residual).max()) < 1e-6
    assert abs(float(ds.ground_force_y[-1]) - ds.attrs["weight"]) < 1e-6 * ds.attrs["weight"]
    for name in (
        "sprocket_angle",
        "sprocket_speed",
        "sprocket_torque",
        "idler_position",
        "idler_force",
        "drive_work",
        "upper_span_tension",
        "lower_span_tension",
        "peak_sprocket_torque",
        "peak_idler_force",
    ):
        assert name in ds
    assert ds.pin.size == sc["track.n_links"]


def test_moving_start_runs_round_the_loop(rest):
    """Moving: the ground run at rest, the top run at twice the speed, the sprocket turning
    to match."""
    sc0, _ = rest
    sc = sc0.with_overrides({"speed": 10.0})
    eq = S.equilibrium(sc)
    y0 = S.initial_state(sc, eq)
    nq = eq.q.size
    nw, n = sc["vehicle.n_wheels"], sc["track.n_links"]
    off = L.pin_offset(nw)
    pins = eq.q[off : off + 2 * n].reshape(n, 2)
    vel = y0[nq + off : nq + off + 2 * n].reshape(n, 2)
    wheels_x = eq.info["wheel_centres"][:, 0]
    low = (pins[:, 1] < pins[:, 1].min() + 2e-3) & (pins[:, 0] < wheels_x[1]) & (pins[:, 0] > wheels_x[3])
    high = (pins[:, 1] > pins[:, 1].max() - 0.05) & (pins[:, 0] < wheels_x[0]) & (pins[:, 0] > wheels_x[-1])
    assert low.sum() >= 5 and high.sum() >= 10
    assert np.abs(vel[low]).max() < 0.05  # the ground run's links are nearly straight
    assert np.allclose(vel[high, 0], 20.0, rtol=1e-3)
    rp = sc["sprocket.pitch_radius"]
    assert y0[nq + L.q_sprocket(nw, n)] == pytest.approx(-10.0 / rp)


def test_derived_values_written_into_the_scenario():
    sc = tb.Scenario.from_dict(FLAT)
    assert sc["track.n_links"] > 30  # the loop, not the paper's 30
    assert sc["sprocket.pitch_radius"] == pytest.approx((0.19 + 80e3 / 8e6) / (2 * math.sin(math.pi / 10)))
    assert sc["idler.preload"] > 80e3
    given = tb.Scenario.from_dict({**FLAT, "idler.preload": 150e3})
    assert given["idler.preload"] == 150e3


@pytest.mark.parametrize(
    "over, words",
    [
        ({"sprocket.teeth": 8, "sprocket.pitch_radius": 0.3236}, "sprocket.teeth = 8"),
        ({"track.n_links": 55}, "idler would leave its guide"),
        ({"solver": "lee"}, "solver = 'lee'"),
        ({"contact.damping": "hunt_crossley", "contact.restitution": 0.5}, "sprocket teeth"),
        ({"drive.kind": "torque"}, "drive.torque"),
        ({"sprocket.pin_radius": 0.04}, "sprocket.pin_radius"),
        ({"rollers.positions": [[0.0, 2.0]]}, "rollers.positions[0]"),
        ({"drive.curve": [[1.0, 2.0], [0.5, 3.0]]}, "drive.curve"),
    ],
)
def test_bad_closed_input(over, words):
    with pytest.raises(ScenarioError) as e:
        tb.Scenario.from_dict({**FLAT, **over})
    assert words in str(e.value)
    assert "\n" not in str(e.value)


def test_closed_parameters_need_the_closed_layout():
    with pytest.raises(ScenarioError, match="closed track only"):
        tb.Scenario.from_dict({"drive.kind": "speed"})


def test_speed_drive_pi_and_anti_windup():
    lp = np.zeros(L.N_LOOP)
    lp[L.LP_DRIVE_KIND] = 2
    lp[L.LP_TARGET] = 10.0
    lp[L.LP_GAIN_P] = 100.0
    lp[L.LP_GAIN_I] = 10.0
    lp[L.LP_TORQUE_LIMIT] = 500.0
    assert drive_torque(lp, 9.0, 0.0, 2.0) == pytest.approx((120.0, 1.0))
    # clipped: the integral stops growing in the clipped direction, may shrink
    assert drive_torque(lp, 0.0, 0.0, 100.0) == pytest.approx((500.0, 0.0))
    assert drive_torque(lp, 11.0, 0.0, 100.0) == pytest.approx((500.0, -1.0))
    lp[L.LP_DRIVE_KIND] = 1
    lp[L.LP_CURVE] = 2
    lp[L.LP_CURVE + 1 : L.LP_CURVE + 5] = [0.0, 1000.0, 10.0, 0.0]
    assert drive_torque(lp, 0.0, 5.0, 0.0)[0] == pytest.approx(500.0)
    assert drive_torque(lp, 0.0, 20.0, 0.0)[0] == pytest.approx(0.0)


RT = 0.3236 + 0.027


def _closed_vector(teeth=10, rp=0.3236, rg=0.03, rt=RT, rpin=0.027):
    lp = np.zeros(L.N_LOOP)
    lp[[L.LP_TEETH, L.LP_PITCH_RADIUS, L.LP_SEAT_RADIUS, L.LP_TIP_RADIUS, L.LP_PIN_RADIUS]] = (
        teeth,
        rp,
        rg,
        rt,
        rpin,
    )
    lp[L.LP_FLANK_ANGLE] = math.radians(15.0)
    return lp


def test_tooth_profile_distance_matches_the_drawn_profile():
    """The pin's penetration is r_pin minus its distance to the profile: checked against a
    finely drawn profile at random points outside the teeth."""
    lp = _closed_vector()
    poly = profile(10, 0.3236, 0.03, RT, 0.027, angle=0.3, per_arc=600)
    rng = np.random.default_rng(1)
    checked = 0
    for _ in range(400):
        r = rng.uniform(0.29, 0.39)
        a = rng.uniform(0.0, 2 * math.pi)
        p = np.array([r * math.cos(a), r * math.sin(a)])
        pen, nx, ny, inside = pin_on_sprocket(p[0], p[1], 0.3, lp)
        if inside or pen < -0.027 + 1e-9:
            continue
        seg_a, seg_b = poly[:-1], poly[1:]
        d = seg_b - seg_a
        t = np.clip(((p - seg_a) * d).sum(1) / (d * d).sum(1), 0.0, 1.0)
        dist = np.hypot(*(seg_a + t[:, None] * d - p).T).min()
        assert 0.027 - pen == pytest.approx(dist, abs=2e-5)
        checked += 1
    assert checked > 100


def test_seated_pin_on_the_pitch_circle_just_touches():
    lp = _closed_vector()
    pen, nx, ny, inside = pin_on_sprocket(0.3236 * math.cos(0.3), 0.3236 * math.sin(0.3), 0.3, lp)
    assert not inside
    assert pen == pytest.approx(0.0, abs=1e-12)
    assert (nx, ny) == pytest.approx((math.cos(0.3), math.sin(0.3)))


def test_closed_run_attributes_describe_the_layout(rest):
    sc, _ = rest
    ds = tb.simulate(sc.with_overrides({"duration": 2e-3}))
    cl = json.loads(ds.attrs["closed_layout"])
    assert ds.attrs["track_layout"] == "closed"
    assert cl["teeth"] == 10 and len(cl["sprocket"]) == 2


DRIVEN = {"track.layout": "closed", "preset": "damped", "contact.friction": 0.6}


@pytest.mark.parametrize("law", ["regularised", "bristle"])
def test_traction_limit(law):
    """A drive torque above what mu x weight carries: the track slips, and the ground's
    tractive force stays at or below mu x its normal force, with either friction law."""
    sc = tb.Scenario.from_dict(
        {
            **DRIVEN,
            "terrain": {"kind": "flat"},
            "speed": 0.0,
            "drive.kind": "torque",
            "drive.torque": 60e3,
            "duration": 0.3,
            "output_interval": 1e-3,
            "contact.friction_law": law,
        }
    )
    assert 60e3 / sc["sprocket.pitch_radius"] > 0.6 * 230e3
    ds = tb.simulate(sc)
    assert ds.attrs["status"] == "completed"
    fx, fy = ds.ground_force_x.values, ds.ground_force_y.values
    assert np.all(fx <= 0.6 * fy * (1 + 1e-9) + 1e-6)
    late = ds.time.values > 0.15
    assert fx[late].mean() > 0.9 * 0.6 * fy[late].mean()  # saturated
    slip = float(ds.sprocket_speed[-1]) * sc["sprocket.pitch_radius"] - float(ds.chassis_vx[-1])
    assert slip > 1.0
    assert float(abs(ds.energy_residual).max()) < 1e-6


def test_drive_torque_peak_stays_at_its_limit():
    """The PI drive's integral ramps the torque into drive.torque_limit: the summary's peak is
    the limit, not a parabola's vertex above the corner (it read 20.000128 kN m here, and up to
    103 kN m against a 100 kN m limit in the drawbar study)."""
    from trackbench.outputs.dataset import summary_numbers

    sc = tb.Scenario.from_dict(
        {
            **DRIVEN,
            "terrain": {"kind": "flat"},
            "speed": 5.0,
            "drive.kind": "speed",
            "drive.target": 5.5,
            "drive.gain_p": 1e3,
            "drive.gain_i": 1e6,
            "drive.torque_limit": 2e4,
            "duration": 0.1,
            "output_interval": 1e-3,
        }
    )
    ds = tb.simulate(sc)
    torque = ds.sprocket_torque.values
    assert torque[0] < 0.2 * 2e4 and np.mean(torque == 2e4) > 0.3  # ramps up, then held
    assert summary_numbers(ds)["peak_sprocket_torque_kN m"] == 20.0


def _parked(law):
    """The closed track held at 0 m/s by the speed drive against a rearward drawbar load of
    30 kN (about 0.22 mu W), 2 s. Returns (the ground run's pins' x drift over the last
    second (m), the creep speed the regularised law predicts (m/s), the run)."""
    sc = tb.Scenario.from_dict(
        {
            **FLAT,
            "speed": 0.0,
            "duration": 2.0,
            "output_interval": 0.01,
            "contact.friction": 0.6,
            "contact.friction_law": law,
            "drive.kind": "speed",
            "drive.target": 0.0,
            "drawbar.load": 30e3,
        }
    )
    ds = tb.simulate(sc)
    t, px, py = ds.time.values, ds.pin_x.values, ds.pin_y.values
    half = t >= 1.0
    ground_run = (py[half] < py[0].min() + 0.02).all(axis=0)  # on the ground all the last second
    drift = px[-1, ground_run] - px[half][0, ground_run]
    r = 30e3 / (0.6 * S.equilibrium(sc).weight)
    return drift, sc["contact.friction_velocity"] * r / math.sqrt(1.0 - r * r), ds


def test_parked_load_below_mu_w_sticks_with_bristles_and_creeps_with_the_regularised_law():
    """Below mu p the regularised law still slides, at the speed where v / sqrt(v^2 + v_eps^2)
    = F / (mu W) (docs/model.md, "Beyond the paper: ground friction"); the bristle law sticks:
    a pin moves only by its bristle's stretch (below 2 mu p / k_t, ~0.75 mm here)."""
    creep, predicted, ds = _parked("regularised")
    stick, _, db = _parked("bristle")
    for run in (ds, db):
        assert run.attrs["status"] == "completed"
        assert float(abs(run.energy_residual).max()) < 1e-6
        # the paper's balance with the tensioner's spring, the dissipated energy (the drawbar's
        # work in it) and the drive's work counted: only the integration is left
        assert np.abs(accounted_balance(run)[0]).max() < 1e-6
    assert len(creep) >= 10 and len(stick) >= 10
    assert np.all(creep < 0.0)  # rearward, every pin
    assert -np.median(creep) == pytest.approx(predicted * 1.0, rel=0.15)  # over 1 s
    assert np.median(np.abs(stick)) < 0.1 * predicted * 1.0
    assert np.abs(stick).max() < 1e-3


def test_paper_step_with_the_closed_track():
    """The paper's step at 10 m/s with the closed layout and the speed drive: completes,
    sprocket torque and tensioner force peaks in the summary."""
    from trackbench.outputs.dataset import summary_numbers

    ds = tb.simulate(tb.Scenario.from_dict({**DRIVEN, "drive.kind": "speed"}))
    assert ds.attrs["status"] == "completed"
    s = summary_numbers(ds)
    assert s["peak_sprocket_torque_kN m"] > 0.0 and s["peak_idler_force_kN"] > 100.0
    assert float(ds.first_contact_time) == pytest.approx(0.0568, abs=3e-3)
    assert float(abs(ds.energy_residual).max()) < 1e-6
    from trackbench.cli.single_run import format_summary  # the drive's work is not a balance error

    line = next(x for x in format_summary(ds).splitlines() if "balance" in x)
    assert "- drive work" in line and float(line.split("work")[1].split("%")[0]) < 1.0


@pytest.fixture(scope="module")
def drive_from_rest():
    """benchmarks/bench_closed.py's drive: from rest to 10 m/s on flat ground, mu = 0.6,
    the speed drive, 6 s (the speed reaches 99 % at ~3.4 s)."""
    sc = tb.Scenario.from_dict(
        {
            **DRIVEN,
            "terrain": {"kind": "flat"},
            "speed": 0.0,
            "drive.kind": "speed",
            "drive.target": 10.0,
            "duration": 6.0,
            "output_interval": 1e-3,
        }
    )
    return sc, tb.simulate(sc)


def test_speed_drive_from_rest_holds_the_target(drive_from_rest):
    """Speed held within 1 % over the last 2 s, reached before 4.5 s; no pin jumps a tooth
    (a pin on a tooth's top or inside the profile stops the run: it completes); the energy
    residual with drive work and friction's and the dampers' dissipation below 1e-6 of E0."""
    sc, ds = drive_from_rest
    assert ds.attrs["status"] == "completed"
    t, vx = ds.time.values, ds.chassis_vx.values
    assert t[np.argmax(vx >= 9.9)] < 4.5
    assert np.abs(vx[t >= 4.0] / 10.0 - 1.0).max() < 0.01
    assert float(abs(ds.energy_residual).max()) < 1e-6


@pytest.mark.xfail(
    strict=True,
    reason=(
        "the mean drive torque is 17.5 % above (lower - upper span tension) x r_p: each pin of the lower "
        "span strikes its seat as it engages (chordal action) and rattles in it, and the pin-tooth dampers "
        "of the damped preset take 22 % of the drive power, the wrapped links' dashpots 5 %; the spans' "
        "pulls each along its own line balance the torque to 0.1 %. No realistic tooth profile reaches 2 % "
        "(30-35 deg flanks: -6 to -9 %, but with 30 deg the 1 % speed hold fails on one run in four; ISO "
        "606's seat: -9 %, taller teeth worse; docs/validation.md, 'The tooth profile')"
    ),
)
def test_drive_torque_is_the_span_tensions_times_the_pitch_radius(drive_from_rest):
    sc, ds = drive_from_rest
    late = ds.time.values >= 4.0
    torque = ds.sprocket_torque.values[late].mean()
    spans = np.nanmean(ds.lower_span_tension.values[late] - ds.upper_span_tension.values[late])
    assert spans * sc["sprocket.pitch_radius"] == pytest.approx(torque, rel=0.02)
