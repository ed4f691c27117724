"""A study's runs as one lazy Dataset along ``run``, built from the files' headers alone.

xarray.open_mfdataset decodes every file and concatenates the runs variable by variable:
on a 1,000-run study it took 150 s before the first value was read. Here each file is
opened once with netCDF4 for its dimensions, its time coordinate and its attributes
(about 3 ms), and every variable becomes a lazily indexed array (xarray's backend array)
that opens, when a selection is read, only the files of the runs it selects. With dask
installed the Dataset is chunked one run to a chunk, as open_mfdataset's was.

It takes the runs as they are in a study: the same variables, dimensions and attributes, and
each run's time a prefix of the longest one's (a shorter run, one that stopped or was shorter,
is NaN-padded at the end: what xarray's outer join gives). Files that do not line up so (a
grid over the number of links, different output intervals) return None: the caller falls
back to open_mfdataset.
"""

import threading

import numpy as np

# attributes that make xarray decode a variable's values: such a file is left to xarray
_DECODED = {"scale_factor", "add_offset", "missing_value", "calendar", "flag_values"}
_LOCK = threading.Lock()   # HDF5 reads from dask's threads, one at a time (see _lock)


def _lock():
    """xarray's own HDF5 lock where it has one: reads of this module and of xarray in other
    threads then never overlap in HDF5 (not thread-safe by default); else a lock of its own."""
    try:
        from xarray.backends.locks import HDF5_LOCK
        return HDF5_LOCK
    except ImportError:
        return _LOCK


def _header(path):
    """(dimension sizes, time values, global attributes, {variable: (dims, dtype, attribute
    names)}): what is read of each run's file when the dataset is opened."""
    import netCDF4
    with _lock(), netCDF4.Dataset(path) as f:
        dims = {k: len(d) for k, d in f.dimensions.items()}
        time = np.ma.filled(f["time"][:], np.nan) if "time" in f.variables else None
        attrs = {k: f.getncattr(k) for k in f.ncattrs()}
        vars_ = {n: (v.dimensions, v.dtype, set(v.ncattrs())) for n, v in f.variables.items()}
    return dims, time, attrs, vars_


def _lines_up(heads, longest):
    """Do all runs' files have the longest one's variables, dimensions (time excepted) and a
    time coordinate that is a prefix of its own, with no value xarray would decode?"""
    dims0, time0, _, vars0 = heads[longest]
    if time0 is None or any(_DECODED & set(a) for _, _, a in vars0.values()):
        return False
    for dims, time, _, vars_ in heads:
        if {k: n for k, n in dims.items() if k != "time"} != {k: n for k, n in dims0.items() if k != "time"}:
            return False
        if {n: (d, t) for n, (d, t, _) in vars_.items()} != {n: (d, t) for n, (d, t, _) in vars0.items()}:
            return False
        if not np.array_equal(time, time0[:time.size]):
            return False
    # a shorter run is NaN-padded along time: only floating-point variables can hold that
    return all(t.kind == "f" or "time" not in d for n, (d, t, _) in vars0.items())


def _same(a, b):
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(np.asarray(a), np.asarray(b))
    return type(a) is type(b) and a == b


def _common_attrs(all_attrs):
    """xarray's combine_attrs="drop_conflicts": every attribute whose values agree."""
    out, dropped = {}, set()
    for attrs in all_attrs:
        for k, v in attrs.items():
            if k in dropped:
                continue
            if k in out and not _same(out[k], v):
                del out[k]
                dropped.add(k)
            elif k not in out:
                out[k] = v
    return out


def _runs_array():
    """The backend array class (xarray loads only when a study's dataset is opened)."""
    from xarray.backends import BackendArray
    from xarray.core import indexing

    class RunsArray(BackendArray):
        """One variable of every run, shape (run, *the variable's), read file by file."""

        def __init__(self, paths, name, shape, dtype, time_axis):
            self.paths, self.name, self.shape, self.dtype = paths, name, shape, dtype
            self.time_axis = time_axis

        def __getitem__(self, key):
            return indexing.explicit_indexing_adapter(key, self.shape, indexing.IndexingSupport.BASIC,
                                                      self._read)

        def _read(self, key):
            runs = np.arange(self.shape[0])[key[0]]
            if runs.ndim == 0:
                return self._one(int(runs))[key[1:]]
            if runs.size == 0:
                return np.empty((0,) + np.empty(self.shape[1:])[key[1:]].shape, self.dtype)
            return np.stack([self._one(int(r))[key[1:]] for r in runs])

        def _one(self, r):
            import netCDF4
            with _lock(), netCDF4.Dataset(self.paths[r]) as f:
                data = f[self.name][:]
            data = np.ma.filled(data, np.nan) if self.dtype.kind == "f" else np.asarray(data)
            short = self.shape[1:][self.time_axis] - data.shape[self.time_axis] if self.time_axis >= 0 else 0
            if short:
                pad = [(0, 0)] * data.ndim
                pad[self.time_axis] = (0, short)
                data = np.pad(data, pad, constant_values=np.nan)
            return data

    return RunsArray


def open_stacked(paths, chunk=True):
    """The runs' files along ``run`` as a lazy Dataset, or None when they do not line up (see
    the module's docstring). chunk: one dask chunk per run where dask is installed."""
    import xarray as xr
    from xarray.core import indexing

    heads = [_header(p) for p in paths]
    longest = max(range(len(heads)), key=lambda i: heads[i][1].size if heads[i][1] is not None else -1)
    if not _lines_up(heads, longest):
        return None
    template = xr.open_dataset(paths[longest], cache=False)
    RunsArray = _runs_array()
    data_vars = {}
    for name, v in template.data_vars.items():
        axis = v.dims.index("time") if "time" in v.dims else -1
        arr = RunsArray([str(p) for p in paths], name, (len(paths),) + v.shape, v.dtype, axis)
        data_vars[name] = xr.Variable(("run",) + v.dims, indexing.LazilyIndexedArray(arr), v.attrs)
    coords = {k: c.variable.load() for k, c in template.coords.items()}
    template.close()
    ds = xr.Dataset(data_vars, coords=coords, attrs=_common_attrs(h[2] for h in heads))
    if chunk:
        ds = ds.chunk({"run": 1})
    return ds
