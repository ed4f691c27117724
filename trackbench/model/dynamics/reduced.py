"""Equations of motion in reduced coordinates: chassis (x, y, pitch), arm angles
relative to the chassis, free pins (model/core/indices.py). The revolute joints are built into
the coordinates, so Eq. (9) becomes M(q) qdd = Q(q, qd) with an (3 + n_wheels)
square block for chassis + arms, solved by its Schur complement (the arm block is
diagonal), and a diagonal block for the pins.

The chassis block and the sums over the arms travel between the helpers as tuples
(a: the 3x3 block a00 a01 a02 a11 a12 a22; f: generalised forces on x, y, pitch;
e: kinetic, torsion and gravity energies); every helper is inlined, and every sum keeps
the order of a single loop.
"""

from numba import njit

from ..core.bundles import ARM_BT, ARM_BX, ARM_BY, ARM_COS, ARM_D, ARM_Q, ARM_SIN
from ..core.indices import (
    ARMS_DAMPING,
    ARMS_DIAGONAL,
    ARMS_INERTIA,
    ARMS_JOUNCE,
    ARMS_LENGTH,
    ARMS_MASS,
    ARMS_PHI0,
    ARMS_PX,
    ARMS_PY,
    ARMS_REBOUND,
    ARMS_STIFFNESS,
    ARMS_STOP_K,
    D_CHASSIS_ALPHA,
    D_CHASSIS_AX,
    D_CHASSIS_AY,
    D_DISSIPATION,
    D_E_GRAVITY,
    D_E_KINETIC,
    D_E_TORSION,
    D_POWER,
    P_CHASSIS_INERTIA,
    P_CHASSIS_MASS,
    P_GRAVITY,
    P_PIN_MASS,
    PN_LAST,
    PN_NQ,
    Q_ARM,
    Q_PITCH,
    Q_X,
    Q_Y,
    Y_DISSIPATED,
    Y_WORK,
)
from ..core.indices_jit import q_pin
from ..core.jit import BORROW, INLINE, SCALAR
from ..ground.grip import bristle_rates, start_bristles, uses_bristle
from ..vehicle.kinematics import body_offset, positions
from .track_loads import track_loads


@njit(**INLINE)
def _track_ends(q, par, apos, fpin):
    """Generalised force on (x, y, pitch) of the pins riding on the chassis (the paper's
    track ends, pins 0 and n_links) and the chassis weight."""
    last = apos.shape[0] - 1
    qx = fpin[0, 0] + fpin[last, 0]
    qy = fpin[0, 1] + fpin[last, 1] - par[P_CHASSIS_MASS] * par[P_GRAVITY]
    qt = 0.0
    for e in range(2):
        b = 0 if e == 0 else last
        qt += (apos[b, 0] - q[Q_X]) * fpin[b, 1] - (apos[b, 1] - q[Q_Y]) * fpin[b, 0]
    return qx, qy, qt


@njit(**SCALAR)
def stop_excess(phi, jounce, rebound):
    """How far arm angle phi lies beyond its bump stops (rad): phi - jounce below the jounce
    stop (the wheel up), phi - rebound above the rebound stop, else 0. The stop's torque on
    the arm is -k_stop times it, its energy 0.5 k_stop times its square."""
    if phi < jounce:
        return phi - jounce
    if phi > rebound:
        return phi - rebound
    return 0.0


