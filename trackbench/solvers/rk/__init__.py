"""Embedded explicit Runge-Kutta pairs (DOPRI5, DOP853) on the reduced coordinates."""
