"""Dense output of a step of a second-order system, written once: the quintic Hermite
interpolant through (q, qd, qdd) at both ends of the step (positions), its derivative
(velocities) and the cubic Hermite for first-order components (the contact work); for a
method of order 3, the cubic Hermite through (qd, qdd) for the velocities instead."""

from numba import njit

from ...model.core.jit import BORROW, INLINE


@njit(**INLINE)
def quintic_basis(t):
    """Weights of (q0, h v0, h^2 a0, q1, h v1, h^2 a1) at t in [0, 1]."""
    t2 = t * t
    t3 = t2 * t
    t4 = t3 * t
    t5 = t4 * t
    return (1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5, t - 6.0 * t3 + 8.0 * t4 - 3.0 * t5,
            0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5, 10.0 * t3 - 15.0 * t4 + 6.0 * t5,
            -4.0 * t3 + 7.0 * t4 - 3.0 * t5, 0.5 * t3 - t4 + 0.5 * t5)


@njit(**INLINE)
def quintic(w, h, q0, v0, a0, q1, v1, a1):
    """The interpolant with weights w = quintic_basis(t)."""
    h00, h10, h20, h01, h11, h21 = w
    return h00 * q0 + h * h10 * v0 + h * h * h20 * a0 + h01 * q1 + h * h11 * v1 + h * h * h21 * a1


@njit(**INLINE)
def coordinate(w, step, k, nq):
    """Coordinate k of y = (q, qd, ...) along a step = (y0, f0, y1, f1, h), f = dy/dt."""
    y0, f0, y1, f1, h = step
    return quintic(w, h, y0[k], y0[nq + k], f0[nq + k], y1[k], y1[nq + k], f1[nq + k])


@njit(**BORROW)
def hermite_second_order(y0, f0, y1, f1, h, theta, nq, out):
    """State at t0 + theta h from (q, qd, qdd) at both ends of a step of a second-order
    system stored as y = (q, qd, extra): quintic Hermite for q, its derivative for qd,
    cubic Hermite for the extra first-order components."""
    t = theta
    t2 = t * t
    t3 = t2 * t
    t4 = t3 * t
    w = quintic_basis(t)
    d00 = (-30.0 * t2 + 60.0 * t3 - 30.0 * t4) / h
    d10 = 1.0 - 18.0 * t2 + 32.0 * t3 - 15.0 * t4
    d20 = h * (t - 4.5 * t2 + 6.0 * t3 - 2.5 * t4)
    d11 = -12.0 * t2 + 28.0 * t3 - 15.0 * t4
    d21 = h * (1.5 * t2 - 4.0 * t3 + 2.5 * t4)
    for k in range(nq):
        q0 = y0[k]
        v0 = y0[nq + k]
        a0 = f0[nq + k]
        q1 = y1[k]
        v1 = y1[nq + k]
        a1 = f1[nq + k]
        out[k] = quintic(w, h, q0, v0, a0, q1, v1, a1)
        out[nq + k] = d00 * q0 + d10 * v0 + d20 * a0 - d00 * q1 + d11 * v1 + d21 * a1
    c00 = 2.0 * t3 - 3.0 * t2 + 1.0
    c10 = t3 - 2.0 * t2 + t
    c01 = -2.0 * t3 + 3.0 * t2
    c11 = t3 - t2
    for k in range(2 * nq, y0.shape[0]):
        out[k] = c00 * y0[k] + h * c10 * f0[k] + c01 * y1[k] + h * c11 * f1[k]


@njit(**BORROW)
def hermite_velocities(y0, f0, y1, f1, h, theta, nq, out):
    """The velocities qd at t0 + theta h by the cubic Hermite interpolant through (qd, qdd) at
    both ends, into out[nq:2 nq]: for a method of order 3 (the Rosenbrock-W loop's samples).
    The derivative of the quintic (hermite_second_order) takes (q1 - q0) / h, whose end error
    h^4 / h leaves velocities of order 2 between the ends of such a step; this one is of
    order 3 (tests/test_ros_tableau.py). Positions stay the quintic's."""
    t = theta
    t2 = t * t
    t3 = t2 * t
    c00 = 2.0 * t3 - 3.0 * t2 + 1.0
    c10 = t3 - 2.0 * t2 + t
    c01 = -2.0 * t3 + 3.0 * t2
    c11 = t3 - t2
    for k in range(nq, 2 * nq):
        out[k] = c00 * y0[k] + h * c10 * f0[k] + c01 * y1[k] + h * c11 * f1[k]
