"""The closed layout's equations of motion: one loop of links around the drive sprocket,
the road wheels, the idler and the support rollers (docs/model.md, "Beyond the paper: the
closed, driven track").

Coordinates (model/core/indices.py): the chassis, the arms, every pin (rows 1..n_links; row 0 of the
pin arrays copies row n_links), the sprocket angle psi relative to the chassis and the
idler carrier's slide s along its guide. The sprocket turns about a chassis-fixed axis
(its mass is part of the chassis'; its inertia I_s adds the kinetic energy
I_s (omega + psi')^2 / 2); the idler (wheel + carrier, mass m_i) is a point mass at
c + R(theta)(g0 + s u); the rollers turn on chassis-fixed axes (their masses are part of
the chassis'). Like an arm, the sprocket and the idler each add one row to the mass matrix
that couples with the chassis alone, so the chassis block is solved by the same Schur
complement as the paper's (model/dynamics/reduced.py).

The drive's torque acts between chassis and sprocket, the tensioner's force between
chassis and carrier: each does work on its own coordinate only. Their power, the power of
the pin-tooth contacts and of every contact of the paper's kernels go into dW/dt, so the
work-based energy residual stays a check of the integration.
"""

import numpy as np
from numba import njit

from ...status import GROUND_CANDIDATES, IDLER_OFF_GUIDE, PIN_THROUGH_SPROCKET
from ..contact.laws import DAMPING_NONE, DAMPING_VISCOUS, GEOMETRY_CONTINUOUS
from ..contact.laws_jit import normal_force
from ..contact.neighbours import refresh_neighbours
from ..contact.track_contacts import contact_law, round_on_track, wheel_contacts
from ..core.bundles import ARM_BT, ARM_BX, ARM_BY, ARM_COLS, ARM_D, ARM_Q, LOOP_IDLER, LOOP_SPROCKET
from ..core.indices import (
    C_EVALUATIONS,
    C_OVERFLOW,
    D_DISSIPATION,
    D_DRAWBAR,
    D_DRIVE_TORQUE,
    D_E_PAD_WHEEL,
    D_IDLER_FORCE,
    D_POWER,
    D_STATUS,
    D_TEETH_TORQUE,
    G_BX,
    G_BY,
    G_REACH,
    K_GUIDE_LINK,
    K_GUIDE_PIN,
    LP_GUIDE_X,
    LP_GUIDE_Y,
    LP_IDLER_MASS,
    LP_PRELOAD,
    LP_SPROCKET_INERTIA,
    LP_SPROCKET_X,
    LP_SPROCKET_Y,
    LP_TENSIONER_DAMPING,
    LP_TENSIONER_STIFFNESS,
    LP_TOOTH_DAMPING,
    LP_TOOTH_STIFFNESS,
    LP_TRAVEL,
    P_C_WHEEL,
    P_CHASSIS_MASS,
    P_CONTACT_EXPONENT,
    P_CONTACT_GEOMETRY,
    P_CONTACT_LAW,
    P_DAMPING_RAMP,
    P_GRAVITY,
    P_MIN_APPROACH,
    P_PIN_MASS,
    PN_LAST,
    PN_NQ,
    Q_ARM,
    Q_PITCH,
    Q_X,
    Q_Y,
    SP_ANGLE,
    SP_FX,
    SP_FY,
    SP_RATE,
    SP_TORQUE,
    SP_VX,
    SP_VY,
    SP_X,
    SP_Y,
    Y_DISSIPATED,
    Y_DRIVE_INTEGRAL,
    Y_DRIVE_WORK,
    Y_WORK,
)
from ..core.indices_jit import diag_tension, q_idler, q_pin, q_sprocket
from ..core.jit import BORROW, INLINE, KERNEL
from ..ground.grip import bristle_rates, start_bristles, uses_bristle
from ..ground.ground_contact import ground_contacts
from ..vehicle.drive import drawbar_on_chassis, drive_torque, has_drawbar, held_speed
from ..vehicle.kinematics import body_offset, place_wheels, wheel_velocities
from ..vehicle.links import link_tensions
from ..vehicle.teeth_jit import pin_on_teeth, stored_shape
from .reduced import (
    chassis_acceleration,
    chassis_and_arms,
    pin_accelerations,
    row_acceleration,
    start_rates,
    store_state_energies,
    take_out_rows,
)


