"""The arrays the compiled kernels share, bundled as named tuples: numba passes a bundle
as one argument and reads its fields at no cost, so a kernel takes a few bundles rather
than thirty arrays. The Python side allocates and fills them once per run (``allocate_*``);
the kernels never allocate. What each array holds: model/core/indices.py."""

from collections import namedtuple

import numpy as np

from ..contact.laws import bristle_active
from . import indices as L

# Fixed for a run, except the candidate lists (nbr, ref), which the contact search
# refreshes as the track moves, and the counters.
ModelArrays = namedtuple("ModelArrays", [
    "par",        # (N_PAR,) scalar parameters, P_*
    "arms",       # (n_wheels, N_ARMS_COLS) per station: pivot body point, torsion-bar free angle, damper,
                  # arm length, wheel reach, masses, stiffness (ARMS_*)
    "ends",       # (2, 2) track-end body points: front (pin 0), rear (pin n_links)
    "seg",        # (n_segments, N_SEG_COLS) ground segments, SEG_*
    "corners",    # (n_corners, 2) convex ground corners
    "nbr",        # int (rows, width) candidate lists: count in NB_COUNT, entries after it
    "nbr_rows",   # int (N_KINDS + 1,) first row of each pair kind's block in nbr, K_*
    "ref",        # (n_pins + n_wheels, 2) pin and wheel positions when nbr was built
    "counters",   # int (N_COUNTERS,) C_*
    "v0",         # (rows, width - 1) approach speed of each pair at its onset, nbr's row layout
                  # and the partner (link, pin or segment) as column; 0 = not in contact
    "pins",       # int (N_PN,) which pin rows are free and the state's layout (nq, len(y)), PN_*
    "loop",       # (N_LOOP,) sprocket, tensioner and drive of the closed layout, LP_*; empty for the paper's
    "guides",     # (n_guides, N_G_COLS) idler (row 0) and support rollers, G_*; no rows for the paper's
    "rut",        # (n_cells,) the soil's memory: deepest sinkage reached in each cell along x (m);
                  # empty on rigid ground (P_RUT_X0, P_RUT_DX place the cells)
    "touchdown",  # (n_pins, 2) soft soil: where each pin touched the soil, for its shear displacement;
                  # NaN: off the soil or touched down in the last step
])

# Scratch of one evaluation of the track forces: pin and wheel-centre kinematics in,
# forces out (model/dynamics/track_loads.py).
Work = namedtuple("Work", [
    "apos",       # (n_pins, 2) pin positions, track ends included
    "avel",       # (n_pins, 2) pin velocities
    "fpin",       # (n_pins, 2) out: tension + contact force on each pin
    "wc",         # (n_wheels, 2) road-wheel centres
    "wv",         # (n_wheels, 2) road-wheel centre velocities
    "fwheel",     # (n_wheels, 2) out: contact force of the track on each wheel
    "lk",         # (n_links, 3) per link: unit direction t (pin b -> b+1) and length
    "arm",        # (n_wheels, ARM_COLS + 1) per arm: cos and sin of beta, the chassis coupling, its
                  # diagonal mass (ARM_D)
    "pair_seen",  # int (rows, width - 1): the evaluation (C_EVALUATIONS) that last found the pair
                  # in contact, for the laws that remember an approach speed
    "pair_rate",  # (rows, width - 1): its compression rate then
    "sink",       # (n_pins,) each pin's sinkage into soft soil at the last evaluation (m; 0 off it)
    "grip",       # (n_pins, N_GRIP) bristle friction at the last evaluation (indices.G_*): each free
                  # pin's deflection (from y), force, speed along the ground and dz/dt
])

ARM_BX, ARM_BY, ARM_BT, ARM_Q, ARM_COS, ARM_SIN = range(6)   # columns of Work.arm
ARM_COLS = 6
ARM_D = ARM_COLS   # Work.arm's and ClosedWork.extra's last column: the row's diagonal mass


def arm_table(pivots, phi0, damping, stations):
    """The arms array: pivot body points, torsion-bar free angles, rotary dampers, and each
    station's own values ({ARMS_* column: values}, model/vehicle/parameters.station_columns)."""
    arms = np.zeros((len(pivots), L.N_ARMS_COLS))
    arms[:, [L.ARMS_PX, L.ARMS_PY]] = pivots
    arms[:, L.ARMS_PHI0] = phi0
    arms[:, L.ARMS_DAMPING] = damping
    for col, values in stations.items():
        arms[:, col] = values
    return arms


