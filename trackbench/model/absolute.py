"""Equations of motion in absolute coordinates (the paper's Eq. 9), for the "lee" solver.

Absolute state ``z`` (length ``nz = 3 (1 + n_wheels) + 2 (n_links - 1)``)::

    z[0:3]               chassis mass centre x, y and pitch theta
    z[3 + 3 i + 0:2]     arm i: mass centre = road-wheel centre (x, y)
    z[3 + 3 i + 2]       arm i: absolute angle beta_i of the vector pivot -> wheel centre
    z[nb + 2 (b-1) + k]  free pin b = 1..n_links-1, coordinate k; nb = 3 (1 + n_wheels)

The mass matrix is constant and diagonal (``inverse_mass``). Revolute joint i (two
rows 2i, 2i+1 of Phi):

    Phi_i = r_c + R(theta) p_i - w_i + l e_i = 0,  e_i = (cos beta_i, sin beta_i)

with p_i the pivot body point. Eq. (9): M zdd = F(z) - Phi_q^T lambda, so lambda_i is
the force the chassis exerts on arm i at its pivot (the chassis gets -lambda_i there).
F holds gravity, torsion bars (torque -k_t (beta_i - theta - phi0_i) on arm i, the
reaction on the chassis), track tension and contact forces from ``kernels.track_loads``
(pins 0 and n_links ride on the chassis at the track-end body points). There are no
velocity-dependent forces, so Eq. (9) has the form z'' = f(z, lambda) an RKN method
integrates. Phi_q is never formed: the products are evaluated directly from the
per-joint vectors dr_i = d(R p_i)/d theta and l s_i = l (-sin beta_i, cos beta_i).
"""

import math

import numpy as np
from numba import njit

from .jit import KERNEL
from .kernels import track_loads
from .layout import (
    D_CHASSIS_AX, D_CHASSIS_AY, D_E_GRAVITY, D_E_KINETIC, D_E_TORSION, D_POWER, D_WHEEL,
    P_ARM_INERTIA, P_ARM_LENGTH, P_ARM_MASS, P_CHASSIS_INERTIA, P_CHASSIS_MASS, P_GRAVITY,
    P_PIN_MASS, P_TORSION_STIFFNESS, Q_ARM, Q_PITCH, Q_X, Q_Y,
)


def n_absolute(n_wheels, n_links):
    return 3 * (1 + n_wheels) + 2 * (n_links - 1)


def inverse_mass(par, n_wheels, n_links):
    """Diagonal of M^-1 (constant)."""
    nb = 3 * (1 + n_wheels)
    m = np.empty(n_absolute(n_wheels, n_links))
    m[0:2] = par[P_CHASSIS_MASS]
    m[2] = par[P_CHASSIS_INERTIA]
    for i in range(n_wheels):
        m[3 + 3 * i:5 + 3 * i] = par[P_ARM_MASS]
        m[5 + 3 * i] = par[P_ARM_INERTIA]
    m[nb:] = par[P_PIN_MASS]
    return 1.0 / m


@njit(cache=True, error_model="numpy")
def from_reduced(y, par, arms, z, zd):
    """Reduced state (q, qd, W) -> absolute z, zd; returns W."""
    nw = arms.shape[0]
    nq = (y.shape[0] - 1) // 2
    nb = 3 * (1 + nw)
    la = par[P_ARM_LENGTH]
    th = y[Q_PITCH]
    om = y[nq + Q_PITCH]
    c = math.cos(th)
    s = math.sin(th)
    for k in range(3):
        z[k] = y[k]
        zd[k] = y[nq + k]
    for i in range(nw):
        beta = th + y[Q_ARM + i]
        bd = om + y[nq + Q_ARM + i]
        rx = c * arms[i, 0] - s * arms[i, 1]
        ry = s * arms[i, 0] + c * arms[i, 1]
        cb = math.cos(beta)
        sb = math.sin(beta)
        j = 3 + 3 * i
        z[j] = y[Q_X] + rx + la * cb
        z[j + 1] = y[Q_Y] + ry + la * sb
        z[j + 2] = beta
        zd[j] = y[nq + Q_X] - om * ry - bd * la * sb
        zd[j + 1] = y[nq + Q_Y] + om * rx + bd * la * cb
        zd[j + 2] = bd
    off = Q_ARM + nw
    for k in range(z.shape[0] - nb):
        z[nb + k] = y[off + k]
        zd[nb + k] = y[nq + off + k]
    return y[2 * nq]


@njit(cache=True, error_model="numpy")
def to_reduced(z, zd, work, nw, y):
    """Absolute z, zd and contact work -> reduced (q, qd, W): phi_i = beta_i - theta."""
    nq = (y.shape[0] - 1) // 2
    nb = 3 * (1 + nw)
    off = Q_ARM + nw
    for k in range(3):
        y[k] = z[k]
        y[nq + k] = zd[k]
    for i in range(nw):
        y[Q_ARM + i] = z[5 + 3 * i] - z[2]
        y[nq + Q_ARM + i] = zd[5 + 3 * i] - zd[2]
    for k in range(z.shape[0] - nb):
        y[off + k] = z[nb + k]
        y[nq + off + k] = zd[nb + k]
    y[2 * nq] = work


