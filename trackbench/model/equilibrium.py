"""Static equilibrium on flat ground (spec, "Initial equilibrium").

Every arm is held at the equilibrium arm angle; unknowns are the chassis height and
pitch and the free pins. The torsion-bar free angles phi0_i (the preloads) follow from
each arm's moment balance about its pivot, so they are eliminated from the Newton
iteration and computed afterwards.
"""

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from ..solvers import dense
from ..status import EquilibriumError
from . import layout as L
from .index import n_coordinates, n_state, pin_offset, q_idler, q_sprocket
from .jit import KERNEL
from .bundles import arm_table, model_arrays, work_arrays
from .parameters import equilibrium_arm_angle, pack, total_mass
from .loop import loop_rhs
from .rhs import rhs
from .terrain import flat_ground
from .track_path import initial_track
from . import fixed_math as fm




@dataclass
class Equilibrium:
    q: np.ndarray              # reduced coordinates (layout.py), chassis x = 0
    phi0: np.ndarray           # torsion-bar free angles (rad)
    preload: np.ndarray        # torsion-bar torque on each arm at equilibrium (N m)
    wheel_load: np.ndarray     # vertical track force on each road wheel (N)
    tension: np.ndarray        # per link (N)
    ground_force: float        # total vertical ground force (N)
    weight: float              # total weight (N)
    residual: float            # max |force residual| (N), torsion-bar moments included
    iterations: int
    info: dict = field(default_factory=dict)

    @property
    def chassis_height(self):
        return float(self.q[L.Q_Y])

    @property
    def chassis_pitch(self):
        return float(self.q[L.Q_PITCH])

    def summary(self):
        t = self.tension
        return {
            "chassis_height_m": self.chassis_height,
            "chassis_pitch_rad": self.chassis_pitch,
            "tension_mean_N": float(t.mean()),
            "tension_max_N": float(t.max()),
            "tension_max_link": int(t.argmax()),
            "tension_min_N": float(t.min()),
            "tension_min_link": int(t.argmin()),
            "wheel_load_N": [float(v) for v in self.wheel_load],
            "torsion_preload_Nm": [float(v) for v in self.preload],
            "ground_force_N": self.ground_force,
            "weight_N": self.weight,
            "residual_N": self.residual,
            "residual_rel": self.residual / self.weight,
        }


class _Problem:
    """Residual of the equilibrium equations in the unknowns u = (y_c, pitch, pins)."""

    def __init__(self, vehicle, track, gravity, contact=None, soil=None):
        self.par, piv, self.ends = pack(vehicle, track, gravity, contact)
        for k, v in (soil or {}).items():    # soft soil: fresh (no memory cells), every pin loading
            self.par[k] = v
        self.nw = int(vehicle["n_wheels"])
        self.n_links = int(track["n_links"])
        self.phi = equilibrium_arm_angle(vehicle)
        self.arms = arm_table(piv, np.full(self.nw, self.phi), 0.0)
        g = flat_ground()
        self.m = model_arrays(self.par, self.arms, self.ends, g.segments, g.corners, self.n_links,
                              rut=np.zeros(0) if soil else None)
        self.work = work_arrays(self.m, self.nw, self.n_links)
        self.diag = np.zeros(L.n_diag(self.nw, self.n_links))
        self.nq = L.n_coordinates(self.nw, self.n_links)
        self.weight = total_mass(vehicle, track) * gravity

    def q_of(self, u):
        q = np.zeros(self.nq)
        q[L.Q_Y] = u[0]
        q[L.Q_PITCH] = u[1]
        q[L.Q_ARM:L.Q_ARM + self.nw] = self.phi
        q[L.pin_offset(self.nw):] = u[2:]
        return q

    def _args(self):
        return self.phi, self.m, self.work, self.diag

    def residual(self, u):
        """(vertical force, moment of chassis + arms, pin forces); horizontal force; arm moments."""
        r = np.empty(u.size)
        arm_moment = np.empty(self.nw)
        fx = _residual(u, *self._args(), r, arm_moment)
        return r, fx, arm_moment

    def jacobian(self, u, h=1e-7):
        """Central finite differences of the residual (a Python loop over compiled
        residuals: 2 x 60 calls cost less than compiling the loop)."""
        args = self._args()
        rp = np.empty(u.size)
        rm = np.empty(u.size)
        am = np.empty(self.nw)
        J = np.empty((u.size, u.size))
        up = u.copy()
        for k in range(u.size):
            up[k] = u[k] + h
            _residual(up, *args, rp, am)
            up[k] = u[k] - h
            _residual(up, *args, rm, am)
            up[k] = u[k]
            J[:, k] = (rp - rm) / (2.0 * h)
        return J

    def loads(self, q):
        _loads_at_rest(q, self.m, self.work, self.diag)
        return self.work.apos, self.work.fpin, self.work.fwheel, self.work.wc


