"""The static equilibrium's equations on flat ground (docs/model.md, "Initial equilibrium"):
the residual of the force balance and its Jacobian, for either track layout; the numerical
methods are solvers/equilibrium/.

Every arm is held at the equilibrium arm angle; unknowns are the chassis height and
pitch and the free pins. The torsion-bar free angles phi0_i (the preloads) follow from
each arm's moment balance about its pivot, so they are eliminated from the Newton
iteration and computed afterwards.

Where the vehicle gives the free angles (vehicle.torsion_free_angle) the arm angles are
Newton unknowns as well, after the others, and each arm's moment balance (torsion bar and
bump stops included) an equation. Why not a fixed-point iteration (rest angle <- free angle
+ arm moment / k_t around the held solve): with the arms held, a wheel's load follows its
angle through the pads' stiffness (about 1e8 N/m, a moment of ~1e7 N m/rad at the pivot),
hundreds of times the torsion bar's k_t, so that iteration diverges; Newton's method takes
the coupling from its Jacobian.
"""


import numpy as np
from numba import njit

from ..core import fixed_math as fm
from ..core import indices as L
from ..core.bundles import arm_table, model_arrays, work_arrays
from ..core.indices_jit import n_coordinates, pin_offset, q_idler, q_sprocket
from ..core.jit import KERNEL
from ..ground.terrain import flat_ground
from ..vehicle.parameters import equilibrium_arm_angle, free_angle, pack, station_columns, total_mass
from .closed_track_jit import closed_rhs
from .reduced import stop_excess
from .rhs import rhs


def _arms_at_rest(problem, vehicle, track, piv):
    """The problem's arm angles (held, or the free arms' first guess), whether the arms are
    free, and its arm table: the torsion bars' free angles where the vehicle gives them, else
    the held angles (no torsion torque: the preloads follow from the balance)."""
    problem.phi = equilibrium_arm_angle(vehicle)   # one per arm
    phi0 = free_angle(vehicle)
    problem.free = phi0 is not None
    problem.arms = arm_table(piv, phi0 if problem.free else problem.phi, 0.0, station_columns(vehicle, track))


