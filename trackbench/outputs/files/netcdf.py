"""The one netCDF writer: a run's Dataset to its netCDF-4 file, whole (write_netcdf) or chunk
by chunk as a long run goes (Appender), each variable laid out as storage.py says ("full":
lossless, zstd; "compact": time histories at a stated resolution)."""

from pathlib import Path

import numpy as np

from trackbench.outputs.files.atomic import atomic_path
from trackbench.outputs.files.storage import COMPACT_CODEC, FULL_CODEC, check_storage, layout


def _add_variable(f, name, var, storage, chunks=None):
    """Create ``var`` in the open file ``f`` as storage.layout lays it out; returns (the netCDF
    variable, the data to write)."""
    dtype, fill, extra, data, kw = layout(name, var, storage)
    if var.ndim and name not in var.dims:   # a coordinate stays as it is: no codec
        kw.update(COMPACT_CODEC if storage == "compact" else FULL_CODEC)
    v = f.createVariable(name, dtype, var.dims, fill_value=False if fill is None else fill,
                         chunksizes=chunks, **kw)
    v.set_auto_maskandscale(False)   # the data are written as prepared here
    v.setncatts({**var.attrs, **extra})
    return v, data


def _write(ds, path, storage):
    """Write ``ds`` to ``path`` (not atomically: write_netcdf is, and it empties a temporary
    file that failed: netCDF keeps a file open whose closing failed, e.g. on a full disk, and
    its space would stay taken)."""
    import netCDF4
    f = netCDF4.Dataset(path, "w", format="NETCDF4")
    try:
        for dim, n in ds.sizes.items():
            f.createDimension(dim, n)
        for name, var in ds.variables.items():
            v, data = _add_variable(f, name, var, storage)
            v[...] = data
        f.setncatts({**ds.attrs, "storage": storage})
    finally:
        f.close()
    return path


def write_netcdf(ds, path, storage="full"):
    """Write ``ds`` to ``path`` whole or not at all (atomic.py), stored as ``storage`` says."""
    check_storage(storage)
    path = Path(path)
    with atomic_path(path) as tmp:
        _write(ds, tmp, storage)
    return path


class Appender:
    """A run's time histories appended to a netCDF-4 file chunk by chunk (an unlimited time
    dimension), the rest at the end: laid out as write_netcdf lays out the run in full."""

    def __init__(self, path, chunk_rows):
        import netCDF4
        self.f = netCDF4.Dataset(path, "w", format="NETCDF4")
        self.n = 0
        self.chunk_rows = chunk_rows

    def _create(self, ds, names):
        self.f.createDimension("time", None)
        for dim, size in ds.sizes.items():
            if dim != "time":
                self.f.createDimension(dim, size)
        for name in names:
            var = ds.variables[name]
            chunks = [self.chunk_rows if d == "time" else ds.sizes[d] for d in var.dims]
            v, _ = _add_variable(self.f, name, var, "full", chunks)
            # HDF5's cache (64 MB a variable by default) kept every chunk written: two chunks
            # suffice, the one being filled and the one before it (a chunk of samples from
            # the solver may end short of a chunk of the file)
            v.set_var_chunk_cache(size=2 * int(np.prod(chunks)) * v.dtype.itemsize, nelems=11,
                                  preemption=1.0)

    def append(self, ds):
        names = [k for k, v in ds.variables.items() if "time" in v.dims]
        if self.n == 0:
            self._create(ds, names)
        n = ds.sizes["time"]
        for name in names:
            self.f.variables[name][self.n:self.n + n] = np.asarray(ds.variables[name].values)
        self.n += n

    def finish(self, ds):
        """The variables without a time dimension, and the run's attributes; closes the file."""
        for name, var in ds.variables.items():
            if "time" not in var.dims:
                v, data = _add_variable(self.f, name, var, "full")
                v[...] = data
        self.f.setncatts({**ds.attrs, "storage": "full"})
        self.close()

    def close(self):
        if self.f is not None and self.f.isopen():
            self.f.close()