@njit(**KERNEL)
def _loads_at_rest(q, m, w, diag):
    """Pin and wheel positions, track forces (work) and diag at configuration q, at rest.
    The solver's own right-hand side computes them: one compiled copy of the contact code."""
    nq = q.shape[0]
    y = np.zeros(n_state(nq))
    for k in range(nq):  # loops, not slice assignments: see solvers/arrays.py
        y[k] = q[k]
    ydot = np.empty(n_state(nq))
    rhs(y, m, w, ydot, diag)


@njit(**KERNEL)
def _residual(u, phi, m, w, diag, r, arm_moment):
    """Force balance of every free pin, vertical force and moment of chassis + arms
    (into r), each arm's moment about its pivot (arm_moment); returns the horizontal force."""
    apos, fpin, fwheel, wc = w.apos, w.fpin, w.fwheel, w.wc
    par, arms = m.par, m.arms
    nw = arms.shape[0]
    n = apos.shape[0] - 1
    nq = n_coordinates(nw, n)
    q = np.zeros(nq)
    q[L.Q_Y] = u[0]
    q[L.Q_PITCH] = u[1]
    for i in range(nw):
        q[L.Q_ARM + i] = phi  # every arm at the same equilibrium angle
    for k in range(2, u.shape[0]):
        q[L.Q_ARM + nw + k - 2] = u[k]
    _loads_at_rest(q, m, w, diag)
    s, c = fm.sincos(u[1])
    g = par[L.P_GRAVITY]
    ma = par[L.P_ARM_MASS]
    yc = u[0]
    fy = fpin[0, 1] + fpin[n, 1] - (par[L.P_CHASSIS_MASS] + nw * ma) * g
    fx = fpin[0, 0] + fpin[n, 0]
    mom = 0.0
    for b in (0, n):
        mom += apos[b, 0] * fpin[b, 1] - (apos[b, 1] - yc) * fpin[b, 0]
    for i in range(nw):
        wfy = fwheel[i, 1] - ma * g
        fy += fwheel[i, 1]
        fx += fwheel[i, 0]
        mom += wc[i, 0] * wfy - (wc[i, 1] - yc) * fwheel[i, 0]
        px = c * arms[i, 0] - s * arms[i, 1]
        py = yc + s * arms[i, 0] + c * arms[i, 1]
        arm_moment[i] = (wc[i, 0] - px) * wfy - (wc[i, 1] - py) * fwheel[i, 0]
    r[0] = fy
    r[1] = mom
    for b in range(1, n):
        r[2 * b] = fpin[b, 0]
        r[2 * b + 1] = fpin[b, 1] - par[L.P_PIN_MASS] * g
    return fx


