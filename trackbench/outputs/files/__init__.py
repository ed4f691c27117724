"""Files written whole or not at all (atomic.py) and how a run's Dataset is stored (storage.py:
the one netCDF writer, full or compact)."""
