"""How a run's files are stored: ``full`` (the default, lossless) or ``compact``.

full     every variable as computed (float64), compressed losslessly: zstd level 1 with the
         byte shuffle (reads back bit for bit; chosen by measurement, docs/benchmarks.md)
compact  the time histories (variables along ``time``) at a stated resolution, see
         RESOLUTION and results_schema.md: positions packed to 0.1 um (CF scale_factor /
         add_offset on int32; xarray decodes them to float64), everything else float32
         rounded to 16 significant bits (netCDF's BitRound: relative error <= 2**-17 plus the
         float32 rounding, 7.7e-6: 5 significant digits); zlib level 1 with the shuffle.
         The time coordinate, the peaks and the first-contact times stay float64, and the
         summary and run.json are computed from the full-precision run before it is written.
         The recording is thinned: side view every COMPACT_FRAME_EVERY-th sample at most,
         time series every COMPACT_SIGNAL_EVERY-th sample.

The netCDF file is written with netCDF4 directly (xarray's to_netcdf spent about a third of
the write on encoding checks); xarray reads it as it read the files before.
"""


import numpy as np

STORAGES = ("full", "compact")
FULL_CODEC = {"compression": "zstd", "complevel": 1, "shuffle": True}
COMPACT_CODEC = {"compression": "zlib", "complevel": 1, "shuffle": True}
POSITIONS = ("chassis_x", "chassis_y", "wheel_x", "wheel_y", "pin_x", "pin_y")
POSITION_STEP = 1e-7          # m: compact positions are multiples of this (error <= 0.05 um)
PACKED_FILL = np.int32(-2**31)  # a NaN position (a run that stopped early) in the packed int32
COMPACT_FRAME_EVERY = 40      # compact recordings: the side view at every 40th sample at most
COMPACT_SIGNAL_EVERY = 10     # ... and the time series at every 10th (and the last)
# the resolution of a compact time history, by kind (results_schema.md says it per variable)
SIGNIFICANT_BITS = 16         # compact float32 histories keep 16 significant bits
RELATIVE_ERROR = 2.0 ** -(SIGNIFICANT_BITS + 1) + 2.0**-24  # the rounding to 16 bits and to float32: 7.7e-6
RESOLUTION = {"position": f"{POSITION_STEP * 1e6:g} um (packed int32)",
              "other": f"{SIGNIFICANT_BITS} significant bits (relative error <= {RELATIVE_ERROR:.1e})"}


def check_storage(value, where="--storage"):
    """``value`` when it is a storage name, else ValueError (one line naming it)."""
    if value not in STORAGES:
        raise ValueError(f"{where} {value!r} is not allowed: expected {' or '.join(STORAGES)}")
    return value


def frame_step(record, output_interval):
    """Output samples per side-view frame: record.every, or 0 there for frames at record.fps,
    the nearest whole number of samples (at least 1): every frame is a sample of the dense
    output, none an interpolation between samples."""
    every = int(record.get("every", 1))
    if every > 0:
        return every
    return max(1, round(1.0 / (float(record.get("fps", 50.0)) * float(output_interval))))


def recording_steps(every, storage="full"):
    """(side-view frame step, time-series step) of a recording: compact storage thins both,
    full keeps the scenario's record.every and every sample of the time series."""
    if storage == "compact":
        return max(int(every), COMPACT_FRAME_EVERY), COMPACT_SIGNAL_EVERY
    return int(every), 1


def is_history(name, var):
    """A time history (stored at reduced resolution by compact): along time, not the coordinate."""
    return "time" in var.dims and name != "time"


def packed(values):
    """(int32 array, add_offset) of positions ``values`` in steps of POSITION_STEP around
    their mid-range; None when they do not fit in int32 (then they are stored as float64)."""
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return None
    lo, hi = float(finite.min()), float(finite.max())
    offset = float(np.round((lo + hi) / 2 / POSITION_STEP) * POSITION_STEP)
    if (hi - lo) / POSITION_STEP / 2 + 2 > 2**31 - 2:
        return None
    steps = np.round((values - offset) / POSITION_STEP)
    out = np.where(np.isfinite(steps), steps, PACKED_FILL).astype(np.int32)
    return out, offset


def layout(name, var, storage):
    """(dtype, fill value or None, extra attributes, data, extra createVariable arguments) of
    one variable in the file."""
    data = np.asarray(var.values)
    if data.dtype.kind not in "fiu":
        raise TypeError(f"variable {name} of dtype {data.dtype} cannot be written to netCDF here")
    if name in var.dims:   # a coordinate: as it is, no fill value (as xarray writes it)
        return data.dtype, None, {}, data, {}
    fill = np.nan if data.dtype.kind == "f" else None
    if storage != "compact" or not is_history(name, var) or data.dtype.kind != "f":
        return data.dtype, fill, {}, data, {}
    if name in POSITIONS:
        p = packed(data)
        if p is not None:
            return np.dtype(np.int32), PACKED_FILL, {"scale_factor": POSITION_STEP, "add_offset": p[1],
                                                      "resolution": RESOLUTION["position"]}, p[0], {}
        return data.dtype, fill, {}, data, {}
    return (
        np.dtype(np.float32),
        np.float32(np.nan),
        {"resolution": RESOLUTION["other"]},
        data.astype(np.float32),
        {"significant_digits": SIGNIFICANT_BITS, "quantize_mode": "BitRound"},
    )
