"""The M113 at rest: `trackbench vehicle show m113`'s side view (what it draws is where the
statics put it, and it can be seen in the PNG: each part's fill colour inside it, not hidden by
another part), and the rear idler's clearance that sets its obstacle-limited speed's cliff
between half-rounds of 6 and 8 in (docs/validation.md, "The M113")."""

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def m113():
    from trackbench.run.vehicle_report import statics, vehicle_scenario

    return statics(vehicle_scenario("m113"))


@pytest.fixture(scope="module")
def drawn(m113, tmp_path_factory):
    from trackbench.figures.plot_common import _plt
    from trackbench.figures.vehicle_figure import draw_vehicle

    plt = _plt()
    fig, ax = plt.subplots(figsize=(10, 4.2))
    draw_vehicle(ax, m113)
    fig.canvas.draw()
    image = np.asarray(fig.canvas.buffer_rgba())[..., :3]
    yield ax, image
    plt.close(fig)


def _circles(ax):
    from matplotlib.patches import Circle

    return [p for p in ax.patches if isinstance(p, Circle)]


def _labels(ax):
    return {t.get_text(): t.get_position() for t in ax.texts} | {t.get_text(): t.xy for t in ax.texts
                                                                 if hasattr(t, "xy")}


def test_every_part_is_named(drawn):
    ax, _ = drawn
    names = set(_labels(ax))
    wanted = {f"road\nwheel {k}" for k in range(1, 6)} | {"sprocket", "idler", "track", "hull (chassis)",
                                                          "mass centre", "seat", "level ground"}
    assert wanted <= names, wanted - names


def test_wheels_stand_on_the_track_on_the_ground(m113, drawn):
    ax, _ = drawn
    sc = m113.scenario
    wheels = sorted((c for c in _circles(ax) if c.get_radius() == pytest.approx(0.305)),
                    key=lambda c: -c.center[0])
    assert len(wheels) == 5
    centres = np.array([c.center for c in wheels])
    assert np.allclose(centres, m113.wheels, atol=1e-12)
    # each wheel's bottom on the track's pads, the track's pads on the ground: within the
    # contacts' squeeze under about 9 kN a wheel at 1e8 N/m (a fraction of a millimetre)
    stand = 0.305 + sc["track.pad_wheel"] + sc["track.pad_ground"]
    assert np.all(np.abs(centres[:, 1] - stand) < 1e-3), centres[:, 1] - stand
    # road wheel 1 at the front (+x), the sprocket ahead of it, the idler behind wheel 5
    circles = {round(c.get_radius(), 6): c.center for c in _circles(ax)}
    sprocket, idler = circles[round(sc["sprocket.pitch_radius"], 6)], circles[round(sc["idler.radius"], 6)]
    assert sprocket[0] > centres[0, 0] + 0.305 and idler[0] < centres[-1, 0] - 0.305


def test_the_track_is_drawn_closed_through_every_pin(m113, drawn):
    ax, _ = drawn
    loops = [ln for ln in ax.lines if len(ln.get_xdata()) == m113.scenario["track.n_links"] + 1]
    assert len(loops) == 1
    xy = np.column_stack([loops[0].get_xdata(), loops[0].get_ydata()])
    assert np.array_equal(xy[0], xy[-1]) and np.allclose(xy[:-1], m113.pins)
    # each link its pitch long, stretched by no more than the largest tension allows
    sc = m113.scenario
    stretch = np.hypot(*np.diff(xy, axis=0).T) - sc["track.link_length"]
    most = 1.1 * m113.eq.tension.max() / sc["track.link_stiffness"]
    assert np.all(stretch > 0.0) and np.all(stretch < most)


def _pixel(ax, image, xy):
    x, y = ax.transData.transform(xy)
    return image[image.shape[0] - 1 - int(round(y)), int(round(x))]


def test_each_part_can_be_seen(m113, drawn):
    """A point inside each wheel, the sprocket and the idler (a third of a radius off the centre,
    away from its label) has that part's fill colour: nothing is drawn over them; the ground and
    the hull show their own."""
    ax, image = drawn
    wheel, closed_part = (244, 244, 244), (230, 238, 246)
    for c in _circles(ax):
        colour = closed_part if c.get_facecolor()[:3] == pytest.approx((230 / 255, 238 / 255, 246 / 255)) \
            else wheel
        x, y = c.center
        assert tuple(_pixel(ax, image, (x, y - 0.6 * c.get_radius()))) == colour, c
    assert tuple(_pixel(ax, image, (0.0, -0.05))) != (255, 255, 255)     # the ground's fill
    hull_x = 0.5 * (m113.wheels[0, 0] + m113.wheels[1, 0])
    assert tuple(_pixel(ax, image, (hull_x, 1.6))) == (233, 237, 242)     # the hull's fill


def test_the_track_under_the_idler_clears_6_in_and_not_8_in(m113):
    """The track's underside below the idler's centre at rest: above a 6 in half-round's top,
    below an 8 in one's, so the larger half-rounds strike the idler (which has no suspension)."""
    from trackbench.run.vehicle_report import closed_drawing

    sc = m113.scenario
    x, y, r = closed_drawing(m113)["idler"]
    near = m113.pins[np.abs(m113.pins[:, 0] - x) < sc["track.link_length"]]
    underside = near[:, 1].min() - sc["track.pad_ground"]
    assert y - r - sc["track.pad_wheel"] > underside > 0.0     # the track below the idler
    assert 6 * 0.0254 < underside < 8 * 0.0254, underside
