"""Equations of motion in reduced coordinates: chassis (x, y, pitch), arm angles
relative to the chassis, free pins (layout.py). The revolute joints are built into
the coordinates, so Eq. (9) becomes M(q) qdd = Q(q, qd) with an (3 + n_wheels)
square block for chassis + arms, solved by its Schur complement (the arm block is
diagonal), and a diagonal block for the pins.
"""

import math

import numpy as np
from numba import njit

from .jit import INLINE, KERNEL
from .kernels import track_loads
from .layout import (
    D_CHASSIS_AX, D_CHASSIS_AY, D_E_GRAVITY, D_POWER, D_E_KINETIC, D_E_TORSION, P_ARM_INERTIA,
    P_ARM_LENGTH, P_ARM_MASS, P_CHASSIS_INERTIA, P_CHASSIS_MASS, P_GRAVITY, P_PIN_MASS,
    P_TORSION_STIFFNESS, Q_ARM, Q_PITCH, Q_X, Q_Y, D_WHEEL,
)


def allocate_work(n_wheels, n_links):
    """Scratch arrays of one right-hand side: (apos, avel, fpin, fwheel, wc, wv, lk, arm)."""
    n_pins = n_links + 1
    return (np.zeros((n_pins, 2)), np.zeros((n_pins, 2)), np.zeros((n_pins, 2)),
            np.zeros((n_wheels, 2)), np.zeros((n_wheels, 2)), np.zeros((n_wheels, 2)),
            np.zeros((n_links, 3)), np.zeros((n_wheels, 6)))


@njit(**INLINE)
def positions(q, qd, par, arms, ends, apos, avel, wc, wv, arm):
    """Pin and wheel-centre positions and velocities from the reduced state; keeps
    cos and sin of each arm's absolute angle in arm[:, 4:6] for the caller."""
    nw = arms.shape[0]
    n_pins = apos.shape[0]
    off = Q_ARM + nw
    c = math.cos(q[Q_PITCH])
    s = math.sin(q[Q_PITCH])
    om = qd[Q_PITCH]
    la = par[P_ARM_LENGTH]
    for i in range(nw):
        beta = q[Q_PITCH] + q[Q_ARM + i]
        cb = math.cos(beta)
        sb = math.sin(beta)
        arm[i, 4] = cb
        arm[i, 5] = sb
        rx = c * arms[i, 0] - s * arms[i, 1] + la * cb
        ry = s * arms[i, 0] + c * arms[i, 1] + la * sb
        wc[i, 0] = q[Q_X] + rx
        wc[i, 1] = q[Q_Y] + ry
        wv[i, 0] = qd[Q_X] - om * ry - qd[Q_ARM + i] * la * sb
        wv[i, 1] = qd[Q_Y] + om * rx + qd[Q_ARM + i] * la * cb
    for e in range(2):
        b = 0 if e == 0 else n_pins - 1
        rx = c * ends[e, 0] - s * ends[e, 1]
        ry = s * ends[e, 0] + c * ends[e, 1]
        apos[b, 0] = q[Q_X] + rx
        apos[b, 1] = q[Q_Y] + ry
        avel[b, 0] = qd[Q_X] - om * ry
        avel[b, 1] = qd[Q_Y] + om * rx
    for b in range(1, n_pins - 1):
        k = off + 2 * (b - 1)
        apos[b, 0] = q[k]
        apos[b, 1] = q[k + 1]
        avel[b, 0] = qd[k]
        avel[b, 1] = qd[k + 1]
    return c, s


