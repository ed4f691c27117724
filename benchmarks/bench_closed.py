"""The closed, driven track: the figures docs/validation.md and docs/benchmarks.md quote.
Prints figures; asserts nothing. Takes several minutes.

    python benchmarks/bench_closed.py            # everything
    python benchmarks/bench_closed.py drive      # one part: rest, drive, profiles, traction, step, cost,
                                                 # ratios, long, precision, spread, criterion, energy
    python benchmarks/bench_closed.py precision --methods dopri5,dop853 --tolerances 1e-7,1e-8,1e-9
    python benchmarks/bench_closed.py energy --methods ros34pw2,dopri5 --tolerances 1e-5,1e-6,1e-7 \
        --pin-ratios 1,10
"""

import sys
import time

import numpy as np
import work_precision
from side_by_side import against_the_paper, best_walls

import trackbench as tb

CLOSED = {"track.layout": "closed", "preset": "damped", "contact.friction": 0.6}
REPEATS = 3
# step()'s run (the paper's step, 10 m/s, speed drive) with each friction law: the precision models
STEP = {**CLOSED, "drive.kind": "speed", "drive.target": 10.0}
MODELS = {
    "closed, regularised friction": STEP,
    "closed, bristle friction": {**STEP, "contact.friction_law": "bristle"},
}


def rest():
    """At rest on flat ground: weight against ground force, tensioner against the spans."""
    import importlib

    S = importlib.import_module("trackbench.run.simulate")
    sc = tb.Scenario.from_dict({**CLOSED, "terrain": {"kind": "flat"}})
    t = time.perf_counter()
    eq = S.equilibrium(sc)
    print(
        f"rest: equilibrium {time.perf_counter() - t:.2f} s, {eq.iterations} iterations, residual "
        f"{eq.residual / eq.weight:.1e} of the weight, ground force - weight "
        f"{abs(eq.ground_force - eq.weight) / eq.weight:.1e} of it; tensioner "
        f"{eq.info['idler_force'] / 1e3:.1f} kN at slide {eq.info['idler_slide'] * 1e3:.1f} mm, holding "
        f"torque {eq.info['holding_torque'] / 1e3:.2f} kN m, links "
        f"{eq.tension.min() / 1e3:.1f}-{eq.tension.max() / 1e3:.1f} kN"
    )


def drive(target=10.0, duration=6.0):
    """Speed drive from rest to `target` on flat ground, mu = 0.6: speed hold, torque against
    (lower - upper span tension) x r_p, pins seated, energy residual."""
    sc = tb.Scenario.from_dict(
        {
            **CLOSED,
            "terrain": {"kind": "flat"},
            "speed": 0.0,
            "drive.kind": "speed",
            "drive.target": target,
            "duration": duration,
            "output_interval": 1e-3,
        }
    )
    ds = tb.simulate(sc)
    a = ds.attrs
    print(f"drive: {a['status']} ({a['status_message']}), solve {a['solve_time']:.1f} s, steps {a['steps']}")
    t = ds.time.values
    vx = ds.chassis_vx.values
    reach = t[np.argmax(vx >= 0.99 * target)] if (vx >= 0.99 * target).any() else np.nan
    print(f"  speed reaches 99 % of {target} m/s at {reach:.2f} s")
    late = t >= duration - 2.0
    if np.isfinite(reach) and reach < duration - 2.0:
        v = vx[late]
        torque = ds.sprocket_torque.values[late]
        rp = sc["sprocket.pitch_radius"]
        from_spans = np.nanmean(ds.lower_span_tension.values[late] - ds.upper_span_tension.values[late]) * rp
        arms = _span_moment(ds, sc, late)
        print(f"  mean teeth torque {ds.teeth_torque.values[late].mean() / 1e3:.3f} kN m")
        print(
            f"  last 2 s: speed {v.min():.3f}-{v.max():.3f} m/s (worst "
            f"{100 * np.abs(v / target - 1).max():.2f} %), mean {v.mean():.3f}; mean torque "
            f"{torque.mean() / 1e3:.3f} kN m, (lower - upper span) x r_p {from_spans / 1e3:.3f} kN m "
            f"({100 * (from_spans / torque.mean() - 1):+.1f} %); the two spans' pulls, each with its own "
            f"lever arm about the axis, hold back {arms / 1e3:.3f} kN m "
            f"({100 * (arms / torque.mean() - 1):+.1f} %)"
        )
    print(
        f"  energy residual max {float(abs(ds.energy_residual).max()):.1e} of E0; drive work "
        f"{float(ds.drive_work[-1]) / 1e3:.0f} kJ, dissipated {float(ds.energy_dissipated[-1]) / 1e3:.0f} kJ"
    )
    return ds


