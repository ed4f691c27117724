"""Additive Runge-Kutta (IMEX) methods: validated tables of Kennedy & Carpenter's pairs."""
