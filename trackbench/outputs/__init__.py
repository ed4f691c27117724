"""The outputs layer: what a run's arrays become. dataset.py (the xarray.Dataset,
results_schema.md) with closed.py and variables.py, quantities.py (the summary quantities in
one table), metrics/ (the driver's seat, traction), files/ (netCDF, atomic writes), recording/
(the rerun recording) and geometry.py (what a recording and a figure draw)."""
