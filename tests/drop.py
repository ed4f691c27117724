"""Drop test of the contact laws: a 20 kg pin meets a pad (k = 1e8 N/m) at 1 m/s; the
restitution obtained is its exit speed / 1 m/s. The law is the compiled one the kernels
use (model/contact/laws_jit.py normal_force). Run as a script to print the table of docs/validation.md:

    python tests/drop.py
"""

import math

from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from trackbench.model.contact.laws import DAMPING_LAWS, ELASTIC_LAWS, damping_ratio_for_restitution
from trackbench.model.contact.laws_jit import normal_force

PIN_MASS = 20.0
K = 1e8
V = 1.0


def drop(damping, e=1.0, zeta=0.0, n=1.0, ramp=2e-4, k=K, m=PIN_MASS, v=V):
    """Measured restitution of one impact (v0 = the impact speed, as at a located onset)."""
    law = ELASTIC_LAWS["linear" if n == 1.0 else "power"].code
    row = DAMPING_LAWS[damping]
    code = row.code
    chi = row.coefficient(e) if row.coefficient else 0.0
    c = 2.0 * zeta * math.sqrt(k * m)

    def rhs(t, s):
        delta, rate = s
        if delta <= 0.0:
            return [rate, 0.0]
        f, _, _ = normal_force((law, code, k, n, c, chi, ramp), delta, rate, v)
        return [rate, -f / m]

    def leaves(t, s):
        return s[0] if t > 0.0 else 1.0

    leaves.terminal = True
    leaves.direction = -1
    r = solve_ivp(
        rhs, (0.0, 0.05), [0.0, v], method="DOP853", rtol=1e-11, atol=1e-15, events=leaves, max_step=2e-6
    )
    return -r.y_events[0][0][1] / v


def viscous_closed_form(zeta):
    """Restitution of a linear spring-dashpot that cannot pull: it lets go where k x + c x'
    = 0 (omega_d t = pi - atan(2 zeta sqrt(1 - zeta^2) / (1 - 2 zeta^2))), not at x = 0."""
    wd = math.sqrt(1.0 - zeta * zeta)
    ts = (math.pi - math.atan2(2.0 * zeta * wd, 1.0 - 2.0 * zeta * zeta)) / wd
    return math.exp(-zeta * ts) * abs(wd * math.cos(wd * ts) - zeta * math.sin(wd * ts)) / wd


def restitution_law_closed_form(chi):
    """Restitution of F = K d^n (1 + chi d'/v0) with v0 the impact speed, for any n: with
    u = d'/v0 and E = K d^(n+1)/(n+1), m v0^2 u du = -(1 + chi u) dE, so the energy stored
    at full compression, 1/chi - ln(1 + chi)/chi^2 (in m v0^2), is given back along
    -u/(1 + chi u) until the force vanishes (u = -1/chi) or the pad is free (u = -e)."""
    if chi <= 0.0:
        return 1.0
    stored = 1.0 / chi - math.log1p(chi) / chi**2

    def returned(e):
        return -e / chi - math.log1p(-chi * e) / chi**2

    top = 1.0 / chi if chi > 1.0 else 1.0
    if chi > 1.0 and returned(top * (1 - 1e-15)) <= stored:
        return top  # the force reaches zero first: the pin leaves at u = -1/chi
    return brentq(lambda e: returned(e) - stored, 0.0, min(top, 1.0) * (1 - 1e-15), xtol=1e-14)


def table():
    rows = [
        "| law | n | e requested | e measured | closed form | measured / requested |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for e in (0.2, 0.5, 0.75, 0.9):
        z = damping_ratio_for_restitution(e)
        for ramp, label in ((1e-9, "viscous (no ramp)"), (2e-4, "viscous (ramp 0.2 mm)")):
            got = drop("viscous", zeta=z, ramp=ramp)
            rows.append(
                f"| {label}, zeta {z:.4f} | 1 | {e} | {got:.4f} | {viscous_closed_form(z):.4f} | "
                f"{got / e:.3f} |"
            )
    for law in ("hunt_crossley", "lankarani_nikravesh", "flores"):
        for n in (1.0, 1.5):
            for e in (0.2, 0.5, 0.75, 0.9):
                got = drop(law, e=e, n=n)
                ref = restitution_law_closed_form(DAMPING_LAWS[law].coefficient(e))
                rows.append(f"| {law} | {n:g} | {e} | {got:.4f} | {ref:.4f} | {got / e:.3f} |")
    return "\n".join(rows)


if __name__ == "__main__":
    print(table())
