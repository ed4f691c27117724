"""Equations of motion in absolute coordinates (the paper's Eq. 9), for the "lee" solver.

Absolute state ``z`` (length ``nz = 3 (1 + n_wheels) + 2 (n_links - 1)``)::

    z[0:3]               chassis mass centre x, y and pitch theta
    z[z_arm(i) + ZA_X, ZA_Y]   arm i: mass centre = road-wheel centre (x, y)
    z[z_arm(i) + ZA_BETA]      arm i: absolute angle beta_i of the vector pivot -> wheel centre
    z[nb + 2 (b-1) + k]  free pin b = 1..n_links-1, coordinate k; nb = 3 (1 + n_wheels)

The mass matrix is constant and diagonal (``inverse_mass``). Revolute joint i (two
rows 2i, 2i+1 of Phi):

    Phi_i = r_c + R(theta) p_i - w_i + l e_i = 0,  e_i = (cos beta_i, sin beta_i)

with p_i the pivot body point. Eq. (9): M zdd = F(z) - Phi_q^T lambda, so lambda_i is
the force the chassis exerts on arm i at its pivot (the chassis gets -lambda_i there).
F holds gravity, torsion bars (torque -k_t (beta_i - theta - phi0_i) on arm i, the
reaction on the chassis; the bump stops' -k_stop x excess beyond a stop likewise), track
tension and contact forces from ``track_loads.track_loads``
(pins 0 and n_links ride on the chassis at the track-end body points). There are no
velocity-dependent forces, so Eq. (9) has the form z'' = f(z, lambda) an RKN method
integrates. Phi_q is never formed: the products are evaluated directly from the
per-joint vectors dr_i = d(R p_i)/d theta and l s_i = l (-sin beta_i, cos beta_i).
"""


import numpy as np
from numba import njit

from ..core import fixed_math as fm
from ..core.indices import (
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
    D_E_GRAVITY,
    D_E_KINETIC,
    D_E_TORSION,
    D_POWER,
    GEO_LX,
    GEO_LY,
    GEO_RX,
    GEO_RY,
    J_X,
    J_Y,
    LK_TX,
    LK_TY,
    N_J_ROWS,
    P_CHASSIS_INERTIA,
    P_CHASSIS_MASS,
    P_GRAVITY,
    P_PIN_MASS,
    Q_ARM,
    Q_PITCH,
    Q_X,
    Q_Y,
    Y_DISSIPATED,
    Y_WORK,
    Z_PITCH,
    Z_X,
    Z_Y,
    ZA_BETA,
    ZA_X,
    ZA_Y,
    n_absolute,
)
from ..core.indices_jit import diag_tension, nq_of, pin_offset, z_arm, z_pin
from ..core.jit import BORROW, INLINE
from ..vehicle.kinematics import body_offset, wheel_offset
from .reduced import stop_excess
from .track_loads import track_loads


def inverse_mass(par, arms, n_links):
    """Diagonal of M^-1 (constant)."""
    n_wheels = arms.shape[0]
    m = np.empty(n_absolute(n_wheels, n_links))
    m[[Z_X, Z_Y]] = par[P_CHASSIS_MASS]
    m[Z_PITCH] = par[P_CHASSIS_INERTIA]
    for i in range(n_wheels):
        m[z_arm(i) + ZA_X] = m[z_arm(i) + ZA_Y] = arms[i, ARMS_MASS]
        m[z_arm(i) + ZA_BETA] = arms[i, ARMS_INERTIA]
    m[z_pin(n_wheels):] = par[P_PIN_MASS]
    return 1.0 / m


@njit(**BORROW)
def from_reduced(y, par, arms, z, zd):
    """Reduced state (q, qd, W, D) -> absolute z, zd; returns W. The wheel centres are
    placed as everywhere else (kinematics.wheel_offset)."""
    nw = arms.shape[0]
    nq = nq_of(y.shape[0])
    nb = z_pin(nw)
    th = y[Q_PITCH]
    om = y[nq + Q_PITCH]
    s, c = fm.sincos(th)
    for k in (Z_X, Z_Y, Z_PITCH):   # the chassis coordinates are the same in both
        z[k] = y[k]
        zd[k] = y[nq + k]
    for i in range(nw):
        la = arms[i, ARMS_LENGTH]
        beta = th + y[Q_ARM + i]
        bd = om + y[nq + Q_ARM + i]
        sb, cb = fm.sincos(beta)
        rx, ry = wheel_offset(c, s, arms, i, la, cb, sb)
        px, py = body_offset(c, s, arms[i, ARMS_PX], arms[i, ARMS_PY])   # the pivot
        j = z_arm(i)
        z[j + ZA_X] = y[Q_X] + rx
        z[j + ZA_Y] = y[Q_Y] + ry
        z[j + ZA_BETA] = beta
        zd[j + ZA_X] = y[nq + Q_X] - om * py - bd * la * sb
        zd[j + ZA_Y] = y[nq + Q_Y] + om * px + bd * la * cb
        zd[j + ZA_BETA] = bd
    off = pin_offset(nw)
    for k in range(z.shape[0] - nb):
        z[nb + k] = y[off + k]
        zd[nb + k] = y[nq + off + k]
    return y[2 * nq + Y_WORK]


