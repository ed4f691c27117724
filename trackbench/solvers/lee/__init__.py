"""The paper's method: absolute coordinates, Lee's accelerated iteration for the
Lagrange multipliers, a Runge-Kutta-Nystrom pair."""
