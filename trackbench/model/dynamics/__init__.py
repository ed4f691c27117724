"""Equations of motion (reduced and absolute coordinates, the closed track), the
right-hand side, the energy, and the static equilibrium's equations."""
