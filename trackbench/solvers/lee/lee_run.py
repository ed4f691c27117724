"""Python side of the "lee" solver (paper sections 3-4): absolute coordinates, Lagrange
multipliers by Lee's accelerated iteration, the Dormand-Prince RKN6(4) pair. Takes and
returns the reduced layout so every output means the same as for the reduced solver;
solver-specific figures go to RunResult.extra (results_schema.md, lee section)."""


from ...model.core import indices as L
from ...model.core.bundles import event_arrays
from ...model.dynamics.absolute import inverse_mass
from ..base import allocate_outputs, trimmed
from .lee_loop import integrate_lee
from .lee_work import (
    L_BUILDS,
    L_DIAG_UNCONVERGED,
    L_EPS1,
    L_IT_ACC,
    L_IT_DIAG,
    L_IT_OUT,
    L_IT_POS,
    L_IT_VEL,
    L_PASSES,
    L_RATIO_ACC,
    L_RATIO_POS,
    L_RATIO_VEL,
    L_REJ_CONSTRAINT,
    L_REJ_ERROR,
    X_ERR_ACC,
    X_ERR_POS,
    X_ERR_VEL,
    X_H,
    X_IT_ACC,
    X_IT_POS,
    X_IT_VEL,
    X_RATIO_ACC,
    X_RATIO_POS,
    X_RATIO_VEL,
    X_REJECTED,
    X_STEPS,
    LeeSettings,
    lee_arrays,
    lee_outputs,
)
from .rkn_tableau import RKN64

T = ("time",)
# the solver's own figures: (dims, name, column, units, long_name); along time the column of
# the per-sample table, for the whole run the slot of the run statistics
_FIGURES = [
    (T, "lee_steps", X_STEPS, "1", "accepted steps since the previous output sample"),
    (
        T,
        "lee_rejected_steps",
        X_REJECTED,
        "1",
        "rejected step attempts (error test or position iteration) since the previous output sample",
    ),
    (
        T,
        "lee_iterations_position",
        X_IT_POS,
        "1",
        "lambda iterations, position level Eq. (12), summed over "
        "the accepted steps since the previous sample",
    ),
    (
        T,
        "lee_iterations_velocity",
        X_IT_VEL,
        "1",
        "lambda iterations, velocity level Eq. (13), summed likewise",
    ),
    (
        T,
        "lee_iterations_acceleration",
        X_IT_ACC,
        "1",
        "lambda iterations, acceleration level Eq. (14), summed likewise",
    ),
    (
        T,
        "lee_error_position",
        X_ERR_POS,
        "m",
        "max final position constraint error max|Phi| over those steps",
    ),
    (T, "lee_error_velocity", X_ERR_VEL, "m s-1", "max final velocity constraint error over those steps"),
    (
        T,
        "lee_error_acceleration",
        X_ERR_ACC,
        "m s-2",
        "max final acceleration constraint error over those steps",
    ),
    (T, "lee_error_ratio_position", X_RATIO_POS, "1", "max position constraint error / its tolerance"),
    (T, "lee_error_ratio_velocity", X_RATIO_VEL, "1", "max velocity constraint error / (position_tol / h)"),
    (
        T,
        "lee_error_ratio_acceleration",
        X_RATIO_ACC,
        "1",
        "max acceleration constraint error / (position_tol / h^2)",
    ),
    (T, "lee_step_size", X_H, "s", "size of the last accepted step before the sample"),
    (
        (),
        "lee_total_iterations_position",
        L_IT_POS,
        "1",
        "lambda iterations at the position level, whole run (rejected attempts included)",
    ),
    (
        (),
        "lee_total_iterations_velocity",
        L_IT_VEL,
        "1",
        "lambda iterations at the velocity level, whole run",
    ),
    (
        (),
        "lee_total_iterations_acceleration",
        L_IT_ACC,
        "1",
        "lambda iterations at the acceleration level, whole run (output samples excluded)",
    ),
    ((), "lee_total_iterations_output", L_IT_OUT, "1", "acceleration-level iterations at the output samples"),
    (
        (),
        "lee_total_iterations_reported",
        L_IT_DIAG,
        "1",
        "further acceleration-level iterations (to 1e-10 m/s^2, "
        "on a copy) for the reported acceleration and joint forces",
    ),
    (
        (),
        "lee_reported_unconverged",
        L_DIAG_UNCONVERGED,
        "1",
        "reported states whose further iteration did not reach 1e-10 m/s^2 (their values are less accurate)",
    ),
    ((), "lee_step_passes", L_PASSES, "1", "RKN passes over a step (one per position-level iteration + 1)"),
    ((), "lee_rejected_error", L_REJ_ERROR, "1", "steps rejected by the integration error test"),
    (
        (),
        "lee_rejected_constraint",
        L_REJ_CONSTRAINT,
        "1",
        "steps rejected because the position-level iteration did not converge (step halved)",
    ),
    ((), "lee_matrix_builds", L_BUILDS, "1", "constructions of A_n and alpha (A1-A6, Eq. 16)"),
    ((), "lee_eps1", L_EPS1, "1", "eps-bar-1 of Eq. (20): estimated smallest eigenvalue of C_1"),
    (
        (),
        "lee_max_error_ratio_position",
        L_RATIO_POS,
        "1",
        "max over accepted steps of position error / tolerance",
    ),
    (
        (),
        "lee_max_error_ratio_velocity",
        L_RATIO_VEL,
        "1",
        "max over accepted steps of velocity error / tolerance",
    ),
    (
        (),
        "lee_max_error_ratio_acceleration",
        L_RATIO_ACC,
        "1",
        "max over accepted steps of acceleration error / tolerance",
    ),
]


def run(model, y0, controls):
    """The run in one piece; Lee's settings are controls.settings (the registry's "lee" table)."""
    own = controls.settings
    tab = RKN64.arrays()
    out = allocate_outputs(controls, model, y0.size)
    lout = lee_outputs(out.y.shape[0], model.nw)
    ls = LeeSettings(int(own["accel_order"]), int(own["eps_iterations"]), float(own["position_tol"]),
                     int(own["max_iterations"]), float(own["matrix_update_angle"]))
    lw = lee_arrays(model.nw, model.n_links, tab.c.shape[0], L.n_diag(model.nw, model.n_links), y0.size)
    minv = inverse_mass(model.par, model.arms, model.n_links)
    integrate_lee(y0, controls.loop_control, tab, ls, minv, model.arrays, model.work,
                  event_arrays(model.nw, model.n_links), lw, out, lout)
    n = int(out.stats[L.S_N_OUT])
    out_x, out_lam, lstats = lout
    W = ("time", "wheel")
    extra = {}
    extra["joint_force_x"] = (
        W,
        out_lam[:n, L.J_X :: L.N_J_ROWS],
        "N",
        "horizontal force of the chassis on arm i at its "
        "pivot (Lagrange multiplier lambda, acceleration level)",
    )
    extra["joint_force_y"] = (
        W,
        out_lam[:n, L.J_Y :: L.N_J_ROWS],
        "N",
        "vertical force of the chassis on arm i at its "
        "pivot (Lagrange multiplier lambda, acceleration level)",
    )
    for dims, name, k, units, text in _FIGURES:
        extra[name] = (dims, out_x[:n, k] if dims else lstats[k], units, text)
    extra["lee_accel_order"] = (
        (),
        own["accel_order"],
        "1",
        "n of the accelerated iteration (A1-A6)",
    )
    return trimmed(controls, out, extra)
