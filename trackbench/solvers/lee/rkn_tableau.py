"""The embedded Runge-Kutta-Nystrom pair of the "lee" solver, as a validated table.

For z'' = f(t, z) one step of size h with s stages is

    Z_i  = z + c_i h z' + h^2 sum_j a_ij k_j,   k_i = f(t + c_i h, Z_i)
    z_1  = z + h z' + h^2 sum_j b_j k_j,        z'_1 = z' + h sum_j bp_j k_j

and the local error estimate is h^2 sum_j eb_j k_j (positions), h sum_j ebp_j k_j
(velocities).

Coefficients: J. R. Dormand and P. J. Prince, "Runge-Kutta-Nystrom triples",
Comput. Math. Applic. 13 (1987) 937-949: the RKN6(4)6FD pair (6th-order solution,
4th-order embedded estimate, 6 stages, the last one evaluated at the new point so
it is reused as the first stage of the next step: first same as last). The exact
values below (surds in sqrt(8581)) are those of that paper as transcribed in
OrdinaryDiffEq.jl's DPRKN6 table. This is the Dormand-Prince RKN family the paper's
DOPRIN code (Hairer, Norsett & Wanner, Solving ODEs I, 1987) belongs to; which exact
member DOPRIN used could not be checked here, so the pair is named for its source.
The table is checked against the order conditions below at import.
"""

from collections import namedtuple
from dataclasses import dataclass
from math import factorial, sqrt

import numpy as np

from ..rk.tableau import lower_triangular

RknArrays = namedtuple("RknArrays", ["A", "b", "bp", "c", "eb", "ebp", "expo"])

R = sqrt(8581.0)

_C = [0.0, (209.0 - R) / 900.0, (209.0 - R) / 450.0, (209.0 + R) / 450.0, 0.9, 1.0]
_A = [
    [],
    [(26131.0 - 209.0 * R) / 810000.0],
    [(26131.0 - 209.0 * R) / 607500.0, (26131.0 - 209.0 * R) / 303750.0],
    [(980403512254.0 + 7781688431.0 * R) / 11694469921875.0,
     -(1262884486208.0 + 15385481287.0 * R) / 11694469921875.0,
     (7166233891441.0 + 78694563299.0 * R) / 46777879687500.0],
    [-9.0 * (329260.0 + 3181.0 * R) / 27040000.0, 27.0 * (35129.0 + 3331.0 * R) / 13520000.0,
     -27.0 * (554358343.0 + 31040327.0 * R) / 464060480000.0,
     153.0 * (8555257.0 - 67973.0 * R) / 2745920000.0],
    [329.0 / 4212.0, 0.0, (84119543.0 + 366727.0 * R) / 409622616.0,
     (84119543.0 - 366727.0 * R) / 409622616.0, 200.0 / 17901.0],
]
_B = [329.0 / 4212.0, 0.0, (84119543.0 + 366727.0 * R) / 409622616.0,
      (84119543.0 - 366727.0 * R) / 409622616.0, 200.0 / 17901.0, 0.0]
_BP = [329.0 / 4212.0, 0.0, (389225579.0 + 96856.0 * R) / 1024056540.0,
       (389225579.0 - 96856.0 * R) / 1024056540.0, 2000.0 / 17901.0, 1.0 / 20.0]
# error weights = high-order minus embedded weights
_EB = [329.0 / 4212.0 - (2701.0 + 23.0 * R) / 4563.0, (9829.0 + 131.0 * R) / 9126.0,
       (84119543.0 + 366727.0 * R) / 409622616.0 - 5.0 * (1798.0 + 17.0 * R) / 9126.0,
       _B[3], _B[4], 0.0]
_EBP = [329.0 / 4212.0 - 115.0 / 2106.0, 0.0,
        (389225579.0 + 96856.0 * R) / 1024056540.0 - (84119543.0 + 366727.0 * R) / 256014135.0,
        (389225579.0 - 96856.0 * R) / 1024056540.0 - (84119543.0 - 366727.0 * R) / 256014135.0,
        2000.0 / 17901.0 - 6950.0 / 17901.0, 1.0 / 20.0 + 1.0 / 10.0]


