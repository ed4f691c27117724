"""Python side of the Rosenbrock-W solver: allocate, call the compiled loop, hand back the
figures of its own (the Jacobians it formed, the pins' velocities' tolerance it used)."""

import numpy as np

from ...model.core import indices as L
from ...model.core.bundles import event_arrays
from ..base import CHUNK_ROWS, allocate_outputs, run_chunks, trimmed
from ..common.pin_jacobian import jacobian_work
from .ros_loop import RosControl, integrate, loop_arrays
from .ros_tableau import ROS_TABLEAUS

# tolerance_pin_velocity not set: the pins' velocities held to this multiple of the tolerance.
# They set the step (docs/benchmarks.md): on the closed, driven step run held at 1e-5, the rest
# at 1e-6 costs 4 % more steps than at 1e-5 and moves the well-conditioned peaks less.
PIN_VELOCITY_RATIO = 10.0
# accepted steps one W (the pins' blocks) serves, renewed sooner after J_REJECTIONS rejections
# in a row: measured on the closed, driven step run (1e-6, pins 1e-5), every 1 / 3 / 10 / 20
# steps 7.3x / 4.7-4.9x / 4.0x / 4.1x the paper model's wall time, the peaks alike
JACOBIAN_AGE = 10


def pin_velocities(jw):
    """(lo, hi): the pins' velocities are y[lo:hi] (the blocks' vx, vy columns, contiguous)."""
    cols = jw.blk[:, 2:4]
    lo, hi = int(cols.min()), int(cols.max()) + 1
    if hi - lo != cols.size:
        raise ValueError("the pins' velocities are not contiguous in the state")
    return lo, hi


def ros_control(controls, jw, jacobian_age=None):
    """The loop's RosControl: the pins' velocities and their tolerance, the accepted steps one
    W serves (None: JACOBIAN_AGE, as this module holds it when the run starts)."""
    lo, hi = pin_velocities(jw)
    # rounded to 12 digits: 10 x 1e-6 is 1e-5 exactly, as a scenario that sets it says
    tol_v = controls.tolerance_pin_velocity or float(f"{PIN_VELOCITY_RATIO * controls.rtol:.12g}")
    return RosControl(lo, hi, float(tol_v), int(jacobian_age or JACOBIAN_AGE))


def run(model, y0, controls, sink=None, jacobian_age=None):
    """The run of controls.method in one piece; with a sink (base.run_chunks), streamed to it
    in chunks. jacobian_age: the accepted steps one W serves (a measurement's knob)."""
    tab = ROS_TABLEAUS[controls.method].arrays()
    out = allocate_outputs(controls, model, y0.size, None if sink is None else CHUNK_ROWS)
    lw = loop_arrays(tab.m.shape[0], y0.size, L.n_diag(model.nw, model.n_links), model.n_links + 1)
    jw = jacobian_work(model, y0.size)
    rc = ros_control(controls, jw, jacobian_age)
    out.resume[L.RS_AGE] = rc.jacobian_age   # no Jacobian yet
    ev = event_arrays(model.nw, model.n_links, model.arrays.guides.shape[0] if model.closed else None)
    ctl = controls.loop_control
    run_chunks(lambda: integrate(y0, ctl, rc, tab, model.arrays, model.work, ev, lw, jw, out), out, sink)
    extra = {
        "jacobian_evaluations": ((), np.int64(lw.counts[0]), "1", "the pins' block Jacobians formed"),
        "tolerance_pin_velocity": ((), rc.tol_pin_velocity, "1",
                                   "the tolerance the error norm held the pins' velocities to"),
        "rejected_at_switch": ((), np.int64(lw.counts[1] + lw.counts[3]), "1",
                               "rejected steps retried to end just after a located contact switch"),
    }
    return trimmed(controls, out, extra)