@njit(cache=True, error_model="numpy")
def joint_vectors(z, par, arms, geo):
    """Per joint i: geo[i] = (r_x, r_y, l cos beta, l sin beta) with r = R(theta) p_i.
    Then dr_i = (-r_y, r_x) and d(l e_i)/d beta = (-l sin beta, l cos beta)."""
    la = par[P_ARM_LENGTH]
    c = math.cos(z[2])
    s = math.sin(z[2])
    for i in range(arms.shape[0]):
        geo[i, 0] = c * arms[i, 0] - s * arms[i, 1]
        geo[i, 1] = s * arms[i, 0] + c * arms[i, 1]
        beta = z[5 + 3 * i]
        geo[i, 2] = la * math.cos(beta)
        geo[i, 3] = la * math.sin(beta)


@njit(cache=True, error_model="numpy")
def phi(z, geo, out):
    """Position constraints Phi (Eq. 1), 2 per joint; geo from joint_vectors(z)."""
    for i in range(geo.shape[0]):
        j = 3 + 3 * i
        out[2 * i] = z[0] + geo[i, 0] - z[j] + geo[i, 2]
        out[2 * i + 1] = z[1] + geo[i, 1] - z[j + 1] + geo[i, 3]


@njit(cache=True, error_model="numpy")
def phi_q_times(geo, u, out):
    """out = Phi_q u (u: body part of a velocity or acceleration vector)."""
    for i in range(geo.shape[0]):
        j = 3 + 3 * i
        out[2 * i] = u[0] - geo[i, 1] * u[2] - u[j] - geo[i, 3] * u[j + 2]
        out[2 * i + 1] = u[1] + geo[i, 0] * u[2] - u[j + 1] + geo[i, 2] * u[j + 2]


@njit(cache=True, error_model="numpy")
def add_phi_qt(geo, lam, scale, out):
    """out += scale * Phi_q^T lambda (body components only)."""
    for i in range(geo.shape[0]):
        j = 3 + 3 * i
        lx = scale * lam[2 * i]
        ly = scale * lam[2 * i + 1]
        out[0] += lx
        out[1] += ly
        out[2] += -geo[i, 1] * lx + geo[i, 0] * ly
        out[j] -= lx
        out[j + 1] -= ly
        out[j + 2] += -geo[i, 3] * lx + geo[i, 2] * ly


@njit(cache=True, error_model="numpy")
def gamma(zd, geo, out):
    """Right side of the acceleration constraint: Phi_q zdd = gamma = theta'^2 r_i + beta_i'^2 l e_i,
    so the error of Eq. (14) is v = gamma - Phi_q zdd."""
    w2 = zd[2] * zd[2]
    for i in range(geo.shape[0]):
        b2 = zd[5 + 3 * i] ** 2
        out[2 * i] = w2 * geo[i, 0] + b2 * geo[i, 2]
        out[2 * i + 1] = w2 * geo[i, 1] + b2 * geo[i, 3]


@njit(cache=True, error_model="numpy")
def constraint_matrix(geo, minv, G):
    """G = Phi_q M^-1 Phi_q^T (the paper's C up to the factors of Eqs. 17-19)."""
    nw = geo.shape[0]
    mc = minv[0]
    ic = minv[2]
    for i in range(nw):
        ai = (-geo[i, 1], geo[i, 0])
        for j in range(nw):
            aj = (-geo[j, 1], geo[j, 0])
            for r in range(2):
                for k in range(2):
                    v = ic * ai[r] * aj[k]
                    if r == k:
                        v += mc
                    G[2 * i + r, 2 * j + k] = v
        ma = minv[3 + 3 * i]
        ia = minv[5 + 3 * i]
        si = (-geo[i, 3], geo[i, 2])
        for r in range(2):
            for k in range(2):
                G[2 * i + r, 2 * i + k] += ia * si[r] * si[k] + (ma if r == k else 0.0)


