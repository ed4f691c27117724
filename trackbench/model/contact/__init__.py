"""Penalty contacts: the normal-force and friction laws (plain and compiled), the contact
geometry, the wheel-track contacts and their neighbour search."""
