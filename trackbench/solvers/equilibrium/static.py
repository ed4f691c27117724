"""The static equilibrium on flat ground of either track layout: the start (the wheels on the
taut track, the track on the ground), the solution by continuation and Newton's method,
and the balance read off at the solution (torsion-bar preloads, wheel loads, tensions)."""

from dataclasses import dataclass, field

import numpy as np

from ...model.core import indices as L
from ...model.dynamics.equilibrium import ClosedStaticProblem, StaticProblem
from ...model.vehicle.parameters import wheel_centres_body
from ...model.vehicle.track_path import initial_track
from .continuation import soil_sinkage_guess, solve_static


@dataclass
class Equilibrium:
    q: np.ndarray  # reduced coordinates (model/core/indices.py), chassis x = 0
    phi0: np.ndarray  # torsion-bar free angles (rad; given by vehicle.torsion_free_angle, or solved)
    preload: np.ndarray  # torsion-bar torque on each arm at equilibrium (N m)
    wheel_load: np.ndarray  # vertical track force on each road wheel (N)
    tension: np.ndarray  # per link (N)
    ground_force: float  # total vertical ground force (N)
    weight: float  # total weight (N)
    residual: float  # max |force residual| (N), torsion-bar moments included
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


def _balance(P, u, it, first_pin=0):
    """At the solution: residuals, coordinates, the torsion bars' free angles and preloads
    (the torsion torque -k_t (phi - phi0) balances each arm's moment about its pivot), pins,
    wheel loads, wheel centres and link tensions."""
    r, fx, arm_moment = P.residual(u)
    q = P.q_of(u)
    phi = q[L.Q_ARM : L.Q_ARM + P.nw]
    if P.free:   # the free angles given, the rest angles solved: the torsion bars' torque there
        phi0 = P.arms[:, L.ARMS_PHI0].copy()
        preload = -P.arms[:, L.ARMS_STIFFNESS] * (phi - phi0)
    else:
        preload = -arm_moment
        phi0 = phi + preload / P.arms[:, L.ARMS_STIFFNESS]
    apos, fpin, fwheel, wc = P.loads(q)
    tension = P.diag[L.diag_tension(P.nw) : L.diag_tension(P.nw) + P.n_links].copy()
    return Equilibrium(
        q=q,
        phi0=phi0,
        preload=preload,
        wheel_load=fwheel[:, 1].copy(),
        tension=tension,
        ground_force=float(P.diag[L.D_GROUND_FY]),
        weight=P.weight,
        residual=float(max(np.abs(r).max(), abs(fx))),
        iterations=it,
        info={"pins": apos[first_pin:].copy(), "wheel_centres": wc.copy()},
    )


def solve_equilibrium(vehicle, track, gravity, contact=None, soil=None, tol_rel=1e-12, max_iter=60):
    """Newton's method from the wheels resting on the track and the track on the ground
    (soil: {P_* index: value} of soft soil, run/assemble.soil_par). A power law is reached by
    continuation (continuation.py)."""
    P = StaticProblem(vehicle, track, gravity, contact, soil)
    rho = P.arms[:, L.ARMS_REACH]   # each wheel's radius + pad
    hg = P.par[L.P_PAD_GROUND]
    # start: wheels resting on the track, the track on the ground, chassis level (the
    # lowest wheel's bottom; rounding is monotonic: max(-y + rho) is -min(y) + rho alike)
    wcb = wheel_centres_body(vehicle)
    yc = float(np.max(-wcb[:, 1] + rho)) + hg
    ends_w = P.ends + [0.0, yc]
    pins, _, _ = initial_track(ends_w, wcb + [0.0, yc], rho, P.n_links)
    u = np.concatenate([[yc, 0.0], pins[1:-1].ravel()])
    u[0] -= soil_sinkage_guess(P, pins)
    u[3::2] -= soil_sinkage_guess(P, pins)
    u = P.with_arms(u)
    u, it = solve_static(
        P, u, max_iter, tol_rel, "static equilibrium not found", "the vehicle and track geometry"
    )
    return _balance(P, u, it)


def solve_closed_equilibrium(
    vehicle, track, gravity, contact, geometry, loop, guides, soil=None, tol_rel=1e-12, max_iter=60,
    start=None,
):
    """Static equilibrium of the closed layout on flat ground: Newton's method from the
    taut loop (model/vehicle/closed_track.py) resting on the ground, the sprocket held; or from
    start, another equilibrium of the same vehicle and loop (its unknowns; the sprocket held
    where it was), the arms at its angles."""
    P = ClosedStaticProblem(vehicle, track, gravity, contact, geometry, loop, guides, soil)
    if start is None:
        yc = (
            -P.pins[:, 1].min() + P.par[L.P_PAD_GROUND] - soil_sinkage_guess(P, P.pins)
        )  # lowest pins on the ground
        u = P.with_arms(np.concatenate([[yc, 0.0, P.slide0, P.psi], (P.pins + [0.0, yc]).ravel()]))
    else:
        n = 4 + 2 * P.n_links
        u = np.concatenate([start.info["unknowns"][:n], start.q[L.Q_ARM:L.Q_ARM + P.nw]]) if P.free else \
            start.info["unknowns"][:n].copy()
        P.psi = u[3]
    u, it = solve_static(
        P,
        u,
        max_iter,
        tol_rel,
        "static equilibrium of the closed track not found",
        "the sprocket, idler and track values",
    )
    eq = _balance(P, u, it, first_pin=1)
    w = P.work
    eq.info.update(
        {
            "idler_slide": float(u[2]),
            "idler_force": float(P.diag[L.D_IDLER_FORCE]),
            "holding_torque": float(w.spr[L.SP_TORQUE]),  # forward drive torque that holds the sprocket
            "guide_forces": w.fguide.copy(),
            "unknowns": u.copy(),   # a start for another solve (start)
        }
    )
    return eq
