"""The Rosenbrock-W table: ROS34PW2 passes its order conditions, a wrong digit is caught, and a
plain numpy step in the transformed variables shows the orders the paper claims, with the exact
Jacobian and with a wrong one (the W-method property), and L-stability."""

import dataclasses
import math

import numpy as np
import pytest

from trackbench.solvers.rosenbrock.ros_tableau import ROS34PW2, ROSENBROCK_TABLEAUS, RosenbrockTableau


def _run(lam, jac, h, t_end, weights="m"):
    """y' = lam y, y(0) = 1, fixed steps of the transformed form; jac is the Jacobian used."""
    T = ROS34PW2.arrays()
    w = T.m if weights == "m" else T.m_hat
    y = 1.0
    for _ in range(round(t_end / h)):
        u = np.zeros(len(w))
        for i in range(len(w)):
            rhs = lam * (y + T.A[i, :i] @ u[:i]) + T.C[i, :i] @ u[:i] / h
            u[i] = rhs / (1.0 / (h * T.gamma) - jac)
        y = y + w @ u
    return y


def _ratios(jac_factor, weights):
    errors = [abs(_run(-1.0, -jac_factor, h, 1.0, weights) - math.exp(-1.0)) for h in (0.1, 0.05, 0.025)]
    return [errors[0] / errors[1], errors[1] / errors[2]]


def test_ros34pw2_validates():
    assert isinstance(ROS34PW2, RosenbrockTableau) and ROSENBROCK_TABLEAUS["ros34pw2"] is ROS34PW2
    assert ROS34PW2.stages == 4 and ROS34PW2.stiffly_accurate
    T = ROS34PW2.arrays()
    assert T.c[-1] == 1.0 and abs(T.gamma_i[-1]) < 1e-15
    assert np.allclose(T.A[-1, :3], T.m[:3]) and T.m[-1] == 1.0  # stiffly accurate, transformed


def test_a_wrong_weight_names_the_condition():
    b = list(ROS34PW2.b)
    b[1] += 1e-3
    with pytest.raises(ValueError, match=r"b fails the condition order 1: sum b_i = 1"):
        dataclasses.replace(ROS34PW2, b=tuple(b))


def test_a_wrong_alpha_fails_an_order_3_condition():
    """alpha_31 moved, gamma_31 moved back: beta (orders 1, 2) unchanged, c_3 wrong."""
    alpha, off = list(ROS34PW2.alpha), list(ROS34PW2.gamma_ij)
    alpha[2] = (alpha[2][0] + 1e-3, alpha[2][1])
    off[2] = (off[2][0] - 1e-3, off[2][1])
    with pytest.raises(ValueError, match=r"b fails the condition order 3: sum b_i alpha_ij alpha_ik = 1/3"):
        dataclasses.replace(ROS34PW2, alpha=tuple(alpha), gamma_ij=tuple(off))


@pytest.mark.parametrize("jac_factor", [1.0, 0.5])
def test_orders_with_exact_and_approximate_jacobian(jac_factor):
    """Order 3 with the exact Jacobian and with J_approx = 0.5 J (a W-method of order 3, the
    paper's claim); the embedded solution order 2 either way."""
    for r in _ratios(jac_factor, "m"):
        assert 6.0 <= r <= 10.0
    for r in _ratios(jac_factor, "m_hat"):
        assert 3.0 <= r <= 5.5


def test_l_stable_on_a_stiff_decay():
    y = _run(-1e6, -1e6, 0.1, 1.0)
    assert abs(y) < 1e-12