def _span_moment(ds, sc, rows):
    """Mean moment about the sprocket axis of the two spans' pulls where they leave the
    sprocket (output._span_links: the second link from the last pin on the teeth), each along
    its own line, forward positive: what the spans hold back against the drive."""
    import json

    from trackbench.outputs.closed import _span_links

    cl = json.loads(ds.attrs["closed_layout"])
    sx, sy = cl["sprocket"]
    th = ds.chassis_pitch.values[rows]
    ax = ds.chassis_x.values[rows] + np.cos(th) * sx - np.sin(th) * sy
    ay = ds.chassis_y.values[rows] + np.sin(th) * sx + np.cos(th) * sy
    px, py = ds.pin_x.values[rows], ds.pin_y.values[rows]
    tension = ds.link_tension.values[rows]
    on_teeth = np.hypot(px - ax[:, None], py - ay[:, None]) < cl["tip_radius"] + cl["pin_radius"]
    links = _span_links(on_teeth, 0.5 * (py + np.roll(py, 1, axis=1)))
    out = []
    for k in range(len(th)):
        if links[k, 0] < 0:
            continue
        m = 0.0
        for b in links[k]:
            a = b - 1  # link b: pins[b - 1] -> pins[b]
            toward = np.hypot(px[k, a] - ax[k], py[k, a] - ay[k]) < np.hypot(
                px[k, b] - ax[k], py[k, b] - ay[k]
            )
            near, far = (a, b) if toward else (b, a)
            dx, dy = px[k, far] - px[k, near], py[k, far] - py[k, near]
            rx, ry = px[k, near] - ax[k], py[k, near] - ay[k]
            m += (
                tension[k, b] * (rx * dy - ry * dx) / np.hypot(dx, dy)
            )  # CCW moment of the pull on the near pin
        out.append(m)  # CCW = backward
    return float(np.mean(out))


# docs/validation.md, "The tooth profile": what differs from the default profile
PROFILES = {
    "default": {},
    "flanks 30 deg": {"sprocket.flank_angle": 30.0},
    "flanks 35 deg": {"sprocket.flank_angle": 35.0},
    "seat 35 mm": {"sprocket.seat_radius": 0.035},
    "flanks 30 deg, tip r_p + 57 mm": {"sprocket.flank_angle": 30.0, "sprocket.tip_radius": 0.3806},
    "ISO seat 27.5 mm, flanks 30 deg": {"sprocket.seat_radius": 0.0275, "sprocket.flank_angle": 30.0},
}


def profiles(duration=6.0):
    """drive()'s run for each tooth profile of PROFILES: the mean torque over t >= 4 s against
    (lower - upper span tension) x r_p, as tests/test_closed.py compares them."""
    for name, over in PROFILES.items():
        sc = tb.Scenario.from_dict(
            {
                **CLOSED,
                "terrain": {"kind": "flat"},
                "speed": 0.0,
                "drive.kind": "speed",
                "drive.target": 10.0,
                "duration": duration,
                "output_interval": 1e-3,
                **over,
            }
        )
        ds = tb.simulate(sc)
        late = ds.time.values >= 4.0
        torque = ds.sprocket_torque.values[late].mean()
        spans = np.nanmean(ds.lower_span_tension.values[late] - ds.upper_span_tension.values[late])
        spans *= sc["sprocket.pitch_radius"]
        print(
            f"profile {name}: {ds.attrs['status']}, mean torque {torque / 1e3:.2f} kN m, "
            f"(lower - upper span) x r_p {spans / 1e3:.2f} kN m ({100 * (spans / torque - 1):+.1f} %), "
            f"{ds.attrs['steps']} steps"
        )


def traction(torque=60e3, duration=1.0):
    """A torque above what mu x weight carries: the track slips, the tractive force stays at
    or below mu x weight."""
    sc = tb.Scenario.from_dict(
        {
            **CLOSED,
            "terrain": {"kind": "flat"},
            "speed": 0.0,
            "drive.kind": "torque",
            "drive.torque": torque,
            "duration": duration,
            "output_interval": 1e-3,
        }
    )
    ds = tb.simulate(sc)
    rp = sc["sprocket.pitch_radius"]
    w = ds.attrs["weight"]
    fx = ds.ground_force_x.values
    fy = ds.ground_force_y.values
    late = ds.time.values > 0.5 * duration
    print(
        f"traction: {ds.attrs['status']}, torque {torque / 1e3:.0f} kN m = {torque / rp / 1e3:.0f} kN at the "
        f"pitch circle against mu W = {0.6 * w / 1e3:.0f} kN; ground force x / y at every sample at most "
        f"{np.max(fx / np.maximum(fy, 1.0)):.4f} (mu = 0.6); over the second half mean x "
        f"{fx[late].mean() / 1e3:.1f} kN, mean y {fy[late].mean() / 1e3:.1f} kN (x / y "
        f"{fx[late].mean() / fy[late].mean():.4f}); track speed at the sprocket "
        f"{float(ds.sprocket_speed[-1]) * rp:.2f} m/s against the vehicle's {float(ds.chassis_vx[-1]):.2f}"
    )


