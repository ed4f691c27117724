"""Rosenbrock-W methods as validated tables.

A Rosenbrock-W step with any matrix W in place of the Jacobian solves, stage after stage,

    (I - h gamma W) k_i = h f(y + sum_j<i alpha_ij k_j) + h W sum_j<i gamma_ij k_j,
    y_new = y + sum_i b_i k_i,   the embedded y_hat = y + sum_i b_hat_i k_i

(an autonomous f: the model's right-hand side has no explicit time). A W-method keeps its
order whatever W is, so W may be an approximation (solvers/common/pin_jacobian.py: the pins'
blocks) and may be reused over steps; W decides only where the step is stable.

The table is kept in the published form (gamma, alpha, Gamma's off-diagonal, b, b_hat) as the
decimal strings read, turned into exact rationals, and checked on construction against the
W-method order conditions (below), its structure (one diagonal gamma; stiffly accurate: b is
the last row of alpha + Gamma, so y_new is the last stage's argument plus its own increment);
the compiled loop takes it in the transformed variables u_i = sum_j Gamma_ij k_j of Hairer &
Wanner II, section IV.7, eq. (7.25), which need no product with W (RosArrays).

Order conditions of a W-method (Hairer & Wanner II, section IV.7, "W-methods"): the B-series
of a step runs over trees whose vertices are f (the function: any number of children, joined
to them by alpha) or W (the matrix: exactly one child, joined by Gamma with its diagonal); the
exact solution's series has the f-trees alone. So the weights b meet sum b Phi(t) = 1 / gamma(t)
(Butcher's density) on every f-tree and 0 on every tree with a W vertex, up to the order:
1, 2, 5 trees of orders 1, 2, 3 (8 conditions for order 3); with W = f'(y) they imply the
Rosenbrock conditions of Hairer & Wanner's Table IV.7.1.

ROS34PW2: J. Rang, L. Angermann, "New Rosenbrock W-methods of order 3 for partial differential
algebraic equations of index 1", BIT Numer. Math. 45 (2005) 761-787: 4 stages, order 3 as a
W-method, embedded order 2 (as a W-method too), stiffly accurate, L-stable (R(inf) = 0; the
embedded method's |R(inf)| = 0.48). Its coefficients are the paper's table of ROS34PW2; the
digits here are those two independent implementations carry, identical to the last of 17
digits: PETSc (src/ts/impls/rosw/rosw.c, TSROSWRA34PW2) and OrdinaryDiffEq.jl (its
ROS34PW2 tableau). In doubles they meet every condition to < 3e-16.
"""

from collections import namedtuple
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache

import numpy as np

# What the compiled loop reads (transformed variables, Hairer & Wanner (7.25) for an autonomous
# f): (I / (h gamma) - W) u_i = f(y + sum_j<i A_ij u_j) + sum_j<i C_ij u_j / h; y_new = y +
# sum m_i u_i, the error estimate sum (m_i - m_hat_i) u_i (= y_new - y_hat), and the
# step-size exponent -1 / (embedded order + 1).
RosArrays = namedtuple("RosArrays", ["A", "C", "m", "e", "gamma", "expo"])

# The published digits meet the conditions to ~3e-16; a wrong digit shows as >> 1e-13.
TOL = 1e-13
MAX_ORDER = 4   # trees are generated (and conditions checkable) up to this order


# --- Trees with f and W vertices ------------------------------------------------------------
# A tree is (label, children): label "f" (children: a sorted tuple of trees, any number) or "W"
# (exactly one child).


def _order(tree):
    return 1 + sum(_order(c) for c in tree[1])


def _density(tree):
    d = _order(tree)
    for c in tree[1]:
        d *= _density(c)
    return d


