"""The additive Runge-Kutta tables: ARK4(3)6L[2]SA and ARK5(4)8L[2]SA pass every order and
coupling condition, a wrong digit is caught and named, and a plain numpy step of the linearised
splitting f = (f - J y) + J y shows the orders the paper claims, mildly stiff and very stiff."""

import dataclasses
from fractions import Fraction
from functools import lru_cache

import numpy as np
import pytest

from trackbench.solvers.imex.ark_tableau import (
    ARK436L2SA,
    ARK548L2SA,
    ARK_TABLEAUS,
    ArkTableau,
    labelled_trees,
    tree_labels,
)

TABLES = [ARK436L2SA, ARK548L2SA]


def test_labelled_trees_are_counted_right():
    """107 labelled trees of order 5 (each non-root vertex E or I); the all-E ones are Butcher's
    1, 1, 2, 4, 9 trees (17 classical conditions up to order 5)."""
    assert [len(labelled_trees(k)) for k in range(1, 6)] == [1, 2, 7, 26, 107]
    pure = [sum(1 for t in labelled_trees(k) if tree_labels(t) <= {"E"}) for k in range(1, 6)]
    assert pure == [1, 1, 2, 4, 9]


@pytest.mark.parametrize("tab", TABLES, ids=lambda t: t.name)
def test_tables_construct_with_their_structure(tab):
    assert isinstance(tab, ArkTableau) and ARK_TABLEAUS[tab.name] is tab
    T = tab.arrays()
    s = tab.stages
    assert s == {"ark436l2sa": 6, "ark548l2sa": 8}[tab.name]
    assert T.gamma == {"ark436l2sa": 0.25, "ark548l2sa": 41 / 200}[tab.name]
    assert T.AE.shape == T.AI.shape == T.D.shape == (s, s)
    assert np.all(np.triu(T.AE) == 0.0) and np.all(np.triu(T.AI, 1) == 0.0)
    assert T.AI[0, 0] == 0.0 and np.all(np.diag(T.AI)[1:] == T.gamma)
    assert np.array_equal(T.AI[-1], T.b)                       # stiffly accurate
    assert np.array_equal(T.D, T.AI - T.AE)
    assert np.allclose(T.AE.sum(axis=1), T.c, atol=1e-15) and np.allclose(T.AI.sum(axis=1), T.c, atol=1e-15)
    assert T.expo == -1.0 / (tab.embedded_order + 1)


@pytest.mark.parametrize("tab", TABLES, ids=lambda t: t.name)
def test_every_condition_holds_to_rounding(tab):
    conds = tab.conditions()
    worst = max(abs(c.residual) for c in conds)
    assert worst < 1e-13
    kinds = [c.label.split(" order")[0] for c in conds]
    classical = {"ark436l2sa": 7, "ark548l2sa": 16}[tab.name]   # the trees of order 2 .. p
    assert kinds.count("b: explicit") == kinds.count("b: implicit") == classical
    assert kinds.count("b: coupling") == {"ark436l2sa": 3 + 18, "ark548l2sa": 3 + 18 + 89}[tab.name]


def _replace_entry(rows, i, j, text):
    rows = [list(r) for r in rows]
    rows[i][j] = text
    return tuple(tuple(r) for r in rows)


def test_a_wrong_digit_fails_its_row_sum():
    ae = _replace_entry(ARK436L2SA.ae, 3, 1, "-2731218467317/15368042101831".replace("731", "732", 1))
    with pytest.raises(ValueError, match=r"ark436l2sa: fails the condition row sum AE\[3\] = c\[3\]"):
        dataclasses.replace(ARK436L2SA, ae=ae)


def test_a_shift_within_a_row_fails_an_order_condition():
    """AE[4][0] up, AE[4][2] down by 1e-9: the row sums hold, the trees through stage 4 do not."""
    delta = Fraction(1, 10**9)
    ae = _replace_entry(ARK548L2SA.ae, 4, 0, str(Fraction(ARK548L2SA.ae[4][0]) + delta))
    ae = _replace_entry(ae, 4, 2, str(Fraction(ARK548L2SA.ae[4][2]) - delta))
    with pytest.raises(ValueError, match=r"ark548l2sa: fails the condition b: \w+ order 3 tree"):
        dataclasses.replace(ARK548L2SA, ae=ae)


