"""Equations of motion in reduced coordinates: chassis (x, y, pitch), arm angles
relative to the chassis, free pins (layout.py). The revolute joints are built into
the coordinates, so Eq. (9) becomes M(q) qdd = Q(q, qd) with an (3 + n_wheels)
square block for chassis + arms, solved by its Schur complement (the arm block is
diagonal), and a diagonal block for the pins.

The chassis block and the sums over the arms travel between the helpers as tuples
(a: the 3x3 block a00 a01 a02 a11 a12 a22; f: generalised forces on x, y, pitch;
e: kinetic, torsion and gravity energies); every helper is inlined, and every sum keeps
the order of a single loop.
"""

from numba import njit

from .bundles import ARM_BT, ARM_BX, ARM_BY, ARM_COS, ARM_Q, ARM_SIN
from .jit import INLINE, KERNEL
from .kernels import track_loads
from .kinematics import body_offset, positions
from .layout import (
    ARMS_DAMPING, ARMS_PHI0, D_DISSIPATION, Y_DISSIPATED, Y_WORK,
    D_CHASSIS_AX, D_CHASSIS_AY, D_E_GRAVITY, D_E_KINETIC, D_E_TORSION, D_POWER, P_ARM_INERTIA, P_ARM_LENGTH,
    P_ARM_MASS, P_CHASSIS_INERTIA, P_CHASSIS_MASS, P_GRAVITY, P_PIN_MASS, P_TORSION_STIFFNESS, Q_ARM, Q_PITCH,
    Q_X, Q_Y, q_pin,
)
from .layout import nq_of


@njit(**INLINE)
def _chassis(q, qd, m, w):
    """The chassis alone: its mass block, the track-end pulls and gravity on it, its
    kinetic energy and gravity potential."""
    par, fpin, apos = m.par, w.fpin, w.apos
    mc = par[P_CHASSIS_MASS]
    g = par[P_GRAVITY]
    last = apos.shape[0] - 1
    a = (mc, 0.0, 0.0, mc, 0.0, par[P_CHASSIS_INERTIA])
    qt = 0.0
    for b in (0, last):
        rx = apos[b, 0] - q[Q_X]
        ry = apos[b, 1] - q[Q_Y]
        qt += rx * fpin[b, 1] - ry * fpin[b, 0]
    f = (fpin[0, 0] + fpin[last, 0], fpin[0, 1] + fpin[last, 1] - mc * g, qt)
    om = qd[Q_PITCH]
    e = (0.5 * mc * (qd[Q_X] ** 2 + qd[Q_Y] ** 2) + 0.5 * par[P_CHASSIS_INERTIA] * om * om, 0.0, mc * g * q[Q_Y])
    return a, f, e


@njit(**INLINE)
def _arms(q, qd, m, w, c, s, a, f, e):
    """Add every arm + road wheel to the chassis block; fill the arm columns of w.arm with
    its coupling B_i to (x, y, pitch) and its generalised force (torsion bar included)."""
    par, arm = m.par, w.arm
    ma = par[P_ARM_MASS]
    ia = par[P_ARM_INERTIA]
    la = par[P_ARM_LENGTH]
    kt = par[P_TORSION_STIFFNESS]
    g = par[P_GRAVITY]
    om = qd[Q_PITCH]
    a00, a01, a02, a11, a12, a22 = a
    qx, qy, qt = f
    ke, e_tors, e_grav = e
    dissipation = 0.0
    for i in range(m.arms.shape[0]):
        cb = arm[i, ARM_COS]
        sb = arm[i, ARM_SIN]
        px, py = body_offset(c, s, m.arms[i, 0], m.arms[i, 1])
        rx = px + la * cb
        ry = py + la * sb
        rpx = -ry           # d(w)/d(pitch)
        rpy = rx
        sx = -la * sb       # d(w)/d(phi_i)
        sy = la * cb
        wb = om + qd[Q_ARM + i]
        # velocity-dependent (centripetal) acceleration of the wheel centre
        avx = -om * om * px - wb * wb * la * cb
        avy = -om * om * py - wb * wb * la * sb
        fx = w.fwheel[i, 0] - ma * avx
        fy = w.fwheel[i, 1] - ma * g - ma * avy
        a00 += ma
        a11 += ma
        a02 += ma * rpx
        a12 += ma * rpy
        a22 += ma * (rpx * rpx + rpy * rpy) + ia
        qx += fx
        qy += fy
        qt += rpx * fx + rpy * fy
        tors = -kt * (q[Q_ARM + i] - m.arms[i, ARMS_PHI0])
        arm[i, ARM_BX] = ma * sx
        arm[i, ARM_BY] = ma * sy
        arm[i, ARM_BT] = ma * (rpx * sx + rpy * sy) + ia
        arm[i, ARM_Q] = sx * fx + sy * fy + tors
        cd = m.arms[i, ARMS_DAMPING]
        if cd != 0.0:
            # rotary shock absorber: -c phi' on the arm, +c phi' on the chassis; phi is
            # relative to the chassis, so the pair acts on phi alone
            arm[i, ARM_Q] -= cd * qd[Q_ARM + i]
            dissipation += cd * qd[Q_ARM + i] ** 2
        ke += 0.5 * ma * (w.wv[i, 0] ** 2 + w.wv[i, 1] ** 2) + 0.5 * ia * wb * wb
        e_tors += 0.5 * kt * (q[Q_ARM + i] - m.arms[i, ARMS_PHI0]) ** 2
        e_grav += ma * g * w.wc[i, 1]
    return (a00, a01, a02, a11, a12, a22), (qx, qy, qt), (ke, e_tors, e_grav), dissipation