@njit(**INLINE)
def _closed_pins(coords, nw, out):
    """Rows 1..n_links from the pin coordinates (or rates), row 0 = row n_links."""
    n = out.shape[0] - 1
    for b in range(1, n + 1):
        k = q_pin(nw, b)
        out[b, 0] = coords[k]
        out[b, 1] = coords[k + 1]
    out[0, 0] = out[n, 0]
    out[0, 1] = out[n, 1]


@njit(**INLINE)
def idler_offset(sl, lp, guides, c, s):
    """The idler centre at slide sl relative to the chassis mass centre, and R u (the guide
    in the world)."""
    ux, uy = body_offset(c, s, lp[LP_GUIDE_X], lp[LP_GUIDE_Y])
    rx, ry = body_offset(c, s, guides[0, G_BX], guides[0, G_BY])
    return rx + sl * ux, ry + sl * uy, ux, uy


@njit(**INLINE)
def guide_offset(j, sl, m, c, s):
    """Centre of guide j (0 the idler at slide sl, then the rollers) relative to the chassis
    mass centre, and the idler's guide direction in the world (0 for a roller)."""
    if j == 0:
        return idler_offset(sl, m.loop, m.guides, c, s)
    rx, ry = body_offset(c, s, m.guides[j, G_BX], m.guides[j, G_BY])
    return rx, ry, 0.0, 0.0


@njit(**INLINE)
def place_closed(q, m, apos, wc, arm, gc):
    """Pins, road wheels, idler and rollers of configuration q (closed layout). Returns the
    pitch's (cos, sin)."""
    nw = m.arms.shape[0]
    n = apos.shape[0] - 1
    c, s = place_wheels(q, m.par, m.arms, wc, arm)
    _closed_pins(q, nw, apos)
    sl = q[q_idler(nw, n)]
    for j in range(gc.shape[0]):
        rx, ry, _, _ = guide_offset(j, sl, m, c, s)
        gc[j, 0] = q[Q_X] + rx
        gc[j, 1] = q[Q_Y] + ry
    return c, s


@njit(**INLINE)
def _closed_positions(q, qd, m, w):
    """Pins, wheels, idler and rollers with their velocities (each guide placed once), and
    the sprocket's axis and angle (w.spr)."""
    nw = m.arms.shape[0]
    n = w.apos.shape[0] - 1
    c, s = place_wheels(q, m.par, m.arms, w.wc, w.arm)
    _closed_pins(q, nw, w.apos)
    wheel_velocities(qd, m.par, m.arms, w.wv, w.arm, c, s)
    _closed_pins(qd, nw, w.avel)
    om = qd[Q_PITCH]
    sl = q[q_idler(nw, n)]
    sd = qd[q_idler(nw, n)]
    for j in range(w.gc.shape[0]):
        rx, ry, ux, uy = guide_offset(j, sl, m, c, s)    # (ux, uy) = 0 for a roller
        w.gc[j, 0] = q[Q_X] + rx
        w.gc[j, 1] = q[Q_Y] + ry
        w.gv[j, 0] = qd[Q_X] - om * ry + sd * ux
        w.gv[j, 1] = qd[Q_Y] + om * rx + sd * uy
    rx, ry = body_offset(c, s, m.loop[LP_SPROCKET_X], m.loop[LP_SPROCKET_Y])
    spr = w.spr
    spr[SP_X] = q[Q_X] + rx
    spr[SP_Y] = q[Q_Y] + ry
    spr[SP_VX] = qd[Q_X] - om * ry
    spr[SP_VY] = qd[Q_Y] + om * rx
    spr[SP_ANGLE] = q[Q_PITCH] + q[q_sprocket(nw, n)]
    spr[SP_RATE] = om + qd[q_sprocket(nw, n)]
    return c, s


@njit(**INLINE)
def _guide_contacts(w, m, diag, mem):
    """The idler and the rollers against the track from inside, frictionless, as the road
    wheels (track_contacts.round_on_track, the same law); their forces into w.fguide."""
    par = m.par
    law = contact_law(par, P_C_WHEEL)
    continuous = par[P_CONTACT_GEOMETRY] == GEOMETRY_CONTINUOUS
    acc = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    for j in range(w.gc.shape[0]):
        probe = (w.gc[j, 0], w.gc[j, 1], w.gv[j, 0], w.gv[j, 1])
        rows = (m.nbr_rows[K_GUIDE_LINK] + j, m.nbr_rows[K_GUIDE_PIN] + j)
        acc = round_on_track(probe, m.guides[j, G_REACH], rows, w, m, law, continuous, mem, diag, acc)
        w.fguide[j, 0] = -acc[0]
        w.fguide[j, 1] = -acc[1]
    diag[D_E_PAD_WHEEL] += acc[3]
    diag[D_POWER] += acc[4]
    diag[D_DISSIPATION] += acc[6]


