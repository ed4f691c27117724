"""The Dataset's variables: one constructor (units and long name on every variable,
results_schema.md) and the dimension tuples."""

import numpy as np
import xarray as xr

T, WH, P, K = ("time",), ("time", "wheel"), ("time", "pin"), ("time", "link")


def var(dims, data, units, long_name, **attrs):
    return xr.Variable(dims, np.asarray(data), {"units": units, "long_name": long_name, **attrs})