def _newton(P, u, target, max_iter):
    """Newton iteration with a finite-difference Jacobian and a backtracking line search;
    returns (u, residual norm, iterations)."""
    r, _, _ = P.residual(u)
    norm = np.abs(r).max()
    it = 0
    while norm > target and it < max_iter:
        it += 1
        J = P.jacobian(u)
        du = np.empty(u.size)
        if not dense.solve(J, -r, du):   # e.g. the closed loop before its pins press on the teeth
            dense.least_squares(J, -r, du)
        lam = 1.0
        while True:
            un = u + lam * du
            rn, _, _ = P.residual(un)
            nn = np.abs(rn).max()
            if nn < norm or lam < 1e-4:
                break
            lam *= 0.5
        if nn >= norm:   # no descent even for a tiny step: stuck
            break
        u, r, norm = un, rn, nn
    return u, norm, it


def _levenberg_marquardt(P, u, target, max_iter):
    """Where Newton's method stalls at a contact that opens or closes under its step:
    Levenberg-Marquardt steps on the sum of squared residuals (the damping grows until a
    step lowers it); returns (u, max residual, iterations)."""
    r, _, _ = P.residual(u)
    it = 0
    lam = 1e-3
    while np.abs(r).max() > target and it < max_iter:
        it += 1
        J = P.jacobian(u)
        A = np.empty((u.size, u.size))
        g = np.empty(u.size)
        dense.normal_equations(J, r, A, g)
        d = np.diag(A).copy() + 1e-30
        du = np.empty(u.size)
        for _ in range(30):
            if not dense.solve(A + lam * np.diag(d), -g, du):
                du[:] = 0.0
            rn, _, _ = P.residual(u + du)
            if dense.dot(rn, rn) < dense.dot(r, r):
                u, r = u + du, rn
                lam = max(lam / 5.0, 1e-9)
                break
            lam *= 4.0
        else:
            break
    return u, np.abs(r).max(), it


def _rounded(P, u, norm, it, target, max_iter):
    """Where Newton's method stalled (a contact opening under its step, soft soil's infinite
    stiffness at the surface for n < 1): Levenberg-Marquardt steps, then Newton again."""
    for _ in range(4):
        if norm <= target:
            break
        u, norm, k = _levenberg_marquardt(P, u, target, 20)
        it += k
        u, norm, k = _newton(P, u, target, max_iter)
        it += k
    return u, norm, it


def _soil_sinkage(P, pins):
    """A first guess of the sinkage into soft soil: the weight spread evenly over the pins
    of the ground run (0 on rigid ground)."""
    if P.par[L.P_SOIL] == 0.0:
        return 0.0
    return _uniform_sinkage(P, max(int(np.sum(pins[:, 1] < pins[:, 1].min() + 0.01)), 1))


def _chain(P, u, target, max_iter, exponent, stiffnesses, d, solve, step=0.05):
    """Newton's method for a power law F = k x^n (no stiffness at x = 0, where Newton's
    method starts) through a chain of laws k d^(n - m) x^m, m from 1 to n in steps of about
    `step`, each solution starting the next: d, a depth the law reaches under the weight,
    keeps the forces of every law of the chain alike. `exponent` and `stiffnesses` are the
    P_* indices of n and of the k's that share it; ``solve`` is one link's solver."""
    par = P.par
    n, k = par[exponent], [par[i] for i in stiffnesses]
    it, norm = 0, np.inf
    for m in np.linspace(1.0, n, 1 + int(math.ceil(abs(n - 1.0) / step))):
        par[exponent] = m
        for i, ki in zip(stiffnesses, k):
            par[i] = ki * fm.pow(d, n - m)
        u, norm, j = solve(P, u, target if m == n else 1e-6 * P.weight, max_iter)
        it += j
    par[exponent] = n
    for i, ki in zip(stiffnesses, k):
        par[i] = ki                        # exactly the scenario's law again
    return u, norm, it