@njit(**INLINE)
def _teeth(w, m, diag):
    """Every pin against the sprocket's tooth profile (model/vehicle/teeth_jit.py): the force on the
    pin pushes it out of the profile, the sprocket takes the opposite force through the
    pin's centre (into w.spr: force and torque about the axis)."""
    par, lp, spr, apos, avel, fpin = m.par, m.loop, w.spr, w.apos, w.avel, w.fpin
    c = lp[LP_TOOTH_DAMPING]
    law = (int(par[P_CONTACT_LAW]), DAMPING_VISCOUS if c > 0.0 else DAMPING_NONE, lp[LP_TOOTH_STIFFNESS],
           par[P_CONTACT_EXPONENT], c, 0.0, par[P_DAMPING_RAMP])
    om = spr[SP_RATE]
    shape = stored_shape(lp)
    fx = fy = torque = energy = power = dissipation = 0.0
    for b in range(1, apos.shape[0]):
        dx = apos[b, 0] - spr[SP_X]
        dy = apos[b, 1] - spr[SP_Y]
        pen, nx, ny, inside = pin_on_teeth(dx, dy, spr[SP_ANGLE], shape)
        if inside:
            diag[D_STATUS] = PIN_THROUGH_SPROCKET
            continue
        if pen <= 0.0:
            continue
        ux = avel[b, 0] - (spr[SP_VX] - om * dy)     # the pin relative to the tooth under it
        uy = avel[b, 1] - (spr[SP_VY] + om * dx)
        p, e, pd = normal_force(law, pen, -(ux * nx + uy * ny), 1.0)
        fpin[b, 0] += p * nx
        fpin[b, 1] += p * ny
        fx -= p * nx
        fy -= p * ny
        torque -= dx * p * ny - dy * p * nx
        energy += e
        dissipation += pd
        power += p * (nx * ux + ny * uy)
    spr[SP_FX] = fx
    spr[SP_FY] = fy
    spr[SP_TORQUE] = torque
    diag[D_E_PAD_WHEEL] += energy
    diag[D_POWER] += power
    diag[D_DISSIPATION] += dissipation


@njit(**INLINE)
def closed_loads(w, m, diag):
    """track_loads.track_loads for the closed layout: tension, road wheels, idler and rollers,
    ground, sprocket teeth; the forces on row 0 (the copy of pin n_links) moved to it."""
    par = m.par
    mem = (m.v0, w.pair_seen, w.pair_rate, m.counters, par[P_MIN_APPROACH])
    diag[D_STATUS] = 0.0
    diag[D_POWER] = 0.0
    diag[D_DISSIPATION] = 0.0
    m.counters[C_EVALUATIONS] += 1
    refresh_neighbours(w.apos, w.wc, w.gc, m)
    if m.counters[C_OVERFLOW]:   # a pin's candidate row overflowed: its contacts are incomplete
        diag[D_STATUS] = GROUND_CANDIDATES
    link_tensions(w.apos, w.avel, par, w.lk, w.fpin, diag, diag_tension(w.wc.shape[0]))
    wheel_contacts(w, m, diag, mem)
    _guide_contacts(w, m, diag, mem)
    ground_contacts(w, m, diag, mem)
    _teeth(w, m, diag)
    n = w.apos.shape[0] - 1
    for k in range(2):
        w.fpin[n, k] += w.fpin[0, k]
        w.fpin[0, k] = 0.0


