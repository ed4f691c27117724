"""The Dataset's variables: one constructor (units and long name on every variable,
results_schema.md), the dimension tuples, and its JSON attributes read back (the run's
scenario among them)."""

import json

import numpy as np

T, WH, P, K = ("time",), ("time", "wheel"), ("time", "pin"), ("time", "link")


def var(dims, data, units, long_name, **attrs):
    import xarray as xr  # here: reading a run's attributes (scenario_of) needs no xarray
    return xr.Variable(dims, np.asarray(data), {"units": units, "long_name": long_name, **attrs})


def attr_json(ds, name):
    """A JSON attribute of a run's Dataset (written as text, as netCDF keeps it) as Python values."""
    v = ds.attrs[name]
    return json.loads(v) if isinstance(v, (str, bytes)) else v


def scenario_of(ds):
    """The run's resolved scenario as a dict (attrs["scenario"])."""
    return attr_json(ds, "scenario")
