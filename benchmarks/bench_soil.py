"""Soft soil: cost of paper_step on LETE sand against the rigid ground (side by side, best of
REPEATS), the closed, speed-driven track on each soil, and the drawbar test on LETE sand:
thrust against slip beside Wong's closed form, with the paper's links and with stiff ones.
Also the work against precision of the closed step on LETE sand (benchmarks/work_precision.py).
Prints figures; asserts nothing.

    python benchmarks/bench_soil.py           # everything
    python benchmarks/bench_soil.py soils     # one part: cost, ratios, soils, slips, stiff_slips, precision,
                                              # spread, criterion
    python benchmarks/bench_soil.py precision --methods dopri5,dop853 --tolerances 1e-7,1e-8,1e-9
"""

import sys

import work_precision
from bench_closed import ROSENBROCK, STEP
from side_by_side import against_the_paper, best_walls

import trackbench as tb
from trackbench.outputs.metrics.traction import pressure_effect, run_soil, steady, wong

REPEATS = 3
# bench_closed.py's step() run (the paper's step, 10 m/s, speed drive) on LETE sand
MODELS = {"closed, LETE sand": {**STEP, "terrain.soil": "lete_sand"}}


def cost():
    variants = {"rigid": tb.Scenario.paper(), "lete_sand": tb.Scenario.paper(**{"terrain.soil": "lete_sand"})}
    best = best_walls(variants, REPEATS)
    print(
        f"cost: paper_step on LETE sand / rigid ground wall time {best['lete_sand'] / best['rigid']:.2f} "
        f"(best of {REPEATS}; target: at most 2)"
    )


def ratios():
    """Wall / simulated time of the closed, driven step run on LETE sand at the defaults and with
    the Rosenbrock-W method, beside the paper's model in this process."""
    (name, model), = MODELS.items()
    against_the_paper({f"{name}, defaults": tb.Scenario.from_dict(model),
                       f"{name}, ros34pw2 at 1e-6": tb.Scenario.from_dict({**model, **ROSENBROCK})}, REPEATS)


def soils(speed=5.0, duration=1.0):
    for soil in ("dry_sand", "lete_sand", "clayey_soil", "sandy_loam"):
        sc = tb.Scenario.from_dict(
            {
                "terrain": {"kind": "flat", "soil": soil},
                "track.layout": "closed",
                "preset": "damped",
                "drive.kind": "speed",
                "speed": speed,
                "duration": duration,
                "output_interval": 1e-3,
            }
        )
        ds = tb.simulate(sc)
        late = ds.time.values > 0.5 * duration
        print(
            f"{soil}: {ds.attrs['status']}, solve {ds.attrs['solve_time']:.1f} s; second half: speed "
            f"{ds.chassis_vx.values[late].mean():.3f} m/s, drawbar pull "
            f"{ds.drawbar_pull.values[late].mean() / 1e3:.1f} kN, slip {float(ds.mean_slip):.3f}, sinkage "
            f"max {float(ds.sinkage.max()) * 100:.1f} cm, deepest rut {float(ds.rut_depth.max()) * 100:.1f} "
            f"cm; energy residual {float(abs(ds.energy_residual).max()):.1e}"
        )


def drawbar_test(slip, soil="lete_sand", speed=4.0, duration=2.0, link_stiffness=None):
    """The closed, damped, speed-driven vehicle on flat soil held at `slip` by the towing rig
    (docs/usage.md, "Drawbar test"); the PI gains and torque limit raised from the drive's
    defaults so that the sprocket reaches the rig's speed within ~0.2 s and the thrust at 50 %
    slip (~0.6 W r_p = 44 kN m) stays below the limit. link_stiffness (N/m): None keeps the
    paper's 8e6."""
    over = {} if link_stiffness is None else {"track.link_stiffness": link_stiffness}
    return tb.Scenario.from_dict(
        {
            "terrain": {"kind": "flat", "soil": soil},
            "track.layout": "closed",
            "preset": "damped",
            "drive.kind": "speed",
            "speed": speed,
            "drive.gain_p": 2e5,
            "drive.gain_i": 2e6,
            "drive.torque_limit": 1e5,
            "drawbar.slip": slip,
            "duration": duration,
            "output_interval": 2e-3,
            **over,
        }
    )


# s: the rig's slip is reached in ~0.2 s; at 5 % slip the thrust settles after ~2 s with stiff
# links (8e7 N/m), ~4.5 s with the paper's (its rise stretches the links, which raises the slip
# at the rear of the contact, which raises the thrust); from 20 % up after ~0.6 s
DURATION, SETTLE = 6.0, 4.0


def slip_curve(slips=(0.05, 0.1, 0.2, 0.3, 0.4, 0.5), link_stiffness=None, duration=DURATION, settle=SETTLE):
    links = "the paper's links (8e6 N/m)" if link_stiffness is None else f"links of {link_stiffness:.3g} N/m"
    print(
        f"drawbar test, flat LETE sand, 4 m/s, {links}, means over t >= {settle:g} s of {duration:g} s; "
        "slip = the sprocket's (the rig's), track slip = the soil's (traction.track_slip); thrust = sum of "
        "the soil shear forces' x (= drawbar_pull on flat soil), DP = drawbar load at the hitch, "
        "R = thrust - DP;\n"
        "Wong: uniform pressure, same contact length, area and weight, at the track slip; R_c his compaction "
        "resistance; non-unif.: Wong's integral over the pins with their own load shares / with equal shares"
    )
    print(
        f"{'slip set':>8} {'slip':>6} {'trk slip':>8} {'thrust kN':>9} {'DP kN':>7} {'R kN':>6} "
        f"{'spr.pull kN':>11} {'W kN':>6} {'l m':>5} {'Wong kN':>8} {'diff %':>7} {'R_c kN':>6} "
        f"{'Wong DP':>7} {'non-unif. %':>11} {'solve s':>7}"
    )
    for slip in slips:
        ds = tb.simulate(drawbar_test(slip, duration=duration, link_stiffness=link_stiffness))
        soil = run_soil(ds)
        fig = steady(ds, settle)
        f_wong, r_c = wong(fig, soil)
        nonuniform, uniform = pressure_effect(ds, settle, fig["track_slip"], soil)
        print(
            f"{slip:8.2f} {fig['slip']:6.3f} {fig['track_slip']:8.3f} {fig['thrust'] / 1e3:9.1f} "
            f"{fig['drawbar_load'] / 1e3:7.1f} "
            f"{(fig['thrust'] - fig['drawbar_load']) / 1e3:6.2f} {fig['sprocket_pull'] / 1e3:11.1f} "
            f"{fig['weight'] / 1e3:6.1f} {fig['length']:5.2f} {f_wong / 1e3:8.1f} "
            f"{100 * (fig['thrust'] / f_wong - 1):+7.2f} {r_c / 1e3:6.2f} {(f_wong - r_c) / 1e3:7.1f} "
            f"{100 * (nonuniform / uniform - 1):+11.2f} {ds.attrs['solve_time']:7.1f}   "
            f"({ds.attrs['status']}, energy residual {float(abs(ds.energy_residual).max()):.1e})"
        )


PARTS = {
    "cost": cost,
    "ratios": ratios,
    "soils": soils,
    "slips": slip_curve,
    "stiff_slips": lambda: slip_curve(link_stiffness=8e7),  # Wong's track is inextensible: test_drawbar's
}

if __name__ == "__main__":
    work_precision.main(sys.argv[1:], PARTS, MODELS)