@njit(**BORROW)
def to_reduced(z, zd, work, nw, y):
    """Absolute z, zd and contact work -> reduced (q, qd, W, D = 0): phi_i = beta_i - theta."""
    nq = nq_of(y.shape[0])
    nb = z_pin(nw)
    off = pin_offset(nw)
    for k in (Z_X, Z_Y, Z_PITCH):
        y[k] = z[k]
        y[nq + k] = zd[k]
    for i in range(nw):
        y[Q_ARM + i] = z[z_arm(i) + ZA_BETA] - z[Z_PITCH]
        y[nq + Q_ARM + i] = zd[z_arm(i) + ZA_BETA] - zd[Z_PITCH]
    for k in range(z.shape[0] - nb):
        y[off + k] = z[nb + k]
        y[nq + off + k] = zd[nb + k]
    y[2 * nq + Y_WORK] = work
    y[2 * nq + Y_DISSIPATED] = 0.0


@njit(**BORROW)
def joint_vectors(z, par, arms, geo):
    """Per joint i: geo[i] = (r_x, r_y, l cos beta, l sin beta) with r = R(theta) p_i.
    Then dr_i = (-r_y, r_x) and d(l e_i)/d beta = (-l sin beta, l cos beta)."""
    s, c = fm.sincos(z[Z_PITCH])
    for i in range(arms.shape[0]):
        la = arms[i, ARMS_LENGTH]
        geo[i, GEO_RX], geo[i, GEO_RY] = body_offset(c, s, arms[i, ARMS_PX], arms[i, ARMS_PY])
        beta = z[z_arm(i) + ZA_BETA]
        geo[i, GEO_LX] = la * fm.cos(beta)
        geo[i, GEO_LY] = la * fm.sin(beta)


@njit(**BORROW)
def phi(z, geo, out):
    """Position constraints Phi (Eq. 1), 2 per joint; geo from joint_vectors(z)."""
    for i in range(geo.shape[0]):
        j = z_arm(i)
        out[N_J_ROWS * i + J_X] = z[Z_X] + geo[i, GEO_RX] - z[j + ZA_X] + geo[i, GEO_LX]
        out[N_J_ROWS * i + J_Y] = z[Z_Y] + geo[i, GEO_RY] - z[j + ZA_Y] + geo[i, GEO_LY]


@njit(**BORROW)
def phi_q_times(geo, u, out):
    """out = Phi_q u (u: body part of a velocity or acceleration vector)."""
    for i in range(geo.shape[0]):
        j = z_arm(i)
        out[N_J_ROWS * i + J_X] = (
            u[Z_X] - geo[i, GEO_RY] * u[Z_PITCH] - u[j + ZA_X] - geo[i, GEO_LY] * u[j + ZA_BETA]
        )
        out[N_J_ROWS * i + J_Y] = (
            u[Z_Y] + geo[i, GEO_RX] * u[Z_PITCH] - u[j + ZA_Y] + geo[i, GEO_LX] * u[j + ZA_BETA]
        )


@njit(**BORROW)
def add_phi_qt(geo, lam, scale, out):
    """out += scale * Phi_q^T lambda (body components only)."""
    for i in range(geo.shape[0]):
        j = z_arm(i)
        lx = scale * lam[N_J_ROWS * i + J_X]
        ly = scale * lam[N_J_ROWS * i + J_Y]
        out[Z_X] += lx
        out[Z_Y] += ly
        out[Z_PITCH] += -geo[i, GEO_RY] * lx + geo[i, GEO_RX] * ly
        out[j + ZA_X] -= lx
        out[j + ZA_Y] -= ly
        out[j + ZA_BETA] += -geo[i, GEO_LY] * lx + geo[i, GEO_LX] * ly


