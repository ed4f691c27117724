"""Rosenbrock-W methods as validated tables, for the stiff local terms (pin friction, impacts).

A Rosenbrock-W step solves (I - h gamma A) k_i = h f(y + sum_j alpha_ij k_j) + h A sum_j gamma_ij k_j
with A any approximation of the Jacobian; a W-method keeps its order for every A, so the integrator
to come may reuse one Jacobian over many steps. The table is kept in the published form (alpha,
Gamma, b, b_hat), checked against the order conditions on construction, and handed to a compiled
loop in the transformed form of Hairer & Wanner II, section IV.7, eq. (7.25), which needs no
product with the Jacobian. ROS34PW2: J. Rang, L. Angermann, "New Rosenbrock W-methods of order 3
for partial differential algebraic equations of index 1", BIT Numer. Math. 45 (2005) 761-787;
4 stages, order 3 (also as a W-method), embedded order 2, stiffly accurate, L-stable. The digits
were read from OrdinaryDiffEq.jl, lib/OrdinaryDiffEqRosenbrock/src/generic_rosenbrock.jl
(ROS34PW2Tableau, which cites the paper).
"""

from collections import namedtuple
from dataclasses import dataclass

import numpy as np

# What the compiled loop reads (transformed variables u = Gamma k): the stage matrix A, the
# coupling C (divided by h in the step), the weights m and m_hat, the stage times c, the
# coefficients gamma_i of h f_t, gamma, and the step-size exponent of the embedded estimate.
RosenbrockArrays = namedtuple(
    "RosenbrockArrays", ["A", "C", "m", "m_hat", "c", "gamma_i", "gamma", "expo"]
)

# The published digits satisfy the conditions to ~2e-16; a wrong digit shows as >> 1e-13.
TOL = 1e-13


def _square(rows):
    """Strictly lower-triangular rows as a square list of float lists."""
    s = len(rows)
    return [[float(rows[i][j]) if j < i else 0.0 for j in range(s)] for i in range(s)]


def _sum_rows(M):
    return [sum(row) for row in M]


def _mat_vec(M, v):
    return [sum(M[i][j] * v[j] for j in range(len(v))) for i in range(len(M))]


def _weigh(w, v):
    return sum(wi * vi for wi, vi in zip(w, v))


def _conditions(gamma, alpha, beta, w_method):
    """(label, order, left side, right side) of every condition; alpha, beta strictly lower.

    Rosenbrock conditions: Hairer & Wanner II, Table IV.7.1 (beta_ij = alpha_ij + gamma_ij for
    j < i; the diagonal gamma is taken out, which gives the right sides in gamma). The W-method
    conditions are those of the trees with a vertex for A (Hairer & Wanner II, section IV.7,
    W-methods): each such tree must have weight 0, which, with the Rosenbrock conditions, is
    equivalent to the four listed here (derived so; the paper's own list was not available).
    """
    a = _sum_rows(alpha)            # alpha_i = c_i
    bt = _sum_rows(beta)            # beta_i' = sum_{j<i} beta_ij
    rows = [
        ("order 1: sum b_i = 1", 1, lambda w: sum(w), 1.0),
        ("order 2: sum b_i beta_ij = 1/2 - gamma", 2, lambda w: _weigh(w, bt), 0.5 - gamma),
        ("order 3: sum b_i alpha_ij alpha_ik = 1/3", 3, lambda w: _weigh(w, [x * x for x in a]), 1 / 3),
        ("order 3: sum b_i beta_ij beta_jk = 1/6 - gamma + gamma^2", 3,
         lambda w: _weigh(w, _mat_vec(beta, bt)), 1 / 6 - gamma + gamma**2),
    ]
    if w_method:
        rows += [
            ("W order 2: sum b_i alpha_ij = 1/2", 2, lambda w: _weigh(w, a), 0.5),
            ("W order 3: sum b_i alpha_ij alpha_jk = 1/6", 3, lambda w: _weigh(w, _mat_vec(alpha, a)), 1 / 6),
            ("W order 3: sum b_i alpha_ij beta_jk = 1/6 - gamma/2", 3,
             lambda w: _weigh(w, _mat_vec(alpha, bt)), 1 / 6 - gamma / 2),
            ("W order 3: sum b_i beta_ij alpha_jk = 1/6 - gamma/2", 3,
             lambda w: _weigh(w, _mat_vec(beta, a)), 1 / 6 - gamma / 2),
        ]
    return rows


def _inverse_lower(G):
    """Inverse of a lower-triangular matrix by forward substitution, in a fixed order (no LAPACK:
    the coefficients a result is made of do not depend on the machine's linear algebra)."""
    s = len(G)
    inv = [[0.0] * s for _ in range(s)]
    for col in range(s):
        for i in range(col, s):
            acc = (1.0 if i == col else 0.0) - sum(G[i][k] * inv[k][col] for k in range(col, i))
            inv[i][col] = acc / G[i][i]
    return inv