@njit(**INLINE)
def _chassis_acceleration(arm, d, a, f):
    """(ax, ay, alpha) of the chassis: the Schur complement S = A - sum B_i B_i^T / d and
    its right side, solved by cofactors (3x3 symmetric). d: the arms' diagonal mass."""
    s00, s01, s02, s11, s12, s22 = a
    r0, r1, r2 = f
    for i in range(arm.shape[0]):
        bx = arm[i, ARM_BX]
        by = arm[i, ARM_BY]
        bt = arm[i, ARM_BT]
        qa = arm[i, ARM_Q]
        s00 -= bx * bx / d
        s01 -= bx * by / d
        s02 -= bx * bt / d
        s11 -= by * by / d
        s12 -= by * bt / d
        s22 -= bt * bt / d
        r0 -= bx * qa / d
        r1 -= by * qa / d
        r2 -= bt * qa / d
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
def _pins(m, w, acc, ke, e_grav):
    """Free pins: point masses under tension, contact forces and gravity."""
    mp = m.par[P_PIN_MASS]
    g = m.par[P_GRAVITY]
    nw = m.arms.shape[0]
    for b in range(1, w.apos.shape[0] - 1):
        k = q_pin(nw, b)
        acc[k] = w.fpin[b, 0] / mp
        acc[k + 1] = w.fpin[b, 1] / mp - g
        ke += 0.5 * mp * (w.avel[b, 0] ** 2 + w.avel[b, 1] ** 2)
        e_grav += mp * g * w.apos[b, 1]
    return ke, e_grav


@njit(**KERNEL)
def reduced_rhs(y, m, w, ydot, diag):
    """ydot = f(y) for y = (q, qd, W, D); fills diag (forces, energies, status)."""
    nq = nq_of(y.shape[0])
    q = y[:nq]
    qd = y[nq:2 * nq]
    c, s = positions(q, qd, m, w)
    track_loads(w, m, diag)
    a, f, e = _chassis(q, qd, m, w)
    a, f, e, arm_dissipation = _arms(q, qd, m, w, c, s, a, f, e)
    d = m.par[P_ARM_MASS] * m.par[P_ARM_LENGTH] * m.par[P_ARM_LENGTH] + m.par[P_ARM_INERTIA]  # arm block: diagonal, constant
    ax, ay, at = _chassis_acceleration(w.arm, d, a, f)
    for k in range(nq):
        ydot[k] = qd[k]
    acc = ydot[nq:2 * nq]
    acc[Q_X] = ax
    acc[Q_Y] = ay
    acc[Q_PITCH] = at
    for i in range(m.arms.shape[0]):
        acc[Q_ARM + i] = (w.arm[i, ARM_Q] - w.arm[i, ARM_BX] * ax - w.arm[i, ARM_BY] * ay
                          - w.arm[i, ARM_BT] * at) / d
    ke, e_tors, e_grav = e
    ke, e_grav = _pins(m, w, acc, ke, e_grav)
    diag[D_DISSIPATION] += arm_dissipation
    ydot[2 * nq + Y_WORK] = diag[D_POWER] - arm_dissipation  # dW/dt: contact forces and dampers
    ydot[2 * nq + Y_DISSIPATED] = diag[D_DISSIPATION]
    diag[D_E_KINETIC] = ke
    diag[D_E_TORSION] = e_tors
    diag[D_E_GRAVITY] = e_grav
    diag[D_CHASSIS_AX] = ax
    diag[D_CHASSIS_AY] = ay
