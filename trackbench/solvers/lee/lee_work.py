"""What the "lee" solver's compiled loop (lee_loop.py) works in and writes to, allocated
once by the Python side: settings, scratch, outputs, and the names of their columns."""

from collections import namedtuple

import numpy as np

from ...model.core import indices as L
from ...model.core.indices import n_absolute

# Lee's iteration settings (controls.settings: the scenario's lee.* table, solvers/registry.py)
LeeSettings = namedtuple("LeeSettings", ["accel_order", "eps_iterations", "position_tol", "max_iterations",
                                         "matrix_update_angle"])

# Written by the loop: per-sample figures (x), multipliers (lam), run totals (lstats).
LeeOutputs = namedtuple("LeeOutputs", ["x", "lam", "lstats"])

# x columns: per output sample, over the accepted steps since the previous sample
X_STEPS, X_REJECTED, X_IT_POS, X_IT_VEL, X_IT_ACC, X_ERR_POS, X_ERR_VEL, X_ERR_ACC, \
    X_RATIO_POS, X_RATIO_VEL, X_RATIO_ACC, X_H = range(12)
N_X = 12
# lstats: run totals
L_IT_POS, L_IT_VEL, L_IT_ACC, L_PASSES, L_REJ_ERROR, L_REJ_CONSTRAINT, L_EPS1, \
    L_RATIO_POS, L_RATIO_VEL, L_RATIO_ACC, L_IT_OUT, L_BUILDS, L_IT_DIAG, L_DIAG_UNCONVERGED = range(14)
N_L = 14
# sc: scalars carried from step to step
SC_W, SC_P_START, SC_ALPHA, SC_GN = range(4)
N_SC = 4

# The loop's scratch. nz absolute coordinates, ns stages, nl = 2 n_wheels multipliers.
LeeWork = namedtuple("LeeWork", [
    "z", "zd", "zdd",            # state at t and its acceleration
    "Y", "zd_new", "zdd_new",    # state at t + h
    "u", "K", "Fst",             # velocity correction; per stage: acceleration, applied forces
    "fcs", "fws", "geos", "diags",   # per stage: contact forces on pins / wheels, joint vectors, diag
    "lam0", "lam1", "lam_prev", "lam_s", "lam_o", "lam_d", "dl", "v", "gam",   # multipliers, errors
    "G", "An", "Cn", "T", "tmp",  # constraint matrix, the accelerated iteration's matrices
    "ya", "fa", "yb", "fb", "yo",  # (z, zd, W) and its rate at both ends of a step; a sample
    "yred", "ev_y0", "ev_f0", "ev_y1", "ev_f1",   # reduced views (output, event location)
    "Fo", "fco", "geo_o", "zdd_o", "zdd_d",   # at an output sample; the reported acceleration
    "acc_x", "ang_ref", "sc",     # per-sample accumulator, angles of the last A_n, SC_* scalars
])


def lee_arrays(n_wheels, n_links, stages, n_diag, ny):
    nz = n_absolute(n_wheels, n_links)
    nl = 2 * n_wheels
    n_pins = n_links + 1
    v = lambda n: np.zeros(n)  # noqa: E731
    return LeeWork(
        v(nz),
        v(nz),
        v(nz),
        v(nz),
        v(nz),
        v(nz),
        v(nz),
        np.zeros((stages, nz)),
        np.zeros((stages, nz)),
        np.zeros((stages, n_pins, 2)),
        np.zeros((stages, n_wheels, 2)),
        np.zeros((stages, n_wheels, L.N_GEO_COLS)),
        np.zeros((stages, n_diag)),
        v(nl),
        v(nl),
        v(nl),
        v(nl),
        v(nl),
        v(nl),
        v(nl),
        v(nl),
        v(nl),
        np.zeros((nl, nl)),
        np.zeros((nl, nl)),
        np.zeros((nl, nl)),
        np.zeros((nl, nl)),
        np.zeros((nl, nl)),
        v(2 * nz + 1),
        v(2 * nz + 1),
        v(2 * nz + 1),
        v(2 * nz + 1),
        v(2 * nz + 1),
        v(ny),
        v(ny),
        v(ny),
        v(ny),
        v(ny),
        v(nz),
        np.zeros((n_pins, 2)),
        np.zeros((n_wheels, L.N_GEO_COLS)),
        v(nz),
        v(nz),
        v(N_X),
        v(1 + n_wheels),
        v(N_SC),
    )


def lee_outputs(n_out, n_wheels):
    return LeeOutputs(np.zeros((n_out, N_X)), np.full((n_out, 2 * n_wheels), np.nan), np.zeros(N_L))