@njit(**KERNEL)
def applied_forces(z, zd, par, arms, ends, seg, corners, nbr, ref, work, F, fc, diag):
    """F = applied generalised forces (no lambda) at z; fc = contact-only force on every
    pin (tension removed), fwheel (in work) = contact force on each wheel; diag filled by
    track_loads (forces, pad and tension energies, status). zd only feeds track_loads'
    power, which the solver recomputes (contact_power) with its final velocities."""
    apos, avel, fpin, fwheel, wc, wv, lk, arm = work
    nw = arms.shape[0]
    n_pins = apos.shape[0]
    nb = 3 * (1 + nw)
    c = math.cos(z[2])
    s = math.sin(z[2])
    for i in range(nw):
        j = 3 + 3 * i
        wc[i, 0] = z[j]
        wc[i, 1] = z[j + 1]
        wv[i, 0] = zd[j]
        wv[i, 1] = zd[j + 1]
    for e in range(2):
        b = 0 if e == 0 else n_pins - 1
        rx = c * ends[e, 0] - s * ends[e, 1]
        ry = s * ends[e, 0] + c * ends[e, 1]
        apos[b, 0] = z[0] + rx
        apos[b, 1] = z[1] + ry
        avel[b, 0] = zd[0] - zd[2] * ry
        avel[b, 1] = zd[1] + zd[2] * rx
    for b in range(1, n_pins - 1):
        k = nb + 2 * (b - 1)
        apos[b, 0] = z[k]
        apos[b, 1] = z[k + 1]
        avel[b, 0] = zd[k]
        avel[b, 1] = zd[k + 1]
    t_off = D_WHEEL + 2 * nw
    track_loads(apos, avel, wc, wv, par, seg, corners, nbr, ref, lk, fpin, fwheel, diag, t_off)
    g = par[P_GRAVITY]
    kt = par[P_TORSION_STIFFNESS]
    F[0] = fpin[0, 0] + fpin[n_pins - 1, 0]
    F[1] = fpin[0, 1] + fpin[n_pins - 1, 1] - par[P_CHASSIS_MASS] * g
    tq = 0.0
    for e in range(2):
        b = 0 if e == 0 else n_pins - 1
        tq += (apos[b, 0] - z[0]) * fpin[b, 1] - (apos[b, 1] - z[1]) * fpin[b, 0]
    for i in range(nw):
        j = 3 + 3 * i
        tors = -kt * (z[j + 2] - z[2] - arms[i, 2])
        tq -= tors
        F[j] = fwheel[i, 0]
        F[j + 1] = fwheel[i, 1] - par[P_ARM_MASS] * g
        F[j + 2] = tors
    F[2] = tq
    mg = par[P_PIN_MASS] * g
    for b in range(1, n_pins - 1):
        k = nb + 2 * (b - 1)
        F[k] = fpin[b, 0]
        F[k + 1] = fpin[b, 1] - mg
    # contact-only pin forces: remove the link pulls of Eq. (8)
    for b in range(n_pins):
        fc[b, 0] = fpin[b, 0]
        fc[b, 1] = fpin[b, 1]
    for b in range(n_pins - 1):
        tn = diag[t_off + b]
        fc[b, 0] -= tn * lk[b, 0]
        fc[b, 1] -= tn * lk[b, 1]
        fc[b + 1, 0] += tn * lk[b, 0]
        fc[b + 1, 1] += tn * lk[b, 1]


@njit(cache=True, error_model="numpy")
def contact_power(z, zd, ends, fc, fw, nw):
    """Power of the contact forces fc (on pins), fw (on wheels) at velocity zd; the same
    sum track_loads forms for D_POWER (pins 0 and n_links move with the chassis)."""
    n_pins = fc.shape[0]
    nb = 3 * (1 + nw)
    c = math.cos(z[2])
    s = math.sin(z[2])
    p = 0.0
    for e in range(2):
        b = 0 if e == 0 else n_pins - 1
        rx = c * ends[e, 0] - s * ends[e, 1]
        ry = s * ends[e, 0] + c * ends[e, 1]
        p += fc[b, 0] * (zd[0] - zd[2] * ry) + fc[b, 1] * (zd[1] + zd[2] * rx)
    for b in range(1, n_pins - 1):
        k = nb + 2 * (b - 1)
        p += fc[b, 0] * zd[k] + fc[b, 1] * zd[k + 1]
    for i in range(nw):
        p += fw[i, 0] * zd[3 + 3 * i] + fw[i, 1] * zd[4 + 3 * i]
    return p


@njit(cache=True, error_model="numpy")
def finish_diag(z, zd, zdd, par, arms, power, diag):
    """Fill what reduced_rhs fills beyond track_loads: kinetic, torsion and gravity
    energy, contact power and chassis acceleration."""
    nw = arms.shape[0]
    nb = 3 * (1 + nw)
    g = par[P_GRAVITY]
    kt = par[P_TORSION_STIFFNESS]
    ke = 0.5 * par[P_CHASSIS_MASS] * (zd[0] ** 2 + zd[1] ** 2) + 0.5 * par[P_CHASSIS_INERTIA] * zd[2] ** 2
    eg = par[P_CHASSIS_MASS] * g * z[1]
    et = 0.0
    for i in range(nw):
        j = 3 + 3 * i
        ke += 0.5 * par[P_ARM_MASS] * (zd[j] ** 2 + zd[j + 1] ** 2) + 0.5 * par[P_ARM_INERTIA] * zd[j + 2] ** 2
        eg += par[P_ARM_MASS] * g * z[j + 1]
        et += 0.5 * kt * (z[j + 2] - z[2] - arms[i, 2]) ** 2
    mp = par[P_PIN_MASS]
    for k in range(nb, z.shape[0], 2):
        ke += 0.5 * mp * (zd[k] ** 2 + zd[k + 1] ** 2)
        eg += mp * g * z[k + 1]
    diag[D_E_KINETIC] = ke
    diag[D_E_TORSION] = et
    diag[D_E_GRAVITY] = eg
    diag[D_POWER] = power
    diag[D_CHASSIS_AX] = zdd[0]
    diag[D_CHASSIS_AY] = zdd[1]
