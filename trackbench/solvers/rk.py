"""Python side of the reduced-coordinate solver: validate nothing (the scenario did),
allocate, call the compiled loop."""

from .base import allocate_outputs, trimmed
from .reduced import integrate
from .tableau import TABLEAUS

H0 = 1e-5        # s: first trial step; the controller grows it at once
H_MIN = 1e-13    # s: below this the run stops with STEP_SIZE_UNDERFLOW


def run(scenario, model, y0):
    A, b, c, e, e3, expo = TABLEAUS[scenario["method"]].arrays()
    out_y, out_d, peaks, stats = allocate_outputs(scenario, model, y0.size)
    tol = scenario["tolerance"]
    dt_out = scenario["output_interval"]
    integrate(y0, scenario["duration"], dt_out, A, b, c, e, e3, expo, tol, tol,
              min(H0, dt_out), dt_out, H_MIN, scenario["max_steps"],
              model.par, model.arms, model.ends, model.seg, model.corners, model.nbr, model.ref,
              model.work, out_y, out_d, peaks, stats)
    return trimmed(scenario, out_y, out_d, peaks, stats)