@njit(**BORROW)
def gamma(zd, geo, out):
    """Right side of the acceleration constraint: Phi_q zdd = gamma = theta'^2 r_i + beta_i'^2 l e_i,
    so the error of Eq. (14) is v = gamma - Phi_q zdd."""
    w2 = zd[Z_PITCH] * zd[Z_PITCH]
    for i in range(geo.shape[0]):
        b2 = zd[z_arm(i) + ZA_BETA] ** 2
        out[N_J_ROWS * i + J_X] = w2 * geo[i, GEO_RX] + b2 * geo[i, GEO_LX]
        out[N_J_ROWS * i + J_Y] = w2 * geo[i, GEO_RY] + b2 * geo[i, GEO_LY]


@njit(**BORROW)
def constraint_matrix(geo, minv, G):
    """G = Phi_q M^-1 Phi_q^T (the paper's C up to the factors of Eqs. 17-19)."""
    nw = geo.shape[0]
    mc = minv[Z_X]
    ic = minv[Z_PITCH]
    for i in range(nw):
        ai = (-geo[i, GEO_RY], geo[i, GEO_RX])
        for j in range(nw):
            aj = (-geo[j, GEO_RY], geo[j, GEO_RX])
            for r in range(N_J_ROWS):
                for k in range(N_J_ROWS):
                    v = ic * ai[r] * aj[k]
                    if r == k:
                        v += mc
                    G[N_J_ROWS * i + r, N_J_ROWS * j + k] = v
        ma = minv[z_arm(i) + ZA_X]
        ia = minv[z_arm(i) + ZA_BETA]
        si = (-geo[i, GEO_LY], geo[i, GEO_LX])
        for r in range(N_J_ROWS):
            for k in range(N_J_ROWS):
                G[N_J_ROWS * i + r, N_J_ROWS * i + k] += ia * si[r] * si[k] + (ma if r == k else 0.0)


@njit(**INLINE)
def _place_absolute(z, zd, ends, w):
    """Pin and wheel-centre positions and velocities from the absolute state into w."""
    apos, avel, wc, wv = w.apos, w.avel, w.wc, w.wv
    n_pins = apos.shape[0]
    nb = z_pin(wc.shape[0])
    s, c = fm.sincos(z[Z_PITCH])
    for i in range(wc.shape[0]):
        j = z_arm(i)
        wc[i, 0] = z[j + ZA_X]
        wc[i, 1] = z[j + ZA_Y]
        wv[i, 0] = zd[j + ZA_X]
        wv[i, 1] = zd[j + ZA_Y]
    for e in range(2):
        b = 0 if e == 0 else n_pins - 1
        rx, ry = body_offset(c, s, ends[e, 0], ends[e, 1])
        apos[b, 0] = z[Z_X] + rx
        apos[b, 1] = z[Z_Y] + ry
        avel[b, 0] = zd[Z_X] - zd[Z_PITCH] * ry
        avel[b, 1] = zd[Z_Y] + zd[Z_PITCH] * rx
    for b in range(1, n_pins - 1):
        k = nb + 2 * (b - 1)
        apos[b, 0] = z[k]
        apos[b, 1] = z[k + 1]
        avel[b, 0] = zd[k]
        avel[b, 1] = zd[k + 1]


@njit(**INLINE)
def _contact_only(fpin, lk, diag, t_off, fc):
    """fc = the pin forces without the link pulls of Eq. (8)."""
    n_pins = fpin.shape[0]
    for b in range(n_pins):
        fc[b, 0] = fpin[b, 0]
        fc[b, 1] = fpin[b, 1]
    for b in range(n_pins - 1):
        tn = diag[t_off + b]
        fc[b, 0] -= tn * lk[b, LK_TX]
        fc[b, 1] -= tn * lk[b, LK_TY]
        fc[b + 1, 0] += tn * lk[b, LK_TX]
        fc[b + 1, 1] += tn * lk[b, LK_TY]