def step(speed=10.0):
    """The paper's step at 10 m/s with the closed layout and the speed drive, 0.5 s."""
    sc = tb.Scenario.from_dict({**CLOSED, "speed": speed, "drive.kind": "speed", "drive.target": speed})
    ds = tb.simulate(sc)
    print(
        f"step: {ds.attrs['status']} ({ds.attrs['status_message']}), solve {ds.attrs['solve_time']:.2f} s; "
        f"peak sprocket torque {float(ds.peak_sprocket_torque) / 1e3:.1f} kN m at "
        f"{float(ds.peak_sprocket_torque_time):.3f} s, peak idler force "
        f"{float(ds.peak_idler_force) / 1e3:.1f} kN, peak wheel forces "
        f"{np.round(ds.peak_wheel_force_y.values / 1e3)} kN, first obstacle contact "
        f"{float(ds.first_contact_time):.4f} s"
    )


def cost():
    """Wall time of paper_step with the closed layout against the paper's layout, side by
    side, best of REPEATS (both damped, so that the figure is the layout's cost)."""
    variants = {
        "paper layout": tb.Scenario.paper(preset="damped"),
        "closed layout": tb.Scenario.from_dict({**CLOSED, "drive.kind": "speed"}),
        "closed, bristle friction": tb.Scenario.from_dict(
            {**CLOSED, "drive.kind": "speed", "contact.friction_law": "bristle"}
        ),
    }
    best = best_walls(variants, REPEATS)
    for name in ("closed layout", "closed, bristle friction"):
        print(
            f"cost: {name} / paper layout wall time {best[name] / best['paper layout']:.1f} (best of "
            f"{REPEATS}; target: at most 3)"
        )


# the Rosenbrock-W method at the setting measured to pass the accuracy criterion on the step run
# with regularised friction (docs/benchmarks.md, "The driven track's integrators")
ROSENBROCK = {"method": "ros34pw2", "tolerance": 1e-6}


def ratios():
    """Wall / simulated time of the closed, driven step run (STEP) with each friction law, at
    the defaults and with the Rosenbrock-W method, beside the paper's model in this process."""
    variants = {}
    for name, model in MODELS.items():
        variants[f"{name}, defaults"] = tb.Scenario.from_dict(model)
        variants[f"{name}, ros34pw2 at 1e-6"] = tb.Scenario.from_dict({**model, **ROSENBROCK})
    against_the_paper(variants, REPEATS)


def long(duration=20.0):
    """The 20 s flat run (closed, damped, mu 0.6, speed drive 10 m/s, samples every 1 ms) at the
    defaults with each friction law, one round beside the paper's model (paper_step at its
    defaults, best of 3): wall time, its ratio per simulated second, the speed held over the
    second half and the energy residual at the end and at most."""
    paper = tb.Scenario.paper()
    best_paper = min(best_walls({"paper": paper}, 3).values()) / paper["duration"]
    print(f"\n| {duration:g} s flat run | method, tolerance | wall | x real time | / the paper model's | "
          "steps (+ rejected) | speed held | residual end / max |\n" + "| --- " * 8 + "|")
    for law in ("regularised", "bristle"):
        sc = tb.Scenario.from_dict({**STEP, "contact.friction_law": law, "terrain": {"kind": "flat"},
                                    "duration": duration, "output_interval": 1e-3})
        t = time.perf_counter()
        ds = tb.simulate(sc)
        wall = time.perf_counter() - t
        f = work_precision._figures(ds, sc, wall)
        res = ds.energy_residual.values   # relative to E0
        print(f"| {law} friction | {sc['method']}, {sc['tolerance']:g} | {wall:.1f} s | "
              f"{wall / duration:.2f} | {wall / duration / best_paper:.1f}x | "
              f"{f['steps']:,} (+{f['rejected']:,}) | "
              f"{f['speed_hold']:.2%} | {res[-1]:.1e} / {f['energy']:.1e} |")


PARTS = {
    "rest": rest,
    "drive": drive,
    "profiles": profiles,
    "traction": traction,
    "step": step,
    "cost": cost,
    "ratios": ratios,
    "long": long,
}

if __name__ == "__main__":
    work_precision.main(sys.argv[1:], PARTS, MODELS)