@dataclass(frozen=True)
class NystromPair:
    name: str
    order: int
    error_order: int
    c: tuple
    a: tuple
    b: tuple
    bp: tuple
    eb: tuple
    ebp: tuple

    def __post_init__(self):
        s = len(self.c)
        tol = 1e-13
        if any(len(x) != s for x in (self.a, self.b, self.bp, self.eb, self.ebp)):
            raise ValueError(f"{self.name}: inconsistent stage counts")
        for i, row in enumerate(self.a):
            if len(row) != i or abs(sum(row) - self.c[i] ** 2 / 2) > tol:
                raise ValueError(f"{self.name}: row {i} of A does not sum to c[{i}]^2 / 2")
        c = np.array(self.c)
        # quadrature conditions of the high-order pair (bushy trees): position weights
        # sum_j b_j c_j^k = 1 / ((k+1)(k+2)), k <= p - 2; velocity weights sum_j bp_j c_j^k =
        # 1/(k+1), k <= p - 1
        for k in range(self.order - 1):
            if abs(np.dot(self.b, c ** k) - 1.0 / ((k + 1) * (k + 2))) > tol:
                raise ValueError(f"{self.name}: position weights fail the order condition c^{k}")
        for k in range(self.order):
            if abs(np.dot(self.bp, c ** k) - 1.0 / (k + 1)) > tol:
                raise ValueError(f"{self.name}: velocity weights fail the order condition c^{k}")
        # Nystrom consistency b_j = bp_j (1 - c_j) and FSAL: last row of A = b, c_s = 1
        if max(abs(bj - bpj * (1 - cj)) for bj, bpj, cj in zip(self.b, self.bp, self.c)) > tol:
            raise ValueError(f"{self.name}: b != bp (1 - c)")
        if self.c[-1] != 1.0 or max(abs(x - y) for x, y in zip(self.a[-1], self.b)) > tol:
            raise ValueError(f"{self.name}: not first-same-as-last")
        # embedded weights b - eb, bp - ebp satisfy the conditions of the lower order
        bl = np.array(self.b) - np.array(self.eb)
        bpl = np.array(self.bp) - np.array(self.ebp)
        for k in range(self.error_order - 1):
            if abs(np.dot(bl, c ** k) - 1.0 / ((k + 1) * (k + 2))) > tol:
                raise ValueError(f"{self.name}: embedded position weights fail c^{k}")
        for k in range(self.error_order):
            if abs(np.dot(bpl, c ** k) - 1.0 / (k + 1)) > tol:
                raise ValueError(f"{self.name}: embedded velocity weights fail c^{k}")
        # one non-bushy condition per order up to 5: sum_i bp_i sum_j a_ij c_j^k = 1/((k+1)(k+2)(k+3))
        for k in range(self.order - 2):
            ac = np.array([sum(r[j] * c[j] ** k for j in range(len(r))) for r in self.a])
            want = factorial(k) / factorial(k + 3)
            if abs(np.dot(self.bp, ac) - want) > tol:
                raise ValueError(f"{self.name}: velocity weights fail sum bp a c^{k}")

    @property
    def stages(self):
        return len(self.c)

    def arrays(self):
        """RknArrays (A, b, bp, c, eb, ebp, step-size exponent) for the compiled loop."""
        return RknArrays(lower_triangular(self.a), np.array(self.b), np.array(self.bp), np.array(self.c),
                         np.array(self.eb), np.array(self.ebp), -1.0 / (self.error_order + 1))


RKN64 = NystromPair("rkn6(4)6fd", 6, 4, tuple(_C), tuple(map(tuple, _A)), tuple(_B), tuple(_BP),
                    tuple(_EB), tuple(_EBP))
