"""Embedded explicit Runge-Kutta pairs as validated tables, run by one compiled stepper.

The error estimate uses the scipy/Hairer convention: the stage list is extended by
f(t + h, y_new) (first same as last), and ``e`` weights that extended list.
DOP853 combines a 5th- and a 3rd-order estimate (Hairer et al., eq. II.10.14).
"""

from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from . import coefficients as K

# What the compiled stepper reads: numba takes the named tuple as one argument.
TableauArrays = namedtuple("TableauArrays", ["A", "b", "c", "e", "e3", "expo"])


def lower_triangular(rows):
    """The strictly lower-triangular rows of a tableau as a square float matrix."""
    A = np.zeros((len(rows), len(rows)))
    for i, row in enumerate(rows):
        A[i, :i] = row
    return A


@dataclass(frozen=True)
class ButcherTableau:
    name: str
    order: int              # order of the propagated solution
    error_order: int        # order of the embedded estimate (sets the step-size exponent)
    c: tuple
    a: tuple                # strictly lower-triangular rows
    b: tuple
    e: tuple                # error weights on the stages + f(t + h, y_new)
    e3: tuple = ()          # DOP853's second (3rd order) estimate

    def __post_init__(self):
        s = len(self.c)
        if len(self.a) != s or len(self.b) != s or len(self.e) != s + 1:
            raise ValueError(f"{self.name}: inconsistent stage counts")
        for i, row in enumerate(self.a):
            if len(row) != i or abs(sum(row) - self.c[i]) > 1e-12:
                raise ValueError(f"{self.name}: row {i} of A does not sum to c[{i}]")
        if abs(sum(self.b) - 1.0) > 1e-12:
            raise ValueError(f"{self.name}: weights do not sum to 1")
        for est in (self.e, self.e3):
            if est and abs(sum(est)) > 1e-12:
                raise ValueError(f"{self.name}: error weights do not sum to 0")

    @property
    def stages(self):
        return len(self.c)

    def arrays(self):
        """TableauArrays (A, b, c, e, e3, error exponent) for the compiled stepper."""
        e3 = np.array(self.e3 if self.e3 else np.zeros(self.stages + 1))
        return TableauArrays(
            lower_triangular(self.a),
            np.array(self.b),
            np.array(self.c),
            np.array(self.e),
            e3,
            -1.0 / (self.error_order + 1),
        )


DOP853 = ButcherTableau("dop853", 8, 7, tuple(K.DOP853_C), tuple(map(tuple, K.DOP853_A)),
                        tuple(K.DOP853_B), tuple(K.DOP853_E5), tuple(K.DOP853_E3))
DOPRI5 = ButcherTableau("dopri5", 5, 4, tuple(K.DOPRI5_C), tuple(map(tuple, K.DOPRI5_A)),
                        tuple(K.DOPRI5_B), tuple(K.DOPRI5_E))

TABLEAUS = {t.name: t for t in (DOP853, DOPRI5)}