def _continuation(P, u, target, max_iter):
    """The contact power law (n != 1) by continuation; d, a wheel's compression under an
    equal share of the weight."""
    n = P.par[L.P_CONTACT_EXPONENT]
    if n == 1.0:
        return _newton(P, u, target, max_iter)
    d = fm.pow(P.weight / (P.nw * P.par[L.P_K_WHEEL]), 1.0 / n)
    return _chain(P, u, target, max_iter, L.P_CONTACT_EXPONENT, (L.P_K_WHEEL, L.P_K_GROUND), d, _newton)


def _uniform_sinkage(P, pins_on_soil):
    """Bekker's sinkage under the weight spread evenly over that many pins' areas."""
    p = P.weight / (pins_on_soil * P.par[L.P_PIN_AREA])
    return fm.pow(p / P.par[L.P_SOIL_K], 1.0 / P.par[L.P_SOIL_N])


def _newton_rounded(P, u, target, max_iter):
    u, norm, it = _newton(P, u, target, max_iter)
    return _rounded(P, u, norm, it, target, max_iter)


def _soil_continuation(P, u, target, max_iter):
    """Soft soil with Bekker's n != 1 by continuation, each link rounded where Newton's
    method stalls; d, the sinkage under the weight spread over half the links."""
    z0 = _uniform_sinkage(P, max(int(P.n_links) // 2, 1))
    return _chain(P, u, target, max_iter, L.P_SOIL_N, (L.P_SOIL_K,), z0, _newton_rounded)


def _solve(P, u, max_iter, tol_rel, failure, check):
    """Newton's method (by continuation for a power law or Bekker's soil), rounded where it
    stalls; the solution and the iteration count, or EquilibriumError above 1e-6 of the weight."""
    target = tol_rel * P.weight
    if P.par[L.P_SOIL] != 0.0 and P.par[L.P_SOIL_N] != 1.0:
        u, norm, it = _soil_continuation(P, u, target, max_iter)
    else:
        u, norm, it = _continuation(P, u, target, max_iter)
    u, norm, it = _rounded(P, u, norm, it, target, max_iter)
    if not np.isfinite(norm) or norm > 1e-6 * P.weight:
        on = max(int(np.count_nonzero(P.work.sink > 0.0)), 1)
        if P.par[L.P_SOIL] != 0.0 and _uniform_sinkage(P, on) > P.par[L.P_PAD_GROUND]:   # a soil too soft
            check = (f"the soil: spread evenly over the {on} pins on it, the weight sinks the track "
                     f"{_uniform_sinkage(P, on):.3g} m (Bekker); a wider track.width or a firmer soil sinks less")
        raise EquilibriumError(f"{failure}: force residual {norm:.3g} N after {it} Newton iterations (needs < "
                               f"{1e-6 * P.weight:.3g} N); check {check}")
    return u, it


def _balance(P, u):
    """At the solution: residuals, coordinates, the torsion bars' free angles and preloads
    (the torsion torque -k_t (phi - phi0) balances each arm's moment about its pivot), pins,
    wheel loads, wheel centres and link tensions."""
    r, fx, arm_moment = P.residual(u)
    q = P.q_of(u)
    preload = -arm_moment
    phi0 = q[L.Q_ARM:L.Q_ARM + P.nw] + preload / P.par[L.P_TORSION_STIFFNESS]
    apos, fpin, fwheel, wc = P.loads(q)
    tension = P.diag[L.diag_tension(P.nw):L.diag_tension(P.nw) + P.n_links].copy()
    return r, fx, arm_moment, q, phi0, preload, apos, fwheel, wc, tension


def solve_equilibrium(vehicle, track, gravity, contact=None, soil=None, tol_rel=1e-12, max_iter=60):
    """Newton's method from the wheels resting on the track and the track on the ground
    (soil: {P_* index: value} of soft soil, assembly.soil_par). A power law is reached by
    continuation (_continuation)."""
    P = _Problem(vehicle, track, gravity, contact, soil)
    rho = P.par[L.P_WHEEL_RADIUS] + P.par[L.P_PAD_WHEEL]
    hg = P.par[L.P_PAD_GROUND]
    # start: wheels resting on the track, the track on the ground, chassis level
    wcb = P.arms[:, [L.ARMS_PX, L.ARMS_PY]] + P.par[L.P_ARM_LENGTH] * np.array([fm.vcos(P.phi), fm.vsin(P.phi)])
    yc = -wcb[:, 1].min() + rho + hg
    ends_w = P.ends + [0.0, yc]
    pins, _, _ = initial_track(ends_w, wcb + [0.0, yc], rho, P.n_links)
    u = np.concatenate([[yc, 0.0], pins[1:-1].ravel()])
    u[0] -= _soil_sinkage(P, pins)
    u[3::2] -= _soil_sinkage(P, pins)
    u, it = _solve(P, u, max_iter, tol_rel, "static equilibrium not found", "the vehicle and track geometry")
    r, fx, arm_moment, q, phi0, preload, apos, fwheel, wc, tension = _balance(P, u)
    return Equilibrium(
        q=q, phi0=phi0, preload=preload, wheel_load=fwheel[:, 1].copy(), tension=tension,
        ground_force=float(P.diag[L.D_GROUND_FY]), weight=P.weight,
        residual=float(max(np.abs(r).max(), abs(fx))), iterations=it,
        info={"pins": apos.copy(), "wheel_centres": wc.copy()})


# --- the closed layout ---------------------------------------------------------------


class _LoopProblem(_Problem):
    """The closed layout at rest: unknowns u = (y_c, pitch, idler slide, sprocket angle,
    every pin), the arms at the equilibrium angle, the sprocket held by the drive at the
    angle that seats the pins (where a free sprocket's teeth torque would vanish, Newton's
    method does not find reliably: the loop's cogging energy is not smooth)."""

    def __init__(self, vehicle, track, gravity, contact, geometry, loop, guides, soil=None):
        from .closed import loop_pins
        self.par, piv, self.ends = pack(vehicle, track, gravity, contact)
        for k, v in (soil or {}).items():
            self.par[k] = v
        self.nw = int(vehicle["n_wheels"])
        self.n_links = geometry.n_links
        self.phi = equilibrium_arm_angle(vehicle)
        self.arms = arm_table(piv, np.full(self.nw, self.phi), 0.0)
        g = flat_ground()
        self.m = model_arrays(self.par, self.arms, self.ends, g.segments, g.corners, self.n_links, loop, guides,
                              np.zeros(0) if soil else None)
        self.work = work_arrays(self.m, self.nw, self.n_links)
        self.diag = np.zeros(L.n_diag(self.nw, self.n_links))
        self.nq = L.n_coordinates(self.nw, self.n_links, closed=True)
        self.pins, self.psi = loop_pins(geometry)
        self.slide0 = geometry.slide
        self.weight = (total_mass(vehicle, track) + track["pin_mass"] + loop[L.LP_IDLER_MASS]) * gravity

    def q_of(self, u):
        q = np.zeros(self.nq)
        q[L.Q_Y] = u[0]
        q[L.Q_PITCH] = u[1]
        q[L.Q_ARM:L.Q_ARM + self.nw] = self.phi
        q[L.q_idler(self.nw, self.n_links)] = u[2]
        q[L.q_sprocket(self.nw, self.n_links)] = u[3]
        q[L.pin_offset(self.nw):L.pin_offset(self.nw) + 2 * self.n_links] = u[4:]
        return q

    def _args(self):
        return self.phi, self.psi, self.m, self.work, self.diag

    def residual(self, u):
        r = np.empty(u.size)
        arm_moment = np.empty(self.nw)
        fx = _loop_residual(u, *self._args(), r, arm_moment)
        return r, fx, arm_moment

    def jacobian(self, u, h=1e-7):
        J = np.empty((u.size, u.size))
        _loop_jacobian(u, h, *self._args(), J)
        return J


@njit(**KERNEL)
def _loop_jacobian(u, h, phi, psi, m, w, diag, J):
    """Central finite differences of _loop_residual (compiled: ~270 residuals a step)."""
    n = u.shape[0]
    rp = np.empty(n)
    rm = np.empty(n)
    am = np.empty(m.arms.shape[0])
    up = u.copy()
    for k in range(n):
        up[k] = u[k] + h
        _loop_residual(up, phi, psi, m, w, diag, rp, am)
        up[k] = u[k] - h
        _loop_residual(up, phi, psi, m, w, diag, rm, am)
        up[k] = u[k]
        for i in range(n):
            v = (rp[i] - rm[i]) / (2.0 * h)
            J[i, k] = v if abs(v) > 1e-200 else 0.0   # no subnormals: LAPACK slows down 50x on them


@njit(**KERNEL)
def _loop_residual(u, phi, psi, m, w, diag, r, arm_moment):
    """The closed layout's generalised forces at rest (loop.loop_rhs fills w.genf) on the
    unknowns into r (on the sprocket angle: its change, which holds it), each arm's moment
    about its pivot; returns the horizontal force."""
    nw = m.arms.shape[0]
    n = w.apos.shape[0] - 1
    nq = w.genf.shape[0]
    y = np.zeros(n_state(nq))
    y[L.Q_Y] = u[0]
    y[L.Q_PITCH] = u[1]
    for i in range(nw):
        y[L.Q_ARM + i] = phi
    y[q_idler(nw, n)] = u[2]
    y[q_sprocket(nw, n)] = u[3]
    off = pin_offset(nw)
    for k in range(2 * n):
        y[off + k] = u[4 + k]
    ydot = np.empty(y.shape[0])
    loop_rhs(y, m, w, ydot, diag)
    r[0] = w.genf[L.Q_Y]
    r[1] = w.genf[L.Q_PITCH]
    r[2] = w.genf[q_idler(nw, n)]
    r[3] = u[3] - psi     # held by the drive
    for k in range(2 * n):
        r[4 + k] = w.genf[off + k]
    for i in range(nw):
        arm_moment[i] = w.genf[L.Q_ARM + i]
    return w.genf[L.Q_X]


def solve_loop_equilibrium(vehicle, track, gravity, contact, geometry, loop, guides, soil=None, tol_rel=1e-12,
                           max_iter=60):
    """Static equilibrium of the closed layout on flat ground: Newton's method from the
    taut loop (model/closed.py) resting on the ground, the sprocket held."""
    P = _LoopProblem(vehicle, track, gravity, contact, geometry, loop, guides, soil)
    yc = -P.pins[:, 1].min() + P.par[L.P_PAD_GROUND] - _soil_sinkage(P, P.pins)   # lowest pins on the ground
    u = np.concatenate([[yc, 0.0, P.slide0, P.psi], (P.pins + [0.0, yc]).ravel()])
    u, it = _solve(P, u, max_iter, tol_rel, "static equilibrium of the closed track not found",
                   "the sprocket, idler and track values")
    r, fx, arm_moment, q, phi0, preload, apos, fwheel, wc, tension = _balance(P, u)
    w = P.work
    return Equilibrium(
        q=q, phi0=phi0, preload=preload, wheel_load=fwheel[:, 1].copy(), tension=tension,
        ground_force=float(P.diag[L.D_GROUND_FY]), weight=P.weight,
        residual=float(max(np.abs(r).max(), abs(fx))), iterations=it,
        info={"pins": apos[1:].copy(), "wheel_centres": wc.copy(), "idler_slide": float(u[2]),
              "idler_force": float(P.diag[L.D_IDLER_FORCE]), "holding_torque": float(w.spr[L.SP_TORQUE]),   # forward drive torque that holds the sprocket
              "guide_forces": w.fguide.copy()})
