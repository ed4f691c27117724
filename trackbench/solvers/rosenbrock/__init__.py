"""Linearly implicit Rosenbrock-W methods with the pins' block Jacobian."""
