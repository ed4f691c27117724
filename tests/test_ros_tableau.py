"""The Rosenbrock-W table: ROS34PW2 passes every W-method order condition, a wrong digit is
caught and named, and a plain numpy step in the transformed variables (as the compiled loop
takes it) shows the orders the paper claims with the exact Jacobian and with a wrong one (the
W-method property), L-stability, and the order of the dense output the loop uses (the quintic
Hermite interpolant of solvers/common/hermite.py) on a linear test problem."""

import dataclasses

import numpy as np
import pytest

from trackbench.solvers.common.hermite import hermite_second_order, hermite_velocities
from trackbench.solvers.rosenbrock.ros_tableau import ROS34PW2, ROS_TABLEAUS, RosTableau, has_w, w_trees


def test_trees_are_counted_right():
    """Trees with f and W vertices (W with one child): 1, 2, 5, 13 of orders 1-4; the f-trees
    among them are Butcher's 1, 1, 2, 4."""
    assert [len(w_trees(k)) for k in range(1, 5)] == [1, 2, 5, 13]
    assert [sum(not has_w(t) for t in w_trees(k)) for k in range(1, 5)] == [1, 1, 2, 4]


def test_ros34pw2_meets_every_condition():
    assert isinstance(ROS34PW2, RosTableau) and ROS_TABLEAUS["ros34pw2"] is ROS34PW2
    conds = ROS34PW2.conditions()
    assert len(conds) == 8 + 3   # b: orders 1-3 (1 + 2 + 5 trees), b_hat: orders 1-2
    assert max(abs(float(c.residual)) for c in conds) < 1e-15
    assert sum(": order 3 W-tree" in c.label for c in conds) == 3


def test_the_transformed_arrays():
    """Stiffly accurate in the transformed variables: y_new is the last stage's argument plus
    u_4 (m = the last row of A, m_4 = 1); the estimate's weights e = m - m_hat."""
    T = ROS34PW2.arrays()
    assert T.A.shape == T.C.shape == (4, 4) and np.all(np.triu(T.A) == 0) and np.all(np.triu(T.C) == 0)
    assert np.allclose(T.A[-1, :3], T.m[:3], rtol=0, atol=1e-15) and T.m[-1] == 1.0
    assert T.gamma == 0.435866521508459 and T.expo == -1.0 / 3.0


def _replace(rows, i, j, text):
    rows = [list(r) for r in rows]
    rows[i][j] = text
    return tuple(tuple(r) for r in rows)


def test_wrong_digits_are_named():
    b_hat = ROS34PW2.b_hat[:2] + ("5.000000001e-01",) + ROS34PW2.b_hat[3:]
    with pytest.raises(ValueError, match=r"ros34pw2: fails the condition b_hat: order 1 f-tree f = 1"):
        dataclasses.replace(ROS34PW2, b_hat=b_hat)
    # alpha_32 moved and gamma_32 back: alpha + Gamma unchanged, so the conditions of a
    # Rosenbrock method with the exact Jacobian still hold; a W-method's do not
    alpha = _replace(ROS34PW2.alpha, 2, 1, "-1.1199064236484185e-01")
    gam = _replace(ROS34PW2.gamma_ij, 2, 1, "5.3180672388095326e-02")
    with pytest.raises(ValueError, match=r"ros34pw2: fails the condition b: order 2 W-tree W\[f\] = 0"):
        dataclasses.replace(ROS34PW2, alpha=alpha, gamma_ij=gam)
    # alpha_31 and alpha_32 moved against each other: c_3 unchanged, an order-3 f-tree fails
    alpha = _replace(ROS34PW2.alpha, 2, 0, "8.4557060015369423e-01")
    alpha = _replace(alpha, 2, 1, "-1.1399064236484185e-01")
    with pytest.raises(ValueError, match=r"ros34pw2: fails the condition b: order 3 \w-tree"):
        dataclasses.replace(ROS34PW2, alpha=alpha)
    b = ROS34PW2.b[:2] + ("1.5452602563351020e+00",) + ROS34PW2.b[3:]
    with pytest.raises(ValueError, match=r"stiffly accurate"):
        dataclasses.replace(ROS34PW2, b=b)
    with pytest.raises(ValueError, match=r"row 2 of alpha has 3 entries, expected 2"):
        dataclasses.replace(ROS34PW2, alpha=ROS34PW2.alpha[:2] + (ROS34PW2.alpha[2] + ("0",),)
                            + ROS34PW2.alpha[3:])


def test_l_stable():
    """|R(iy)| <= 1 on the imaginary axis (A-stable) and R(z) -> 0 as z -> -inf."""
    ys = np.logspace(-3, 6, 200)
    assert max(abs(ROS34PW2.stability(1j * y)) for y in ys) <= 1.0 + 1e-12
    assert abs(ROS34PW2.stability(-1e12)) < 1e-10 and abs(ROS34PW2.stability(-1e6)) < 1e-4


# --- One step in plain numpy, as the compiled loop takes it -------------------------------------
# p' = q, q' = -sin p + z / 2, z' = k (p - z): nonlinear, with a stiff linear part for k large.


