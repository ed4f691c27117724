"""Soft soil: cost of paper_step on LETE sand against the rigid ground (side by side, best of
REPEATS), the closed, speed-driven track on each soil, and the drawbar test on LETE sand:
thrust against slip beside Wong's closed form. Prints figures; asserts nothing.

    python benchmarks/bench_soil.py
"""


import numpy as np

import trackbench as tb
from side_by_side import best_walls
from trackbench.traction import pressure_effect, run_soil, steady, wong

REPEATS = 3


def cost():
    variants = {"rigid": tb.Scenario.paper(), "lete_sand": tb.Scenario.paper(**{"terrain.soil": "lete_sand"})}
    best = best_walls(variants, REPEATS)
    print(f"cost: paper_step on LETE sand / rigid ground wall time {best['lete_sand'] / best['rigid']:.2f} "
          f"(best of {REPEATS}; target: at most 2)")


def soils(speed=5.0, duration=1.0):
    for soil in ("dry_sand", "lete_sand", "clayey_soil", "sandy_loam"):
        sc = tb.Scenario.from_dict({"terrain": {"kind": "flat", "soil": soil}, "track.layout": "closed",
                                    "preset": "damped", "drive.kind": "speed", "speed": speed,
                                    "duration": duration, "output_interval": 1e-3})
        ds = tb.simulate(sc)
        late = ds.time.values > 0.5 * duration
        print(f"{soil}: {ds.attrs['status']}, solve {ds.attrs['solve_time']:.1f} s; second half: speed "
              f"{ds.chassis_vx.values[late].mean():.3f} m/s, drawbar pull {ds.drawbar_pull.values[late].mean() / 1e3:.1f} "
              f"kN, slip {np.nanmean(ds.slip.values[late]):.3f}, sinkage max {float(ds.sinkage.max()) * 100:.1f} cm, "
              f"deepest rut {float(ds.rut_depth.max()) * 100:.1f} cm; energy residual "
              f"{float(abs(ds.energy_residual).max()):.1e}")


def drawbar_test(slip, soil="lete_sand", speed=4.0, duration=2.0):
    """The closed, damped, speed-driven vehicle on flat soil held at `slip` by the towing rig
    (docs/usage.md, "Drawbar test"); the PI gains and torque limit raised from the drive's
    defaults so that the sprocket reaches the rig's speed within ~0.2 s and the thrust at 50 %
    slip (~0.6 W r_p = 44 kN m) stays below the limit."""
    return tb.Scenario.from_dict({
        "terrain": {"kind": "flat", "soil": soil}, "track.layout": "closed", "preset": "damped",
        "drive.kind": "speed", "speed": speed, "drive.gain_p": 2e5, "drive.gain_i": 2e6,
        "drive.torque_limit": 1e5, "drawbar.slip": slip, "duration": duration, "output_interval": 2e-3})


SETTLE = 0.6   # s: the rig's slip is reached in ~0.2 s, the thrust after the track ran one contact length


def slip_curve(slips=(0.05, 0.1, 0.2, 0.3, 0.4, 0.5)):
    print("drawbar test, flat LETE sand, 4 m/s, means over t >= 0.6 s of 2 s; thrust = sum of the soil shear "
          "forces' x (= drawbar_pull on flat soil), DP = drawbar load at the hitch, R = thrust - DP;\n"
          "Wong: uniform pressure, same contact length, area and weight; R_c his compaction resistance; "
          "non-unif.: Wong's integral over the pins with their own load shares / with equal shares")
    print(f"{'slip set':>8} {'slip':>6} {'thrust kN':>9} {'DP kN':>7} {'R kN':>6} {'spr.pull kN':>11} "
          f"{'W kN':>6} {'l m':>5} {'Wong kN':>8} {'diff %':>7} {'R_c kN':>6} {'Wong DP':>7} {'non-unif. %':>11} "
          f"{'solve s':>7}")
    for slip in slips:
        ds = tb.simulate(drawbar_test(slip))
        soil = run_soil(ds)
        fig = steady(ds, SETTLE)
        f_wong, r_c = wong(fig, soil)
        nonuniform, uniform = pressure_effect(ds, SETTLE, fig["slip"], soil)
        print(f"{slip:8.2f} {fig['slip']:6.3f} {fig['thrust'] / 1e3:9.1f} {fig['drawbar_load'] / 1e3:7.1f} "
              f"{(fig['thrust'] - fig['drawbar_load']) / 1e3:6.2f} {fig['sprocket_pull'] / 1e3:11.1f} "
              f"{fig['weight'] / 1e3:6.1f} {fig['length']:5.2f} {f_wong / 1e3:8.1f} "
              f"{100 * (fig['thrust'] / f_wong - 1):+7.2f} {r_c / 1e3:6.2f} {(f_wong - r_c) / 1e3:7.1f} "
              f"{100 * (nonuniform / uniform - 1):+11.2f} {ds.attrs['solve_time']:7.1f}   ({ds.attrs['status']}, "
              f"energy residual {float(abs(ds.energy_residual).max()):.1e})")


if __name__ == "__main__":
    cost()
    soils()
    slip_curve()