def test_wrong_weights_and_structure_are_named():
    b_hat = list(ARK436L2SA.b_hat)
    b_hat[5] = "61728/225920"
    with pytest.raises(ValueError, match=r"b_hat: order 1 sum b_hat_i = 1"):
        dataclasses.replace(ARK436L2SA, b_hat=tuple(b_hat))
    b = list(ARK436L2SA.b)
    b[2] = "15626/83664"
    with pytest.raises(ValueError, match=r"stiffly accurate \(last row of AI = b\)"):
        dataclasses.replace(ARK436L2SA, b=tuple(b))
    ai = _replace_entry(ARK436L2SA.ai, 2, 2, "1/5")
    with pytest.raises(ValueError, match=r"AI\[2\]\[2\] = gamma"):
        dataclasses.replace(ARK436L2SA, ai=ai)
    ae = ARK436L2SA.ae[:2] + (ARK436L2SA.ae[2] + ("0",),) + ARK436L2SA.ae[3:]
    with pytest.raises(ValueError, match=r"ark436l2sa: row 2 has 3 entries, expected 2"):
        dataclasses.replace(ARK436L2SA, ae=ae)


# --- The linearised splitting in plain numpy ----------------------------------------------------
# p' = q, q' = -sin p + z / 2, z' = k (p - z): the linear part A (one eigenvalue near -k) is J and
# goes to the ESDIRK, -sin p to the explicit tableau, so every step uses both and the coupling
# conditions count. With k large, z follows p on the slow manifold; h = 0.1 there is hk = 1e5.


def _problem(k):
    J = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 0.5], [k, 0.0, -k]])

    def f(y):
        return J @ y + np.array([0.0, -np.sin(y[0]), 0.0])

    return f, J


def _step(T, f, J, y, h):
    """One step as ArkArrays describes it: (I - h gamma J) Z_i = h sum_{j<i} [AE_ij F_j +
    D_ij J Z_j]; returns y_new and the error estimate."""
    s = len(T.b)
    M = np.eye(len(y)) - h * T.gamma * J
    F, JZ = np.zeros((s, len(y))), np.zeros((s, len(y)))
    F[0] = f(y)
    for i in range(1, s):
        z = np.linalg.solve(M, h * (T.AE[i, :i] @ F[:i] + T.D[i, :i] @ JZ[:i]))
        JZ[i] = J @ z
        F[i] = f(y + z)
    return y + h * (T.b @ F), h * ((T.b - T.b_hat) @ F)


Y0 = (1.0, 0.0, 1.0)


@lru_cache(maxsize=None)
def _run(name, k, n, t_end=2.0):
    T, (f, J) = ARK_TABLEAUS[name].arrays(), _problem(k)
    y = np.array(Y0)
    for _ in range(n):
        y, _ = _step(T, f, J, y, t_end / n)
    return y


@pytest.mark.parametrize("k", [1.0, 1e6], ids=["nonstiff", "stiff"])
@pytest.mark.parametrize("tab", TABLES, ids=lambda t: t.name)
def test_observed_order_on_the_nonstiff_part(tab, k):
    """h = 0.1, 0.05, 0.025 against ARK5(4)8L[2]SA at h = 1/640: the error in (p, q) falls by
    2^4 (ARK4) and 2^5 (ARK5) per halving, with both parts nonstiff (k = 1: the coupling
    conditions decide the order) and at hk up to 1e5. (At k = 5 to 10 ARK5 is not yet at its
    asymptote on these steps: 4.7 to 4.9.)"""
    ref = _run("ark548l2sa", k, 1280)
    errors = [np.abs(_run(tab.name, k, n)[:2] - ref[:2]).max() for n in (20, 40, 80)]
    orders = [np.log2(a / b) for a, b in zip(errors, errors[1:])]
    assert all(abs(o - tab.order) < 0.2 for o in orders), orders


@pytest.mark.parametrize("tab", TABLES, ids=lambda t: t.name)
def test_stable_on_the_stiff_part(tab):
    """hk = 2e5: the stiff component stays on its slow manifold (z = p - q/k + ...), bounded."""
    k = 1e6
    ref = _run("ark548l2sa", k, 1280)
    for n in (10, 20):
        y = _run(tab.name, k, n)
        assert np.all(np.isfinite(y)) and abs(y[2] - ref[2]) < 1e-5 and abs(y[2] - y[0]) < 1e-5


@pytest.mark.parametrize("k", [1.0, 1e6], ids=["nonstiff", "stiff"])
@pytest.mark.parametrize("tab", TABLES, ids=lambda t: t.name)
def test_error_estimate_has_the_embedded_order(tab, k):
    """The estimate of one step falls by 2^(q + 1) per halving (q the embedded order): the
    exponent expo = -1/(q + 1) the step-size control will use."""
    T, (f, J) = tab.arrays(), _problem(k)
    y = np.array([1.0, 0.3, 1.0])
    est = [np.abs(_step(T, f, J, y, h)[1][:2]).max() for h in (0.05, 0.025, 0.0125)]
    for a, b in zip(est, est[1:]):
        assert abs(np.log2(a / b) + 1.0 / T.expo) < 0.2