def _problem(k):
    def f(y):
        return np.array([y[1], -np.sin(y[0]) + 0.5 * y[2], k * (y[0] - y[2])])

    def jac(y):
        return np.array([[0.0, 1.0, 0.0], [-np.cos(y[0]), 0.0, 0.5], [k, 0.0, -k]])

    return f, jac


def ros_step(T, f, W, y, h):
    """(I / (h gamma) - W) u_i = f(y + sum A_ij u_j) + sum C_ij u_j / h; y_new, the estimate."""
    s = len(T.m)
    M = np.eye(len(y)) / (h * T.gamma) - W
    U = np.zeros((s, len(y)))
    for i in range(s):
        U[i] = np.linalg.solve(M, f(y + T.A[i, :i] @ U[:i]) + T.C[i, :i] @ U[:i] / h)
    return y + T.m @ U, T.e @ U


def _run(k, n, w_of, t_end=2.0):
    T, (f, jac) = ROS34PW2.arrays(), _problem(k)
    y = np.array([1.0, 0.0, 1.0])
    for _ in range(n):
        y, _ = ros_step(T, f, w_of(jac, y), y, t_end / n)
    return y


W_CHOICES = {
    "exact": lambda jac, y: jac(y),
    "stiff part only": lambda jac, y: np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                                                [jac(y)[2, 0], 0.0, jac(y)[2, 2]]]),
    "half": lambda jac, y: 0.5 * jac(y),
}


@pytest.mark.parametrize("which", W_CHOICES)
def test_order_3_whatever_w(which):
    """Non-stiff (k = 1), the error in (p, q) falls by 2^3 per halving of h with the exact
    Jacobian, with only the stiff block (the pins' blocks' kind of W) and with half of it."""
    exact = _run(1.0, 2560, W_CHOICES["exact"])
    errors = [np.abs(_run(1.0, n, W_CHOICES[which])[:2] - exact[:2]).max() for n in (20, 40, 80)]
    orders = [np.log2(a / b) for a, b in zip(errors, errors[1:])]
    assert all(abs(o - 3.0) < 0.25 for o in orders), orders


def test_stable_on_the_stiff_part_with_its_block():
    """hk = 1e5 with W the stiff block alone: bounded, on the slow manifold z = p."""
    for n in (10, 20):
        y = _run(1e6, n, W_CHOICES["stiff part only"])
        assert np.all(np.isfinite(y)) and abs(y[2] - y[0]) < 1e-5


def test_the_estimate_has_the_embedded_order():
    """One step's estimate falls by 2^3 per halving (embedded order 2): expo = -1/3."""
    T, (f, jac) = ROS34PW2.arrays(), _problem(1.0)
    y = np.array([1.0, 0.3, 1.0])
    est = [np.abs(ros_step(T, f, 0.5 * jac(y), y, h)[1][:2]).max() for h in (0.05, 0.025, 0.0125)]
    for a, b in zip(est, est[1:]):
        assert abs(np.log2(a / b) - 3.0) < 0.2


def _dense(y0, y1, J, h, theta, cubic):
    out = np.empty(2)
    hermite_second_order(y0, J @ y0, y1, J @ y1, h, theta, 1, out)
    if cubic:
        hermite_velocities(y0, J @ y0, y1, J @ y1, h, theta, 1, out)
    return out


def _dense_orders(W, cubic):
    """On q'' = -w^2 q - 2 zeta w q', one ROS34PW2 step from the exact start: log2 of the
    error's fall per halving of h inside the step (theta = 1/4, 1/2, 3/4), for q and qd."""
    w0, zeta = 2.0, 0.1
    J = np.array([[0.0, 1.0], [-w0**2, -2 * zeta * w0]])
    lam, V = np.linalg.eig(J)
    y0 = np.array([1.0, 0.5])

    def exact(t):
        return (V @ (np.exp(lam * t) * np.linalg.solve(V, y0))).real

    T = ROS34PW2.arrays()
    errs = []
    for h in (0.025, 0.0125, 0.00625):   # the velocities' asymptote comes from above (4.5 at 0.1)
        y1, _ = ros_step(T, lambda y: J @ y, W(J), y0, h)
        err = [np.abs(_dense(y0, y1, J, h, th, cubic) - exact(th * h)) for th in (0.25, 0.5, 0.75)]
        errs.append(np.max(err, axis=0))
    return np.log2(np.array(errs[:-1]) / np.array(errs[1:]))


@pytest.mark.parametrize("W", [lambda J: J, lambda J: 0.5 * J], ids=["W = J", "W = J / 2"])
def test_dense_output_is_of_order_3(W):
    """The loop's samples (stepping.dense_state): positions by the quintic Hermite interpolant
    through (q, qd, qdd) at both ends of the step (hermite.py, as the explicit pairs'), velocities
    by the cubic Hermite through (qd, qdd): local errors O(h^4), the fall 2^4 per halving, of the
    method's order 3 both. The quintic's own derivative would leave the velocities at O(h^3):
    its (q1 - q0) / h divides the end's O(h^4) error by h."""
    orders = _dense_orders(W, cubic=True)
    assert np.all(np.abs(orders - 4.0) < 0.3), orders
    derivative = _dense_orders(W, cubic=False)
    assert np.all(np.abs(derivative[:, 0] - 4.0) < 0.3) and np.all(np.abs(derivative[:, 1] - 3.0) < 0.3)