@dataclass(frozen=True)
class RosenbrockTableau:
    name: str
    order: int              # order of the propagated solution (b)
    embedded_order: int     # order of b_hat (sets the step-size exponent)
    gamma: float            # the diagonal of Gamma
    alpha: tuple            # strictly lower-triangular rows
    gamma_ij: tuple         # strictly lower-triangular rows: Gamma's off-diagonal
    b: tuple
    b_hat: tuple
    w_method: bool = True   # also check the conditions that hold for any Jacobian approximation

    def __post_init__(self):
        s = len(self.b)
        if len(self.b_hat) != s or len(self.alpha) != s or len(self.gamma_ij) != s:
            raise ValueError(f"{self.name}: inconsistent stage counts")
        for label, rows in (("alpha", self.alpha), ("gamma_ij", self.gamma_ij)):
            for i, row in enumerate(rows):
                if len(row) != i:
                    raise ValueError(f"{self.name}: row {i} of {label} is not strictly lower triangular")
        if not self.gamma > 0:
            raise ValueError(f"{self.name}: gamma must be positive")
        if not 1 <= self.embedded_order < self.order <= 3:
            raise ValueError(f"{self.name}: orders {self.order}({self.embedded_order}) not checkable "
                             "(conditions implemented up to order 3)")
        alpha, off = _square(self.alpha), _square(self.gamma_ij)
        beta = [[x + y for x, y in zip(ra, ro)] for ra, ro in zip(alpha, off)]
        for weights, order, which in ((self.b, self.order, "b"), (self.b_hat, self.embedded_order, "b_hat")):
            for label, k, lhs, rhs in _conditions(self.gamma, alpha, beta, self.w_method):
                if k <= order and abs(lhs(weights) - rhs) > TOL:
                    raise ValueError(f"{self.name}: {which} fails the condition {label} "
                                     f"(residual {lhs(weights) - rhs:.3e})")

    @property
    def stages(self):
        return len(self.b)

    @property
    def stiffly_accurate(self):
        """b_i = beta_si (last row of alpha + Gamma): y_new is the last stage's argument."""
        last = [x + y for x, y in zip(self.alpha[-1], self.gamma_ij[-1])] + [self.gamma]
        return all(abs(x - y) <= TOL for x, y in zip(last, self.b))

    def gamma_matrix(self):
        """Gamma with its diagonal, as float lists."""
        G = _square(self.gamma_ij)
        for i in range(self.stages):
            G[i][i] = float(self.gamma)
        return G

    def arrays(self):
        """RosenbrockArrays in the transformed variables u_i = sum_j Gamma_ij k_j (Hairer & Wanner
        (7.25)): (I/(h gamma) - J) u_i = f(t + c_i h, y + sum_j A_ij u_j) + sum_j C_ij u_j / h
        + gamma_i h f_t, y_new = y + sum m_i u_i, the estimate y + sum m_hat_i u_i.
        Setup code, computed once with plain loops in a fixed order."""
        s, G = self.stages, self.gamma_matrix()
        Ginv = _inverse_lower(G)
        alpha = _square(self.alpha)
        A = [[sum(alpha[i][k] * Ginv[k][j] for k in range(s)) for j in range(s)] for i in range(s)]
        C = [[(1.0 / G[i][i] if i == j else 0.0) - Ginv[i][j] for j in range(s)] for i in range(s)]
        m = [sum(self.b[k] * Ginv[k][j] for k in range(s)) for j in range(s)]
        m_hat = [sum(self.b_hat[k] * Ginv[k][j] for k in range(s)) for j in range(s)]
        return RosenbrockArrays(
            np.array(A),
            np.array(C),
            np.array(m),
            np.array(m_hat),
            np.array(_sum_rows(alpha)),
            np.array(_sum_rows(G)),
            float(self.gamma),
            -1.0 / (self.embedded_order + 1),
        )


def _floats(rows):
    return tuple(tuple(float(x) for x in row) for row in rows)


# ROS34PW2, Rang & Angermann (2005), with the digits as OrdinaryDiffEq.jl carries them (see the
# module docstring); kept as the decimal strings read, converted once. The fourth stage's alpha row is
# (0, 0, 1): with b = alpha_4j + gamma_4j and b_4 = gamma the method is stiffly accurate.
_ROS34PW2_GAMMA = "4.3586652150845900e-01"
_ROS34PW2_ALPHA = (
    (),
    ("8.7173304301691801e-01",),
    ("8.4457060015369423e-01", "-1.1299064236484185e-01"),
    ("0", "0", "1"),
)
_ROS34PW2_GAMMA_IJ = (
    (),
    ("-8.7173304301691801e-01",),
    ("-9.0338057013044082e-01", "5.4180672388095326e-02"),
    ("2.4212380706095346e-01", "-1.2232505839045147e+00", "5.4526025533510214e-01"),
)
_ROS34PW2_B = ("2.4212380706095346e-01", "-1.2232505839045147e+00", "1.5452602553351020e+00",
               "4.3586652150845900e-01")
_ROS34PW2_B_HAT = ("3.7810903145819369e-01", "-9.6042292212423178e-02", "5.0000000000000000e-01",
                   "2.1793326075422950e-01")

ROS34PW2 = RosenbrockTableau(
    "ros34pw2", 3, 2, float(_ROS34PW2_GAMMA), _floats(_ROS34PW2_ALPHA), _floats(_ROS34PW2_GAMMA_IJ),
    tuple(map(float, _ROS34PW2_B)), tuple(map(float, _ROS34PW2_B_HAT)),
)

ROSENBROCK_TABLEAUS = {t.name: t for t in (ROS34PW2,)}
