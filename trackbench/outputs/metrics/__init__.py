"""Figures derived from a run's time histories: ride.py (the driver's seat), traction.py (the
drawbar test)."""