def model_arrays(par, arms, ends, seg, corners, n_links, loop=None, guides=None, rut=None):
    """The bundle, with empty candidate lists (marked stale: built at the first use).
    loop and guides: the closed layout's (LP_*, G_*); rut: soft soil's memory cells; None
    for the paper's layout and rigid ground."""
    n_wheels = arms.shape[0]
    closed = loop is not None
    guides = np.zeros((0, L.N_G_COLS)) if guides is None else guides
    rows = L.neighbour_rows(n_wheels, corners.shape[0], n_links, guides.shape[0])
    nbr = np.zeros((rows[L.N_KINDS], L.neighbour_width(n_links, seg.shape[0])), dtype=np.int64)
    ref = np.full((n_links + 1 + n_wheels + guides.shape[0], 2), np.nan)
    pins = np.zeros(L.N_PN, dtype=np.int64)
    pins[L.PN_LAST] = n_links if closed else n_links - 1
    pins[L.PN_CLOSED] = int(closed)
    pins[L.PN_NQ] = L.n_coordinates(n_wheels, n_links, closed)
    pins[L.PN_NY] = L.n_state(pins[L.PN_NQ], pins[L.PN_LAST] if bristle_active(par) else 0)
    return ModelArrays(np.ascontiguousarray(par, dtype=float), np.ascontiguousarray(arms, dtype=float),
                       np.ascontiguousarray(ends, dtype=float), np.ascontiguousarray(seg, dtype=float),
                       np.ascontiguousarray(corners, dtype=float).reshape(-1, 2), nbr,
                       np.array(rows, dtype=np.int64), ref, np.zeros(L.N_COUNTERS, dtype=np.int64),
                       np.zeros((nbr.shape[0], nbr.shape[1] - 1)), pins,
                       np.ascontiguousarray(loop if closed else np.zeros(0), dtype=float),
                       np.ascontiguousarray(guides, dtype=float).reshape(-1, L.N_G_COLS),
                       np.zeros(0) if rut is None else np.ascontiguousarray(rut, dtype=float),
                       np.full((n_links + 1, 2), np.nan))


def work_arrays(m, n_wheels, n_links, at_rest=True):
    """Work for the paper's layout, ClosedWork for the closed one (m.pins says which).
    at_rest: room for the closed layout's generalised forces at rest (genf), which only the
    static equilibrium reads; without it (a run's) the evaluations skip them."""
    n_pins = n_links + 1
    closed = bool(m.pins[L.PN_CLOSED])
    base = (np.zeros((n_pins, 2)), np.zeros((n_pins, 2)), np.zeros((n_pins, 2)),
            np.zeros((n_wheels, 2)), np.zeros((n_wheels, 2)), np.zeros((n_wheels, 2)),
            np.zeros((n_links + closed, L.N_LK_COLS)), np.zeros((n_wheels, ARM_COLS + 1)),
            np.full(m.v0.shape, -1, dtype=np.int64), np.zeros(m.v0.shape), np.zeros(n_pins),
            np.zeros((n_pins, L.N_GRIP)))
    if not closed:
        return Work(*base)
    ng = m.guides.shape[0]
    nq = L.n_coordinates(n_wheels, n_links, closed=True)
    return ClosedWork(*base, np.zeros((ng, 2)), np.zeros((ng, 2)), np.zeros((ng, 2)), np.zeros(L.N_SP),
                    np.zeros((2, ARM_COLS + 1)), np.zeros(nq if at_rest else 0))


# The closed layout's scratch: Work, then the idler and rollers as Work has the road wheels,
# the sprocket and the generalised forces (the static equilibrium solves for them).
ClosedWork = namedtuple("ClosedWork", list(Work._fields) + [
    "gc",         # (n_guides, 2) idler and roller centres
    "gv",         # (n_guides, 2) their velocities
    "fguide",     # (n_guides, 2) out: contact force of the track on each
    "spr",        # (N_SP,) sprocket kinematics in, loads out (SP_*)
    "extra",      # (2, ARM_COLS + 1) the sprocket's and the idler's rows of the mass matrix, as
                  # Work.arm's, with their own diagonal mass in column ARM_COLS
    "genf",       # (nq,) out: generalised forces at rest (no inertia terms) for the equilibrium;
                  # (0,) in a run's Work: not computed
])
LOOP_SPROCKET, LOOP_IDLER = 0, 1   # rows of ClosedWork.extra


# Scratch of the event location (solvers/common/events.py): the configuration at both ends of
# a rejected step; the closed layout's adds its idler and rollers.
EventWork = namedtuple("EventWork", ["pins0", "pins1", "wheels0", "wheels1", "arm"])
ClosedEventWork = namedtuple("ClosedEventWork", list(EventWork._fields) + ["guides0", "guides1"])


def event_arrays(n_wheels, n_links, n_guides=None):
    """EventWork for the paper's layout, ClosedEventWork (n_guides: idler and rollers) for
    the closed one."""
    n_pins = n_links + 1
    base = (np.zeros((n_pins, 2)), np.zeros((n_pins, 2)), np.zeros((n_wheels, 2)), np.zeros((n_wheels, 2)),
            np.zeros((n_wheels, ARM_COLS)))
    if n_guides is None:
        return EventWork(*base)
    return ClosedEventWork(*base, np.zeros((n_guides, 2)), np.zeros((n_guides, 2)))