@njit(**INLINE)
def _chassis_own(q, m, w):
    """Generalised force on (x, y, pitch) of what acts on the chassis itself: its weight,
    the pins on the sprocket (at its axis, and their torque about it) and the track on the
    rollers."""
    spr, gc, fg = w.spr, w.gc, w.fguide
    qx = spr[SP_FX]
    qy = spr[SP_FY] - m.par[P_CHASSIS_MASS] * m.par[P_GRAVITY]
    qt = (spr[SP_X] - q[Q_X]) * spr[SP_FY] - (spr[SP_Y] - q[Q_Y]) * spr[SP_FX] + spr[SP_TORQUE]
    for j in range(1, gc.shape[0]):
        qx += fg[j, 0]
        qy += fg[j, 1]
        qt += (gc[j, 0] - q[Q_X]) * fg[j, 1] - (gc[j, 1] - q[Q_Y]) * fg[j, 0]
    return qx, qy, qt


@njit(**INLINE)
def _row(extra, r, bx, by, bt, d, gq):
    extra[r, ARM_BX] = bx
    extra[r, ARM_BY] = by
    extra[r, ARM_BT] = bt
    extra[r, ARM_D] = d
    extra[r, ARM_Q] = gq


@njit(**INLINE)
def _idler(q, qd, m, w, c, s, force):
    """The idler's row of the mass matrix into w.extra (force: the tensioner's, along the
    guide) and what it adds to the chassis block and force: (dA, df, kinetic, gravity)."""
    nw = m.arms.shape[0]
    n = w.apos.shape[0] - 1
    mi = m.loop[LP_IDLER_MASS]
    g = m.par[P_GRAVITY]
    rx = w.gc[0, 0] - q[Q_X]           # placed by _closed_positions
    ry = w.gc[0, 1] - q[Q_Y]
    ux, uy = body_offset(c, s, m.loop[LP_GUIDE_X], m.loop[LP_GUIDE_Y])
    om = qd[Q_PITCH]
    sd = qd[q_idler(nw, n)]
    # velocity-dependent acceleration of the idler centre: centripetal and Coriolis
    bx = -om * om * rx - 2.0 * om * sd * uy
    by = -om * om * ry + 2.0 * om * sd * ux
    fx = w.fguide[0, 0] - mi * bx
    fy = w.fguide[0, 1] - mi * g - mi * by
    _row(w.extra, LOOP_IDLER, mi * ux, mi * uy, mi * (-ry * ux + rx * uy), mi, ux * fx + uy * fy + force)
    da = (mi, 0.0, -mi * ry, mi, mi * rx, mi * (rx * rx + ry * ry))
    df = (fx, fy, -ry * fx + rx * fy)
    kinetic = 0.5 * mi * (w.gv[0, 0] ** 2 + w.gv[0, 1] ** 2)
    return da, df, kinetic, mi * g * w.gc[0, 1]


@njit(**INLINE)
def _forces_at_rest(f, w, nw, n, genf):
    """The generalised forces (no inertia terms at rest) for the static equilibrium."""
    genf[Q_X], genf[Q_Y], genf[Q_PITCH] = f
    for i in range(nw):
        genf[Q_ARM + i] = w.arm[i, ARM_Q]
    genf[q_sprocket(nw, n)] = w.extra[LOOP_SPROCKET, ARM_Q]
    genf[q_idler(nw, n)] = w.extra[LOOP_IDLER, ARM_Q]


