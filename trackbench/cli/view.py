"""`trackbench view PATH [RUN_ID]`: find a run's recording and open the rerun viewer on it.

PATH is an .rrd file; a run folder holding recording.rrd; a .nc file or a run folder
without a recording (one is written beside the .nc first); or a study (its results
folder or its TOML file) together with a run id (a unique prefix is enough).
"""

import os
import subprocess
import sys
from pathlib import Path

from trackbench.outputs.recording.record import RECORDING_NAME
from trackbench.study.read.folder import study_output


class ViewError(RuntimeError):
    """The recording cannot be found or the viewer cannot start; the message says why."""


def _run_folder(study_dir, run_id):
    runs = Path(study_dir) / "runs"
    if not runs.is_dir():
        raise ViewError(f"{study_dir} is not a study results folder (no runs/ inside)")
    if (runs / run_id).is_dir():
        return runs / run_id
    hits = sorted(p for p in runs.iterdir() if p.is_dir() and p.name.startswith(run_id))
    if len(hits) == 1:
        return hits[0]
    if not hits:
        raise ViewError(f"no run '{run_id}' in {runs} (see summary.csv for the run ids)")
    raise ViewError(f"run id '{run_id}' is ambiguous in {runs}: {', '.join(p.name for p in hits[:5])} ...")


def _from_netcdf(nc):
    """Recording beside a .nc (written now if missing): run folders use recording.rrd,
    other files <stem>.rrd."""
    nc = Path(nc)
    rrd = nc.parent / (RECORDING_NAME if nc.name == "timeseries.nc" else nc.stem + ".rrd")
    if not rrd.exists() or rrd.stat().st_mtime < nc.stat().st_mtime:
        import xarray as xr

        from trackbench.outputs.recording.record import write_recording
        write_recording(xr.load_dataset(nc), rrd)
        print(f"wrote {rrd} from {nc}", file=sys.stderr)
    return rrd


def resolve_recording(path, run_id=None):
    """PATH (+ RUN_ID) -> the .rrd file to open (see the module doc)."""
    p = Path(path)
    if not p.exists():
        raise ViewError(f"{p} does not exist")
    if p.is_file() and p.suffix == ".toml":
        if not run_id:
            raise ViewError(f"{p} is a study: give a run id too, e.g. `trackbench view {p} RUN_ID`")
        p = _run_folder(study_output(p), run_id)
    elif p.is_dir() and run_id:
        p = _run_folder(p, run_id)
    if p.is_file():
        if p.suffix == ".rrd":
            return p
        if p.suffix == ".nc":
            return _from_netcdf(p)
        raise ViewError(f"{p}: expected an .rrd or .nc file, a run folder or a study")
    if (p / RECORDING_NAME).exists():
        return p / RECORDING_NAME
    if (p / "runs").is_dir():
        raise ViewError(f"{p} is a study: give a run id too, e.g. `trackbench view {p} RUN_ID`")
    if (p / "timeseries.nc").exists():
        return _from_netcdf(p / "timeseries.nc")
    rrds = sorted(p.glob("*.rrd"))
    if len(rrds) == 1:
        return rrds[0]
    raise ViewError(f"{p} holds no {RECORDING_NAME} (and no timeseries.nc to make one from)")


def display_available(env=None):
    """False on Linux without an X11 or Wayland display (e.g. over ssh, in CI)."""
    env = os.environ if env is None else env
    if not sys.platform.startswith("linux"):
        return True
    return bool(env.get("DISPLAY") or env.get("WAYLAND_DISPLAY"))


def no_display_message(rrd):
    return (f"cannot open the rerun viewer here: no display (neither DISPLAY nor WAYLAND_DISPLAY is set).\n"
            f"The recording is {Path(rrd).resolve()}\n"
            f"To watch it, copy it to a machine with a display and run\n"
            f"    rerun {Path(rrd).name}\n"
            f"(pip install rerun-sdk==0.41.*), or drag and drop the file onto https://app.rerun.io")


def viewer_command(rrd):
    return [sys.executable, "-m", "rerun", str(rrd)]


def open_viewer(path, run_id=None, env=None):
    """Resolve the recording and start the rerun viewer on it (blocks until it is closed).
    Returns the viewer's exit code; raises ViewError (no recording, or no display)."""
    rrd = resolve_recording(path, run_id)
    if not display_available(env):
        raise ViewError(no_display_message(rrd))
    try:
        return subprocess.call(viewer_command(rrd))
    except OSError as e:
        raise ViewError(f"could not start the rerun viewer ({e}); open {rrd} with `rerun {rrd}`") from e
