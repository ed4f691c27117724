"""Soft soil: cost of paper_step on LETE sand against the rigid ground (side by side, best of
REPEATS), and the closed, speed-driven track on each soil. Prints figures; asserts nothing.

    python benchmarks/bench_soil.py
"""


import numpy as np

import trackbench as tb
from side_by_side import best_walls

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


if __name__ == "__main__":
    cost()
    soils()