@njit(**BORROW)
def applied_forces(z, zd, m, w, F, fc, diag):
    """F = applied generalised forces (no lambda) at z; fc = contact-only force on every
    pin (tension removed), w.fwheel = contact force on each wheel; diag filled by
    track_loads (forces, pad and tension energies, status). zd only feeds track_loads'
    power, which the solver recomputes (contact_power) with its final velocities."""
    par, arms = m.par, m.arms
    apos, fpin, fwheel = w.apos, w.fpin, w.fwheel
    nw = arms.shape[0]
    n_pins = apos.shape[0]
    nb = z_pin(nw)
    _place_absolute(z, zd, m.ends, w)
    track_loads(w, m, diag)
    g = par[P_GRAVITY]
    F[Z_X] = fpin[0, 0] + fpin[n_pins - 1, 0]
    F[Z_Y] = fpin[0, 1] + fpin[n_pins - 1, 1] - par[P_CHASSIS_MASS] * g
    tq = 0.0
    for e in range(2):
        b = 0 if e == 0 else n_pins - 1
        tq += (apos[b, 0] - z[Z_X]) * fpin[b, 1] - (apos[b, 1] - z[Z_Y]) * fpin[b, 0]
    for i in range(nw):
        j = z_arm(i)
        tors = -arms[i, ARMS_STIFFNESS] * (z[j + ZA_BETA] - z[Z_PITCH] - arms[i, ARMS_PHI0])
        if arms[i, ARMS_STOP_K] != 0.0:   # bump stops (reduced.chassis_and_arms)
            tors -= arms[i, ARMS_STOP_K] * stop_excess(z[j + ZA_BETA] - z[Z_PITCH], arms[i, ARMS_JOUNCE],
                                                       arms[i, ARMS_REBOUND])
        tq -= tors
        F[j + ZA_X] = fwheel[i, 0]
        F[j + ZA_Y] = fwheel[i, 1] - arms[i, ARMS_MASS] * g
        F[j + ZA_BETA] = tors
    F[Z_PITCH] = tq
    mg = par[P_PIN_MASS] * g
    for b in range(1, n_pins - 1):
        k = nb + 2 * (b - 1)
        F[k] = fpin[b, 0]
        F[k + 1] = fpin[b, 1] - mg
    _contact_only(fpin, w.lk, diag, diag_tension(nw), fc)


@njit(**BORROW)
def contact_power(z, zd, ends, fc, fw, nw):
    """Power of the contact forces fc (on pins), fw (on wheels) at velocity zd; the same
    sum track_loads forms for D_POWER (pins 0 and n_links move with the chassis)."""
    n_pins = fc.shape[0]
    nb = z_pin(nw)
    s, c = fm.sincos(z[Z_PITCH])
    p = 0.0
    for e in range(2):
        b = 0 if e == 0 else n_pins - 1
        rx, ry = body_offset(c, s, ends[e, 0], ends[e, 1])
        p += fc[b, 0] * (zd[Z_X] - zd[Z_PITCH] * ry) + fc[b, 1] * (zd[Z_Y] + zd[Z_PITCH] * rx)
    for b in range(1, n_pins - 1):
        k = nb + 2 * (b - 1)
        p += fc[b, 0] * zd[k] + fc[b, 1] * zd[k + 1]
    for i in range(nw):
        p += fw[i, 0] * zd[z_arm(i) + ZA_X] + fw[i, 1] * zd[z_arm(i) + ZA_Y]
    return p


@njit(**BORROW)
def finish_diag(z, zd, zdd, par, arms, power, diag):
    """Fill what reduced_rhs fills beyond track_loads: kinetic, torsion and gravity
    energy, contact power and chassis acceleration."""
    nw = arms.shape[0]
    nb = z_pin(nw)
    g = par[P_GRAVITY]
    ke = (0.5 * par[P_CHASSIS_MASS] * (zd[Z_X] ** 2 + zd[Z_Y] ** 2)
          + 0.5 * par[P_CHASSIS_INERTIA] * zd[Z_PITCH] ** 2)
    eg = par[P_CHASSIS_MASS] * g * z[Z_Y]
    et = 0.0
    for i in range(nw):
        j = z_arm(i)
        ke += (0.5 * arms[i, ARMS_MASS] * (zd[j + ZA_X] ** 2 + zd[j + ZA_Y] ** 2)
               + 0.5 * arms[i, ARMS_INERTIA] * zd[j + ZA_BETA] ** 2)
        eg += arms[i, ARMS_MASS] * g * z[j + ZA_Y]
        et += 0.5 * arms[i, ARMS_STIFFNESS] * (z[j + ZA_BETA] - z[Z_PITCH] - arms[i, ARMS_PHI0]) ** 2
        if arms[i, ARMS_STOP_K] != 0.0:
            ex = stop_excess(z[j + ZA_BETA] - z[Z_PITCH], arms[i, ARMS_JOUNCE], arms[i, ARMS_REBOUND])
            et += 0.5 * arms[i, ARMS_STOP_K] * ex * ex
    mp = par[P_PIN_MASS]
    for k in range(nb, z.shape[0], 2):
        ke += 0.5 * mp * (zd[k] ** 2 + zd[k + 1] ** 2)
        eg += mp * g * z[k + 1]
    diag[D_E_KINETIC] = ke
    diag[D_E_TORSION] = et
    diag[D_E_GRAVITY] = eg
    diag[D_POWER] = power
    diag[D_CHASSIS_AX] = zdd[Z_X]
    diag[D_CHASSIS_AY] = zdd[Z_Y]
    diag[D_CHASSIS_ALPHA] = zdd[Z_PITCH]