class StaticProblem:
    """Residual of the equilibrium equations in the unknowns u = (y_c, pitch, pins), and
    the arm angles where they are free (self.free)."""

    def __init__(self, vehicle, track, gravity, contact=None, soil=None):
        self.par, piv, self.ends = pack(vehicle, track, gravity, contact)
        for k, v in (soil or {}).items():    # soft soil: fresh (no memory cells), every pin loading
            self.par[k] = v
        self.nw = int(vehicle["n_wheels"])
        self.n_links = int(track["n_links"])
        _arms_at_rest(self, vehicle, track, piv)
        g = flat_ground()
        self.m = model_arrays(self.par, self.arms, self.ends, g.segments, g.corners, self.n_links,
                              rut=np.zeros(0) if soil else None)
        self.work = work_arrays(self.m, self.nw, self.n_links)
        self.diag = np.zeros(L.n_diag(self.nw, self.n_links))
        self.nq = L.n_coordinates(self.nw, self.n_links)
        self.weight = total_mass(vehicle, track) * gravity

    def arm_angles(self, u):
        """The arms' angles at u: the free arms' unknowns (u's last nw), or the held angles."""
        return u[u.size - self.nw:] if self.free else self.phi

    def with_arms(self, u):
        """u with the free arms' unknowns appended at their first guess (else u itself)."""
        return np.concatenate([u, self.phi]) if self.free else u

    def q_of(self, u):
        q = np.zeros(self.nq)
        q[L.Q_Y] = u[0]
        q[L.Q_PITCH] = u[1]
        q[L.Q_ARM:L.Q_ARM + self.nw] = self.arm_angles(u)
        q[L.pin_offset(self.nw):] = u[2:u.size - self.nw * self.free]
        return q

    def _args(self):
        return self.phi, self.m, self.work, self.diag, self.free

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
    The solver's own right-hand side computes them: one compiled copy of the contact code
    (with the bristle law, every bristle at rest: z = 0)."""
    nq = q.shape[0]
    y = np.zeros(m.pins[L.PN_NY])
    for k in range(nq):  # loops, not slice assignments: see solvers/common/arrays.py
        y[k] = q[k]
    ydot = np.empty(m.pins[L.PN_NY])
    rhs(y, m, w, ydot, diag)


@njit(**KERNEL)
def _arms_mass(arms):
    """Every arm's mass: n m_a where they are all alike (the paper's sum, to the last bit)."""
    nw = arms.shape[0]
    alike = True
    for i in range(1, nw):
        alike = alike and arms[i, L.ARMS_MASS] == arms[0, L.ARMS_MASS]
    if alike:
        return nw * arms[0, L.ARMS_MASS]
    total = 0.0
    for i in range(nw):
        total += arms[i, L.ARMS_MASS]
    return total


@njit(**KERNEL)
def _residual(u, phi, m, w, diag, free, r, arm_moment):
    """Force balance of every free pin, vertical force and moment of chassis + arms
    (into r), each arm's moment about its pivot (arm_moment: the loads', torsion bar and
    stops left out); free arms: their angles u's last nw, their balance r's last nw. Returns
    the horizontal force."""
    apos, fpin, fwheel, wc = w.apos, w.fpin, w.fwheel, w.wc
    par, arms = m.par, m.arms
    nw = arms.shape[0]
    n = apos.shape[0] - 1
    nq = n_coordinates(nw, n)
    n_free = nw if free else 0
    q = np.zeros(nq)
    q[L.Q_Y] = u[0]
    q[L.Q_PITCH] = u[1]
    for i in range(nw):
        if free:
            q[L.Q_ARM + i] = u[u.shape[0] - nw + i]
        else:
            q[L.Q_ARM + i] = phi[i]  # every arm at its equilibrium angle
    for k in range(2, u.shape[0] - n_free):
        q[L.Q_ARM + nw + k - 2] = u[k]
    _loads_at_rest(q, m, w, diag)
    s, c = fm.sincos(u[1])
    g = par[L.P_GRAVITY]
    yc = u[0]
    fy = fpin[0, 1] + fpin[n, 1] - (par[L.P_CHASSIS_MASS] + _arms_mass(arms)) * g
    fx = fpin[0, 0] + fpin[n, 0]
    mom = 0.0
    for b in (0, n):
        mom += apos[b, 0] * fpin[b, 1] - (apos[b, 1] - yc) * fpin[b, 0]
    for i in range(nw):
        wfy = fwheel[i, 1] - arms[i, L.ARMS_MASS] * g
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
    for i in range(n_free):   # the free arms' balance: loads, torsion bar, bump stops
        a = q[L.Q_ARM + i]
        tq = arm_moment[i] - arms[i, L.ARMS_STIFFNESS] * (a - arms[i, L.ARMS_PHI0])
        if arms[i, L.ARMS_STOP_K] != 0.0:
            tq -= arms[i, L.ARMS_STOP_K] * stop_excess(a, arms[i, L.ARMS_JOUNCE], arms[i, L.ARMS_REBOUND])
        r[u.shape[0] - nw + i] = tq
    return fx


# --- the closed layout ---------------------------------------------------------------


class ClosedStaticProblem(StaticProblem):
    """The closed layout at rest: unknowns u = (y_c, pitch, idler slide, sprocket angle,
    every pin), the arms at the equilibrium angle, the sprocket held by the drive at the
    angle that seats the pins (where a free sprocket's teeth torque would vanish, Newton's
    method does not find reliably: the loop's cogging energy is not smooth)."""

    def __init__(self, vehicle, track, gravity, contact, geometry, loop, guides, soil=None):
        from ..vehicle.closed_track import closed_pins
        self.par, piv, self.ends = pack(vehicle, track, gravity, contact)
        for k, v in (soil or {}).items():
            self.par[k] = v
        self.nw = int(vehicle["n_wheels"])
        self.n_links = geometry.n_links
        _arms_at_rest(self, vehicle, track, piv)
        g = flat_ground()
        self.m = model_arrays(
            self.par,
            self.arms,
            self.ends,
            g.segments,
            g.corners,
            self.n_links,
            loop,
            guides,
            np.zeros(0) if soil else None,
        )
        self.work = work_arrays(self.m, self.nw, self.n_links)
        self.diag = np.zeros(L.n_diag(self.nw, self.n_links))
        self.nq = L.n_coordinates(self.nw, self.n_links, closed=True)
        self.pins, self.psi = closed_pins(geometry)
        self.slide0 = geometry.slide
        self.weight = (total_mass(vehicle, track) + track["pin_mass"] + loop[L.LP_IDLER_MASS]) * gravity

    def q_of(self, u):
        q = np.zeros(self.nq)
        q[L.Q_Y] = u[0]
        q[L.Q_PITCH] = u[1]
        q[L.Q_ARM:L.Q_ARM + self.nw] = self.arm_angles(u)
        q[L.q_idler(self.nw, self.n_links)] = u[2]
        q[L.q_sprocket(self.nw, self.n_links)] = u[3]
        q[L.pin_offset(self.nw):L.pin_offset(self.nw) + 2 * self.n_links] = u[4:4 + 2 * self.n_links]
        return q

    def _args(self):
        return self.phi, self.psi, self.m, self.work, self.diag, self.free

    def residual(self, u):
        r = np.empty(u.size)
        arm_moment = np.empty(self.nw)
        fx = _closed_residual(u, *self._args(), r, arm_moment)
        return r, fx, arm_moment

    def jacobian(self, u, h=1e-7):
        J = np.empty((u.size, u.size))
        _closed_jacobian(u, h, *self._args(), J)
        return J


@njit(**KERNEL)
def _closed_jacobian(u, h, phi, psi, m, w, diag, free, J):
    """Central finite differences of _closed_residual (compiled: ~270 residuals a step)."""
    n = u.shape[0]
    rp = np.empty(n)
    rm = np.empty(n)
    am = np.empty(m.arms.shape[0])
    up = u.copy()
    for k in range(n):
        up[k] = u[k] + h
        _closed_residual(up, phi, psi, m, w, diag, free, rp, am)
        up[k] = u[k] - h
        _closed_residual(up, phi, psi, m, w, diag, free, rm, am)
        up[k] = u[k]
        for i in range(n):
            v = (rp[i] - rm[i]) / (2.0 * h)
            J[i, k] = v if abs(v) > 1e-200 else 0.0   # no subnormals: LAPACK slows down 50x on them


@njit(**KERNEL)
def _closed_residual(u, phi, psi, m, w, diag, free, r, arm_moment):
    """The closed layout's generalised forces at rest (closed_track_jit.closed_rhs fills w.genf) on the
    unknowns into r (on the sprocket angle: its change, which holds it), each arm's moment
    about its pivot (held arms: the loads'; free arms, u's and r's last nw: the balance, torsion
    bar and stops included); returns the horizontal force."""
    nw = m.arms.shape[0]
    n = w.apos.shape[0] - 1
    y = np.zeros(m.pins[L.PN_NY])   # at rest: every bristle's deflection 0
    y[L.Q_Y] = u[0]
    y[L.Q_PITCH] = u[1]
    for i in range(nw):
        if free:
            y[L.Q_ARM + i] = u[4 + 2 * n + i]
        else:
            y[L.Q_ARM + i] = phi[i]
    y[q_idler(nw, n)] = u[2]
    y[q_sprocket(nw, n)] = u[3]
    off = pin_offset(nw)
    for k in range(2 * n):
        y[off + k] = u[4 + k]
    ydot = np.empty(y.shape[0])
    closed_rhs(y, m, w, ydot, diag)
    r[0] = w.genf[L.Q_Y]
    r[1] = w.genf[L.Q_PITCH]
    r[2] = w.genf[q_idler(nw, n)]
    r[3] = u[3] - psi     # held by the drive
    for k in range(2 * n):
        r[4 + k] = w.genf[off + k]
    for i in range(nw):
        arm_moment[i] = w.genf[L.Q_ARM + i]
        if free:
            r[4 + 2 * n + i] = w.genf[L.Q_ARM + i]
    return w.genf[L.Q_X]