@njit(**BORROW)
def closed_rhs(y, m, w, ydot, diag):
    """ydot = f(y) for the closed layout (reduced.reduced_rhs for the paper's); fills diag
    and w.genf (where it has room: the equilibrium's Work)."""
    par, arms, lp = m.par, m.arms, m.loop
    nq = m.pins[PN_NQ]
    q = y[:nq]
    qd = y[nq:2 * nq]
    nw = arms.shape[0]
    n = w.apos.shape[0] - 1
    i_spr = q_sprocket(nw, n)
    i_idl = q_idler(nw, n)
    c, s = _closed_positions(q, qd, m, w)
    bristles = uses_bristle(par)
    if bristles:
        start_bristles(y, nq, m.pins[PN_LAST], par, w.grip)
    closed_loads(w, m, diag)
    if bristles:
        bristle_rates(ydot, nq, m.pins[PN_LAST], par, w.grip, diag)
    # the drive (forward = clockwise, psi counter-clockwise) and the tensioner
    omega = -qd[i_spr]
    tau, d_integral = drive_torque(lp, held_speed(lp, qd[Q_X], omega), omega, y[2 * nq + Y_DRIVE_INTEGRAL])
    sd = qd[i_idl]
    tension_force = lp[LP_PRELOAD] - lp[LP_TENSIONER_STIFFNESS] * q[i_idl] - lp[LP_TENSIONER_DAMPING] * sd
    if abs(q[i_idl]) > lp[LP_TRAVEL]:
        diag[D_STATUS] = IDLER_OFF_GUIDE
    own = _chassis_own(q, m, w)
    drawbar = drawbar_power = 0.0
    if has_drawbar(lp):
        fx, torque, drawbar_power = drawbar_on_chassis(lp, qd[Q_X], qd[Q_PITCH], c, s)
        own = (own[0] + fx, own[1], own[2] + torque)
        drawbar = -fx
    a, f, e, arm_dissipation = chassis_and_arms(q, qd, par, arms, w.fwheel, w.wv, w.wc, w.arm, c, s, own)
    ke, e_tors, e_grav = e
    inertia = lp[LP_SPROCKET_INERTIA]
    _row(w.extra, LOOP_SPROCKET, 0.0, 0.0, inertia, inertia, w.spr[SP_TORQUE] - tau)
    ke += 0.5 * inertia * w.spr[SP_RATE] ** 2
    da, df, ke_idler, eg_idler = _idler(q, qd, m, w, c, s, tension_force)
    a = (a[0] + da[0], a[1], a[2] + da[2], a[3] + da[3], a[4] + da[4], a[5] + da[5] + inertia)
    f = (f[0] + df[0], f[1] + df[1], f[2] + df[2])
    at_rest = w.genf.shape[0] > 0   # the equilibrium's Work: it reads the forces at rest
    if at_rest:
        _forces_at_rest(f, w, nw, n, w.genf)
    a, f = take_out_rows(w.extra, 0.0, ARM_D, a, f)   # the sprocket's and the idler's rows
    acc3 = chassis_acceleration(w.arm, a, f)
    acc = start_rates(ydot, qd, nq, acc3)
    for i in range(nw):
        acc[Q_ARM + i] = row_acceleration(w.arm, i, w.arm[i, ARM_D], acc3)
    for r, k in ((LOOP_SPROCKET, i_spr), (LOOP_IDLER, i_idl)):
        acc[k] = row_acceleration(w.extra, r, w.extra[r, ARM_D], acc3)
    ke, e_grav = pin_accelerations(par, nw, n, w.apos, w.avel, w.fpin, acc, ke + ke_idler, e_grav + eg_idler)
    for b in range(1, n + 1 if at_rest else 1):   # pins at rest: their forces for the equilibrium
        k = q_pin(nw, b)
        w.genf[k] = acc[k] * par[P_PIN_MASS]
        w.genf[k + 1] = acc[k + 1] * par[P_PIN_MASS]
    drive_power = tau * omega
    tensioner_damping = lp[LP_TENSIONER_DAMPING] * sd * sd
    diag[D_DISSIPATION] += (
        arm_dissipation + tensioner_damping - drawbar_power
    )  # the drawbar takes its work out
    ydot[2 * nq + Y_WORK] = diag[D_POWER] - arm_dissipation + drive_power + tension_force * sd + drawbar_power
    ydot[2 * nq + Y_DISSIPATED] = diag[D_DISSIPATION]
    ydot[2 * nq + Y_DRIVE_WORK] = drive_power
    ydot[2 * nq + Y_DRIVE_INTEGRAL] = d_integral
    store_state_energies(diag, (ke, e_tors, e_grav), acc3)
    diag[D_DRIVE_TORQUE] = tau
    diag[D_IDLER_FORCE] = tension_force
    diag[D_DRAWBAR] = drawbar
    diag[D_TEETH_TORQUE] = -w.spr[SP_TORQUE]


@njit(**KERNEL)
def place_closed_samples(qs, m, pins, wheels, guides):
    """place_closed for every row of qs (output samples): pins (n, n_links, 2) (rows 1..n_links),
    wheels (n, n_wheels, 2), idler and rollers (n, n_guides, 2)."""
    apos = np.empty((pins.shape[1] + 1, 2))
    arm = np.empty((m.arms.shape[0], ARM_COLS + 1))
    for k in range(qs.shape[0]):
        place_closed(qs[k], m, apos, wheels[k], arm, guides[k])
        for b in range(pins.shape[1]):
            pins[k, b, 0] = apos[b + 1, 0]
            pins[k, b, 1] = apos[b + 1, 1]
