"""Linearly implicit Rosenbrock-W methods for the stiff local terms (tables; the time loop
comes with the integrator)."""