@lru_cache(maxsize=None)
def w_trees(order):
    """Every tree of the given order with f and W vertices (a W vertex has one child), each once."""
    if order == 1:
        return (("f", ()),)
    out = [("W", (t,)) for t in w_trees(order - 1)]
    items = [t for k in range(1, order) for t in w_trees(k)]
    found = []

    def grow(start, left, chosen):   # the children as a multiset: indices never decrease
        if left == 0:
            found.append(("f", tuple(sorted(chosen))))
            return
        for idx in range(start, len(items)):
            k = _order(items[idx])
            if k <= left:
                grow(idx, left - k, chosen + [items[idx]])

    grow(0, order - 1, [])
    return tuple(out + found)


def has_w(tree):
    return tree[0] == "W" or any(has_w(c) for c in tree[1])


def tree_name(tree):
    """f[f, W[f]]: a vertex's label, its children in brackets."""
    label, children = tree
    return label + ("[" + ", ".join(tree_name(c) for c in children) + "]" if children else "")


def _phi(tree, alpha, gam):
    """The elementary weights of a tree, per stage (exact)."""
    s = len(alpha)
    label, children = tree
    if label == "W":
        v = _phi(children[0], alpha, gam)
        return [sum(gam[i][j] * v[j] for j in range(s)) for i in range(s)]
    out = [Fraction(1)] * s
    for c in children:
        v = _phi(c, alpha, gam)
        out = [out[i] * sum(alpha[i][j] * v[j] for j in range(s)) for i in range(s)]
    return out


Condition = namedtuple("Condition", ["label", "residual"])


def _lower(rows, s, what):
    """Strictly lower rows (row i has i entries) as a square list of exact rationals."""
    M = [[Fraction(0)] * s for _ in range(s)]
    for i, row in enumerate(rows):
        if len(row) != i:
            raise ValueError(f"row {i} of {what} has {len(row)} entries, expected {i}")
        for j, x in enumerate(row):
            M[i][j] = Fraction(x)
    return M


def _inverse_lower(G):
    """The inverse of a lower-triangular matrix by forward substitution (exact rationals)."""
    s = len(G)
    inv = [[Fraction(0)] * s for _ in range(s)]
    for col in range(s):
        for i in range(col, s):
            acc = (1 if i == col else 0) - sum(G[i][k] * inv[k][col] for k in range(col, i))
            inv[i][col] = acc / G[i][i]
    return inv