@njit(**INLINE)
def chassis_and_arms(q, qd, par, arms, fwheel, wv, wc, arm, c, s, f0):
    """Chassis block A (3x3, symmetric) and generalised force on (x, y, pitch), starting
    from f0 (what acts on the chassis itself), every arm + road wheel added; the coupling
    B_i of each arm and its generalised force (torsion bar and bump stops included) into w.arm. Returns
    (A, f, (kinetic, torsion, gravity energies), power dissipated by the shock absorbers)."""
    mc = par[P_CHASSIS_MASS]
    g = par[P_GRAVITY]
    om = qd[Q_PITCH]
    a00 = mc
    a11 = mc
    a22 = par[P_CHASSIS_INERTIA]
    a01 = 0.0
    a02 = 0.0
    a12 = 0.0
    qx, qy, qt = f0
    ke = 0.5 * mc * (qd[Q_X] ** 2 + qd[Q_Y] ** 2) + 0.5 * a22 * om * om
    e_tors = 0.0
    dissipation = 0.0
    e_grav = mc * g * q[Q_Y]
    for i in range(arms.shape[0]):
        ma = arms[i, ARMS_MASS]
        ia = arms[i, ARMS_INERTIA]
        la = arms[i, ARMS_LENGTH]
        kt = arms[i, ARMS_STIFFNESS]
        cb = arm[i, ARM_COS]
        sb = arm[i, ARM_SIN]
        px, py = body_offset(c, s, arms[i, ARMS_PX], arms[i, ARMS_PY])
        rx = px + la * cb
        ry = py + la * sb
        rpx = -ry           # d(w)/d(pitch)
        rpy = rx
        sx = -la * sb       # d(w)/d(phi_i)
        sy = la * cb
        wb = om + qd[Q_ARM + i]
        # velocity-dependent (centripetal) acceleration of the wheel centre
        fx = fwheel[i, 0] - ma * (-om * om * px - wb * wb * la * cb)
        fy = fwheel[i, 1] - ma * g - ma * (-om * om * py - wb * wb * la * sb)
        a00 += ma
        a11 += ma
        a02 += ma * rpx
        a12 += ma * rpy
        a22 += ma * (rpx * rpx + rpy * rpy) + ia
        qx += fx
        qy += fy
        qt += rpx * fx + rpy * fy
        arm[i, ARM_BX] = ma * sx
        arm[i, ARM_BY] = ma * sy
        arm[i, ARM_BT] = ma * (rpx * sx + rpy * sy) + ia
        arm[i, ARM_Q] = sx * fx + sy * fy - kt * (q[Q_ARM + i] - arms[i, ARMS_PHI0])
        arm[i, ARM_D] = arms[i, ARMS_DIAGONAL]   # m l^2 + I: the arm block is diagonal
        if arms[i, ARMS_DAMPING] != 0.0:
            # rotary shock absorber: -c phi' on the arm, +c phi' on the chassis; phi is
            # relative to the chassis, so the pair acts on phi alone
            arm[i, ARM_Q] -= arms[i, ARMS_DAMPING] * qd[Q_ARM + i]
            dissipation += arms[i, ARMS_DAMPING] * qd[Q_ARM + i] ** 2
        ke += 0.5 * ma * (wv[i, 0] ** 2 + wv[i, 1] ** 2) + 0.5 * ia * wb * wb
        e_tors += 0.5 * kt * (q[Q_ARM + i] - arms[i, ARMS_PHI0]) ** 2
        if arms[i, ARMS_STOP_K] != 0.0:
            # bump stops: a stiff torsion spring beyond each stop angle, its energy with the
            # torsion bars' (skipped without stops: the paper's arm, bit for bit)
            ex = stop_excess(q[Q_ARM + i], arms[i, ARMS_JOUNCE], arms[i, ARMS_REBOUND])
            arm[i, ARM_Q] -= arms[i, ARMS_STOP_K] * ex
            e_tors += 0.5 * arms[i, ARMS_STOP_K] * ex * ex
        e_grav += ma * g * wc[i, 1]
    return (a00, a01, a02, a11, a12, a22), (qx, qy, qt), (ke, e_tors, e_grav), dissipation


@njit(**INLINE)
def take_out_rows(rows, d, col_d, a, f):
    """The Schur complement's part of rows that couple with the chassis alone (arms, the
    closed track's sprocket and idler): A - sum B_i B_i^T / d_i and f - sum B_i Q_i / d_i,
    d_i = d, or rows[i, col_d] where col_d >= 0."""
    s00, s01, s02, s11, s12, s22 = a
    r0, r1, r2 = f
    for i in range(rows.shape[0]):
        bx = rows[i, ARM_BX]
        by = rows[i, ARM_BY]
        bt = rows[i, ARM_BT]
        qa = rows[i, ARM_Q]
        di = rows[i, col_d] if col_d >= 0 else d
        s00 -= bx * bx / di
        s01 -= bx * by / di
        s02 -= bx * bt / di
        s11 -= by * by / di
        s12 -= by * bt / di
        s22 -= bt * bt / di
        r0 -= bx * qa / di
        r1 -= by * qa / di
        r2 -= bt * qa / di
    return (s00, s01, s02, s11, s12, s22), (r0, r1, r2)