@njit(**KERNEL)
def reduced_rhs(y, par, arms, ends, seg, corners, nbr, ref, work, ydot, diag):
    """ydot = f(y) for y = (q, qd, W); fills diag (forces, energies, status).

    arms: (n_wheels, 3) pivot body point and free angle phi0 of each torsion bar.
    """
    apos, avel, fpin, fwheel, wc, wv, lk, arm = work
    nw = arms.shape[0]
    n_pins = apos.shape[0]
    nq = (y.shape[0] - 1) // 2
    q = y[:nq]
    qd = y[nq:2 * nq]
    c, s = positions(q, qd, par, arms, ends, apos, avel, wc, wv, arm)
    track_loads(apos, avel, wc, wv, par, seg, corners, nbr, ref, lk, fpin, fwheel,
                diag, D_WHEEL + 2 * nw)

    g = par[P_GRAVITY]
    mc = par[P_CHASSIS_MASS]
    ma = par[P_ARM_MASS]
    ia = par[P_ARM_INERTIA]
    la = par[P_ARM_LENGTH]
    kt = par[P_TORSION_STIFFNESS]
    mp = par[P_PIN_MASS]
    om = qd[Q_PITCH]

    # chassis block A (3x3, symmetric) and generalised force on (x, y, pitch)
    a00 = mc
    a11 = mc
    a22 = par[P_CHASSIS_INERTIA]
    a01 = 0.0
    a02 = 0.0
    a12 = 0.0
    qx = fpin[0, 0] + fpin[n_pins - 1, 0]
    qy = fpin[0, 1] + fpin[n_pins - 1, 1] - mc * g
    qt = 0.0
    for e in range(2):
        b = 0 if e == 0 else n_pins - 1
        rx = apos[b, 0] - q[Q_X]
        ry = apos[b, 1] - q[Q_Y]
        qt += rx * fpin[b, 1] - ry * fpin[b, 0]
    d = ma * la * la + ia  # arm block: diagonal and constant
    ke = 0.5 * mc * (qd[Q_X] ** 2 + qd[Q_Y] ** 2) + 0.5 * a22 * om * om
    e_tors = 0.0
    e_grav = mc * g * q[Q_Y]
    # accumulate the Schur complement S = A - sum B_i B_i^T / d and its right side
    bx_ = arm[:, 0]  # coupling column B_i of arm i with (x, y, pitch)
    by_ = arm[:, 1]
    bt_ = arm[:, 2]
    qa_ = arm[:, 3]  # generalised force on phi_i
    for i in range(nw):
        cb = arm[i, 4]
        sb = arm[i, 5]
        px = c * arms[i, 0] - s * arms[i, 1]
        py = s * arms[i, 0] + c * arms[i, 1]
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
        fx = fwheel[i, 0] - ma * avx
        fy = fwheel[i, 1] - ma * g - ma * avy
        a00 += ma
        a11 += ma
        a02 += ma * rpx
        a12 += ma * rpy
        a22 += ma * (rpx * rpx + rpy * rpy) + ia
        qx += fx
        qy += fy
        qt += rpx * fx + rpy * fy
        tors = -kt * (q[Q_ARM + i] - arms[i, 2])
        bx_[i] = ma * sx
        by_[i] = ma * sy
        bt_[i] = ma * (rpx * sx + rpy * sy) + ia
        qa_[i] = sx * fx + sy * fy + tors
        ke += 0.5 * ma * (wv[i, 0] ** 2 + wv[i, 1] ** 2) + 0.5 * ia * wb * wb
        e_tors += 0.5 * kt * (q[Q_ARM + i] - arms[i, 2]) ** 2
        e_grav += ma * g * wc[i, 1]
    s00 = a00
    s01 = a01
    s02 = a02
    s11 = a11
    s12 = a12
    s22 = a22
    r0 = qx
    r1 = qy
    r2 = qt
    for i in range(nw):
        s00 -= bx_[i] * bx_[i] / d
        s01 -= bx_[i] * by_[i] / d
        s02 -= bx_[i] * bt_[i] / d
        s11 -= by_[i] * by_[i] / d
        s12 -= by_[i] * bt_[i] / d
        s22 -= bt_[i] * bt_[i] / d
        r0 -= bx_[i] * qa_[i] / d
        r1 -= by_[i] * qa_[i] / d
        r2 -= bt_[i] * qa_[i] / d
    # 3x3 symmetric solve by cofactors
    c00 = s11 * s22 - s12 * s12
    c01 = s02 * s12 - s01 * s22
    c02 = s01 * s12 - s02 * s11
    c11 = s00 * s22 - s02 * s02
    c12 = s01 * s02 - s00 * s12
    c22 = s00 * s11 - s01 * s01
    det = s00 * c00 + s01 * c01 + s02 * c02
    ax = (c00 * r0 + c01 * r1 + c02 * r2) / det
    ay = (c01 * r0 + c11 * r1 + c12 * r2) / det
    at = (c02 * r0 + c12 * r1 + c22 * r2) / det
    for k in range(nq):
        ydot[k] = qd[k]
    acc = ydot[nq:2 * nq]
    acc[Q_X] = ax
    acc[Q_Y] = ay
    acc[Q_PITCH] = at
    for i in range(nw):
        acc[Q_ARM + i] = (qa_[i] - bx_[i] * ax - by_[i] * ay - bt_[i] * at) / d
    off = Q_ARM + nw
    for b in range(1, n_pins - 1):
        k = off + 2 * (b - 1)
        acc[k] = fpin[b, 0] / mp
        acc[k + 1] = fpin[b, 1] / mp - g
        ke += 0.5 * mp * (avel[b, 0] ** 2 + avel[b, 1] ** 2)
        e_grav += mp * g * apos[b, 1]
    ydot[2 * nq] = diag[D_POWER]  # dW/dt
    diag[D_E_KINETIC] = ke
    diag[D_E_TORSION] = e_tors
    diag[D_E_GRAVITY] = e_grav
    diag[D_CHASSIS_AX] = ax
    diag[D_CHASSIS_AY] = ay
