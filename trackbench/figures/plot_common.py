"""What the run and study figures share: matplotlib's lazy import, finding and loading a run,
the words and units of parameters and values (axis labels, run titles). matplotlib is an
optional dependency (extra "plot"); it is imported only when a figure is drawn."""

import json
import textwrap
from pathlib import Path

import numpy as np

from trackbench.outputs import geometry as G

PAPER_TIMES = (0.1, 0.35, 0.45)   # the paper's Figs. 8-10 (a 0.5 s run)
DPI = 130
SOIL_DENT = "#f2dc9b"   # soft soil: the rut, between the original surface and the dent


def _plt():
    try:
        import matplotlib
    except ImportError as e:  # pragma: no cover - depends on the install
        raise ImportError("plotting needs matplotlib: pip install 'trackbench[plot]'") from e
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt
    return plt


def find_timeseries(path):
    """A .nc file, or a run folder holding timeseries.nc (or exactly one .nc) -> the .nc Path."""
    path = Path(path)
    if path.is_file():
        return path
    if path.is_dir():
        if (path / "timeseries.nc").exists():
            return path / "timeseries.nc"
        ncs = sorted(path.glob("*.nc"))
        if len(ncs) == 1:
            return ncs[0]
        if len(ncs) > 1:
            raise FileNotFoundError(
                f"{path} holds several .nc files ({', '.join(p.name for p in ncs)}); give one"
            )
        raise FileNotFoundError(f"{path} holds no timeseries.nc (nor any .nc file)")
    raise FileNotFoundError(f"{path} does not exist")


def load_run(ds_or_path):
    """A Dataset is returned as is; a path (a .nc file or a run folder) is loaded into memory."""
    if hasattr(ds_or_path, "data_vars"):
        return ds_or_path
    import xarray as xr
    path = find_timeseries(ds_or_path)
    try:
        ds = xr.load_dataset(path)
    except (ValueError, OSError) as e:  # xarray's "did not find a match in any of ... IO backends"
        raise ValueError(
            f"{path} is not a netCDF file trackbench can read ({type(e).__name__}); give a run's "
            ".nc file or its folder"
        ) from None
    if "time" not in ds.dims or "scenario" not in ds.attrs:
        raise ValueError(f"{path} is a netCDF file but not a trackbench run (no time dimension or scenario)")
    return ds


def _wheels_to_show(ds):
    """The paper shows wheels 1, 3 and 5; for other vehicles: the first, middle and last."""
    w = [int(x) for x in ds["wheel"].values]
    if {1, 3, 5} <= set(w):
        return [1, 3, 5]
    return sorted({w[0], w[len(w) // 2], w[-1]})


def _name(ds):
    try:
        return G.scenario_of(ds).get("name", "run")
    except (KeyError, ValueError):
        return "run"


def _wrap(text, width=95):
    """Long titles broken into lines (each paragraph on its own)."""
    return "\n".join(textwrap.fill(line, width) for line in text.split("\n"))


# ------------------------------------------------------------ parameters and their units ----

def parameter_unit(name):
    """The unit of a scenario parameter ('' when it has none): scenario.UNITS."""
    from trackbench.scenario import UNITS
    return UNITS.get(name, "")


def display_scale(name, values=()):
    """(factor, unit) a parameter is shown in: slips in %, forces of 10 kN and more in kN,
    torques in kN m; else (1, its unit)."""
    if name.endswith("slip"):
        return 100.0, "%"
    unit = parameter_unit(name)
    big = np.nanmax(np.abs(np.asarray(values, dtype=float))) >= 1e4 if len(values) else False
    if unit in ("N", "N m") and big:
        return 1e-3, "k" + unit
    return 1.0, unit


def axis_label(name, values=()):
    k, unit = display_scale(name, values)
    extra = ", at the sprocket" if name == "drawbar.slip" else ""
    return f"{name} ({unit}{extra})" if unit else name


def _parsed(value):
    if isinstance(value, str) and value[:1] in "{[":
        try:
            return json.loads(value)
        except ValueError:
            return value
    return value


def terrain_label(t):
    """A short name of a terrain table: kind, height (and length), soil."""
    if not isinstance(t, dict):
        return str(t)
    kind = t.get("kind", "terrain")
    if kind == "sequence":
        text = " + ".join(terrain_label(o) for o in t.get("obstacles", []))[:60] or "sequence"
    elif kind == "points":
        text = f"points ({len(t.get('points', []))})"
    else:
        text = kind
        if "height" in t or "radius" in t:
            text += f" {float(t.get('height', t.get('radius'))):g} m"
        if "length" in t:
            text += f" x {float(t['length']):g} m"
    soil = t.get("soil")
    if soil not in (None, "rigid"):
        text += f", {soil if isinstance(soil, str) else 'soil table'}"
    return text


def value_label(name, value):
    """A parameter's value for a title, a legend or a tick: '12.5 m/s', 'bump 0.1 m x 0.6 m'."""
    v = _parsed(value)
    if isinstance(v, dict):
        return terrain_label(v)
    if isinstance(v, (list, tuple)):
        return json.dumps(v, separators=(",", ":"))[:30]
    if isinstance(v, (bool, np.bool_)) or isinstance(v, str):
        return str(v)
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    k, unit = display_scale(name, [x])
    return f"{x * k:g} {unit}".strip()


def run_label(ds, path=None):
    """What a run's figure titles start with: the study, the run id and the run's grid values
    (run.json beside a study's timeseries.nc), e.g. 'speed_sweep run 1a2b3c4d: speed 12.5 m/s,
    terrain.height 0.1 m'; a run outside a study: its scenario's name."""
    name = _name(ds)
    if path is None:
        return name
    from trackbench.study.store import read_json
    rec = read_json(find_timeseries(path).parent / "run.json")
    if not isinstance(rec, dict):
        return name
    text = f"{rec.get('study', name)} run {str(rec.get('run_id', ''))[:8]}".rstrip()
    params = rec.get("params") or {}
    if rec.get("replicate"):
        params = {**params, "replicate": rec["replicate"]}
    if params:
        text += ": " + ", ".join(f"{k} {value_label(k, v)}" for k, v in params.items())
    return text


def _status_note(ds):
    if ds.attrs.get("status", "completed") == "completed":
        return ""
    return f"  [run {ds.attrs.get('status')} at t = {float(ds.attrs.get('t_final', np.nan)):.4f} s]"


def manifest(src):
    """The study's runs.json beside its summary ({} without one)."""
    from trackbench.study.store import read_json
    return read_json(src.parent / "runs.json") or {}