@njit(**INLINE)
def chassis_acceleration(arm, a, f):
    """(ax, ay, alpha) of the chassis: the Schur complement S = A - sum B_i B_i^T / d_i and
    its right side, solved by cofactors (3x3 symmetric). d_i: arm i's diagonal mass (ARM_D)."""
    (s00, s01, s02, s11, s12, s22), (r0, r1, r2) = take_out_rows(arm, 0.0, ARM_D, a, f)
    c00 = s11 * s22 - s12 * s12
    c01 = s02 * s12 - s01 * s22
    c02 = s01 * s12 - s02 * s11
    c11 = s00 * s22 - s02 * s02
    c12 = s01 * s02 - s00 * s12
    c22 = s00 * s11 - s01 * s01
    det = s00 * c00 + s01 * c01 + s02 * c02
    return ((c00 * r0 + c01 * r1 + c02 * r2) / det, (c01 * r0 + c11 * r1 + c12 * r2) / det,
            (c02 * r0 + c12 * r1 + c22 * r2) / det)


@njit(**INLINE)
def pin_accelerations(par, nw, last, apos, avel, fpin, acc, ke, e_grav):
    """Free pins (rows 1..last): point masses under tension, contact forces and gravity."""
    mp = par[P_PIN_MASS]
    g = par[P_GRAVITY]
    for b in range(1, last + 1):
        k = q_pin(nw, b)
        acc[k] = fpin[b, 0] / mp
        acc[k + 1] = fpin[b, 1] / mp - g
        ke += 0.5 * mp * (avel[b, 0] ** 2 + avel[b, 1] ** 2)
        e_grav += mp * g * apos[b, 1]
    return ke, e_grav


@njit(**INLINE)
def start_rates(ydot, qd, nq, acc3):
    """ydot's first part, q' = qd, and the chassis accelerations (ax, ay, alpha) into its
    second; returns the accelerations' view."""
    for k in range(nq):
        ydot[k] = qd[k]
    acc = ydot[nq:2 * nq]
    acc[Q_X], acc[Q_Y], acc[Q_PITCH] = acc3
    return acc


@njit(**INLINE)
def row_acceleration(rows, i, d, acc3):
    """Acceleration of the coordinate of row i (an arm, the sprocket, the idler) that couples
    with the chassis alone: (Q_i - B_i . (ax, ay, alpha)) / d_i."""
    ax, ay, at = acc3
    return (rows[i, ARM_Q] - rows[i, ARM_BX] * ax - rows[i, ARM_BY] * ay - rows[i, ARM_BT] * at) / d


@njit(**INLINE)
def store_state_energies(diag, energies, acc3):
    """Kinetic, torsion and gravity energy and the chassis acceleration (ax, ay, alpha) into diag."""
    diag[D_E_KINETIC], diag[D_E_TORSION], diag[D_E_GRAVITY] = energies
    diag[D_CHASSIS_AX], diag[D_CHASSIS_AY], diag[D_CHASSIS_ALPHA] = acc3


@njit(**BORROW)
def reduced_rhs(y, m, w, ydot, diag):
    """ydot = f(y) for y = (q, qd, W, D, ..., bristles); fills diag (forces, energies, status)."""
    par, arms = m.par, m.arms
    apos, avel, fpin, wc, wv, fwheel, arm = w.apos, w.avel, w.fpin, w.wc, w.wv, w.fwheel, w.arm
    nq = m.pins[PN_NQ]
    q = y[:nq]
    qd = y[nq:2 * nq]
    c, s = positions(q, qd, par, arms, m.ends, apos, avel, wc, wv, arm)
    bristles = uses_bristle(par)
    if bristles:
        start_bristles(y, nq, m.pins[PN_LAST], par, w.grip)
    track_loads(w, m, diag)
    if bristles:
        bristle_rates(ydot, nq, m.pins[PN_LAST], par, w.grip, diag)
    a, f, e, arm_dissipation = chassis_and_arms(q, qd, par, arms, fwheel, wv, wc, arm, c, s,
                                                _track_ends(q, par, apos, fpin))
    acc3 = chassis_acceleration(arm, a, f)
    acc = start_rates(ydot, qd, nq, acc3)
    for i in range(arm.shape[0]):
        acc[Q_ARM + i] = row_acceleration(arm, i, arm[i, ARM_D], acc3)
    ke, e_tors, e_grav = e
    ke, e_grav = pin_accelerations(par, arms.shape[0], apos.shape[0] - 2, apos, avel, fpin, acc, ke, e_grav)
    diag[D_DISSIPATION] += arm_dissipation
    ydot[2 * nq + Y_WORK] = diag[D_POWER] - arm_dissipation  # dW/dt: contact forces and dampers
    ydot[2 * nq + Y_DISSIPATED] = diag[D_DISSIPATION]
    store_state_energies(diag, (ke, e_tors, e_grav), acc3)