@dataclass(frozen=True)
class RosTableau:
    name: str
    order: int            # of y_new as a W-method
    embedded_order: int   # of y_hat as a W-method (sets the step-size exponent)
    gamma: str
    alpha: tuple          # strictly lower rows
    gamma_ij: tuple       # strictly lower rows: Gamma's off-diagonal
    b: tuple
    b_hat: tuple

    def __post_init__(self):
        s = len(self.b)
        if not (len(self.b_hat) == len(self.alpha) == len(self.gamma_ij) == s):
            raise ValueError(f"{self.name}: inconsistent stage counts")
        if not 1 <= self.embedded_order < self.order <= MAX_ORDER:
            raise ValueError(f"{self.name}: orders {self.order}({self.embedded_order}) not checkable")
        try:
            _lower(self.alpha, s, "alpha"), _lower(self.gamma_ij, s, "gamma_ij")
        except ValueError as err:
            raise ValueError(f"{self.name}: {err}") from None
        if not Fraction(self.gamma) > 0:
            raise ValueError(f"{self.name}: gamma must be positive")
        alpha, gam = self.matrices()
        last = [alpha[-1][j] + gam[-1][j] for j in range(s)]
        if not all(abs(x - Fraction(y)) <= TOL for x, y in zip(last, self.b)):
            raise ValueError(f"{self.name}: fails the condition stiffly accurate "
                             "(b = last row of alpha + Gamma)")
        for cond in self.conditions():
            if not abs(cond.residual) <= TOL:
                raise ValueError(f"{self.name}: fails the condition {cond.label} "
                                 f"(residual {float(cond.residual):.3e})")

    @property
    def stages(self):
        return len(self.b)

    def matrices(self):
        """alpha and Gamma (its diagonal gamma included), square, exact."""
        s = self.stages
        alpha, gam = _lower(self.alpha, s, "alpha"), _lower(self.gamma_ij, s, "gamma_ij")
        for i in range(s):
            gam[i][i] = Fraction(self.gamma)
        return alpha, gam

    def conditions(self):
        """(label, residual) of every W-method condition: b up to the order, b_hat up to the
        embedded order."""
        alpha, gam = self.matrices()
        out = []
        for which, w, top in (("b", self.b, self.order), ("b_hat", self.b_hat, self.embedded_order)):
            w = [Fraction(x) for x in w]
            for k in range(1, top + 1):
                for tree in w_trees(k):
                    lhs = sum(x * y for x, y in zip(w, _phi(tree, alpha, gam)))
                    rhs = Fraction(0) if has_w(tree) else Fraction(1, _density(tree))
                    kind = "W" if has_w(tree) else "f"
                    label = f"{which}: order {k} {kind}-tree {tree_name(tree)} = {rhs}"
                    out.append(Condition(label, lhs - rhs))
        return out

    def stability(self, z):
        """R(z) of y' = lambda y with W = lambda (z = h lambda): 1 + z b^T (I - z B)^-1 1, B =
        alpha + Gamma (complex z; plain numpy, for the tests)."""
        alpha, gam = self.matrices()
        B = np.array([[float(a + g) for a, g in zip(ra, rg)] for ra, rg in zip(alpha, gam)])
        b = np.array([float(x) for x in self.b])
        s = self.stages
        return 1 + z * b @ np.linalg.solve(np.eye(s) - z * B, np.ones(s))

    def arrays(self):
        """RosArrays (see there), from the exact rationals, rounded once."""
        s = self.stages
        alpha, gam = self.matrices()
        ginv = _inverse_lower(gam)
        A = [[sum(alpha[i][k] * ginv[k][j] for k in range(s)) for j in range(s)] for i in range(s)]
        C = [[(1 / gam[i][i] if i == j else 0) - ginv[i][j] for j in range(s)] for i in range(s)]
        m = [sum(Fraction(self.b[k]) * ginv[k][j] for k in range(s)) for j in range(s)]
        m_hat = [sum(Fraction(self.b_hat[k]) * ginv[k][j] for k in range(s)) for j in range(s)]
        e = [x - y for x, y in zip(m, m_hat)]
        A, C, m, e = (np.array(v, dtype=float) for v in (A, C, m, e))
        return RosArrays(A, C, m, e, float(Fraction(self.gamma)), -1.0 / (self.embedded_order + 1))


# ROS34PW2, Rang & Angermann (2005): the digits as PETSc and OrdinaryDiffEq.jl carry them (the
# module docstring). The fourth stage's alpha row (0, 0, 1) and b = its alpha + Gamma row with
# b_4 = gamma: stiffly accurate.
ROS34PW2 = RosTableau(
    "ros34pw2", 3, 2, "4.3586652150845900e-01",
    alpha=(
        (),
        ("8.7173304301691801e-01",),
        ("8.4457060015369423e-01", "-1.1299064236484185e-01"),
        ("0", "0", "1"),
    ),
    gamma_ij=(
        (),
        ("-8.7173304301691801e-01",),
        ("-9.0338057013044082e-01", "5.4180672388095326e-02"),
        ("2.4212380706095346e-01", "-1.2232505839045147e+00", "5.4526025533510214e-01"),
    ),
    b=("2.4212380706095346e-01", "-1.2232505839045147e+00", "1.5452602553351020e+00",
       "4.3586652150845900e-01"),
    b_hat=("3.7810903145819369e-01", "-9.6042292212423178e-02", "5.0000000000000000e-01",
           "2.1793326075422950e-01"),
)

ROS_TABLEAUS = {t.name: t for t in (ROS34PW2,)}
