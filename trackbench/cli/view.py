"""`trackbench view PATH [RUN_ID]`: find a run's recording and open the rerun viewer on it
(or serve it to a browser with --web: web_view.py).

PATH is an .rrd file; a run folder holding recording.rrd; a .nc file or a run folder
without a recording (one is written beside the .nc first); or a study (its results
folder or its TOML file) together with a run id (a unique prefix is enough) or, for a
study with [search], --limit POINT: the run at the limit of a grid point of limits.csv,
POINT its number (1 = the first row) or its values (terrain.height=0.2).
"""

import csv
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


RRD_MAGIC = b"RRF"   # an .rrd file's first bytes (RRF2 since rerun 0.23; RRF0/1 before)


def _checked_rrd(p):
    try:
        with open(p, "rb") as f:
            head = f.read(4)
    except OSError as e:
        raise ViewError(f"{p}: {e.strerror}") from None
    if not head.startswith(RRD_MAGIC):
        raise ViewError(f"{p} is not a rerun recording (an .rrd file starts with {RRD_MAGIC.decode()})")
    return p


def _limit_rows(study_dir):
    from trackbench.study.read.limits import LIMIT_COLUMNS, LIMITS_FILE
    path = Path(study_dir) / LIMITS_FILE
    if not path.is_file():
        raise ViewError(f"{study_dir} has no {LIMITS_FILE}: --limit is for a study with [search] "
                        f"(give a run id instead)")
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    axes = [c for c in (rows[0] if rows else {}) if c not in LIMIT_COLUMNS]
    return rows, axes


def _same(a, b):
    try:
        return float(a) == float(b)
    except ValueError:
        return a.strip() == b.strip()


def _pick_point(rows, axes, point):
    """The row POINT names: its number (1 = the first) or NAME=VALUE[,NAME=VALUE]."""
    if point.strip().isdigit():
        k = int(point)
        return [rows[k - 1]] if 1 <= k <= len(rows) else []
    wanted = []
    for item in point.split(","):
        name, eq, value = item.partition("=")
        if not eq or name.strip() not in axes:
            raise ViewError(f"--limit {point}: expected a grid point's number (1 to {len(rows)}) or "
                            f"NAME=VALUE with NAME one of {', '.join(axes) or '(no grid axis)'}")
        wanted.append((name.strip(), value))
    return [r for r in rows if all(_same(r[n], v) for n, v in wanted)]


def _point_label(k, row, axes):
    where = ", ".join(f"{a}={row[a]}" for a in axes) or "the base scenario"
    return f"{k}: {where} ({row['status']}, limit {row['search_value'] or '-'})"


def limit_run_id(study_dir, point):
    """The run id at the limit of the grid point POINT of a search's limits.csv."""
    rows, axes = _limit_rows(study_dir)
    hits = _pick_point(rows, axes, str(point))
    points = "; ".join(_point_label(k, r, axes) for k, r in enumerate(rows, 1))
    if len(hits) != 1:
        many = "matches several grid points" if hits else "names no grid point"
        raise ViewError(f"--limit {point} {many}; the grid points are {points}")
    row = hits[0]
    if not row.get("limit_run"):
        k = rows.index(row) + 1
        raise ViewError(f"grid point {_point_label(k, row, axes)} has no run at the limit yet")
    return row["limit_run"]


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


def resolve_recording(path, run_id=None, limit=None):
    """PATH (+ RUN_ID or LIMIT) -> the .rrd file to open (see the module doc)."""
    p = Path(path)
    if not p.exists():
        raise ViewError(f"{p} does not exist")
    if limit is not None:
        if run_id:
            raise ViewError("give either a run id or --limit, not both")
        folder = study_output(p) if p.is_file() and p.suffix == ".toml" else p
        run_id = limit_run_id(folder, limit)
    if p.is_file() and p.suffix == ".toml":
        if not run_id:
            raise ViewError(f"{p} is a study: give a run id too, e.g. `trackbench view {p} RUN_ID`")
        p = _run_folder(study_output(p), run_id)
    elif p.is_dir() and run_id:
        p = _run_folder(p, run_id)
    if p.is_file():
        if p.suffix == ".rrd":
            return _checked_rrd(p)
        if p.suffix == ".nc":
            return _from_netcdf(p)
        raise ViewError(f"{p}: expected an .rrd or .nc file, a run folder or a study")
    if (p / RECORDING_NAME).exists():
        return _checked_rrd(p / RECORDING_NAME)
    if (p / "runs").is_dir():
        from trackbench.study.read.limits import LIMITS_FILE
        searched = (p / LIMITS_FILE).is_file()
        limit = f", or --limit POINT for the run at a limit of its {LIMITS_FILE}" if searched else ""
        raise ViewError(f"{p} is a study: give a run id too, e.g. `trackbench view {p} RUN_ID`{limit}")
    if (p / "timeseries.nc").exists():
        return _from_netcdf(p / "timeseries.nc")
    rrds = sorted(p.glob("*.rrd"))
    if len(rrds) == 1:
        return _checked_rrd(rrds[0])
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
            f"(pip install rerun-sdk==0.41.*), or drag and drop the file onto https://app.rerun.io,\n"
            f"or serve it to a browser from here: add --web to this command")


def viewer_command(rrd):
    return [sys.executable, "-m", "rerun", str(rrd)]


def open_viewer(path, run_id=None, env=None, limit=None):
    """Resolve the recording and start the rerun viewer on it (blocks until it is closed).
    Returns the viewer's exit code; raises ViewError (no recording, or no display)."""
    rrd = resolve_recording(path, run_id, limit)
    if not display_available(env):
        raise ViewError(no_display_message(rrd))
    try:
        return subprocess.call(viewer_command(rrd))
    except OSError as e:
        raise ViewError(f"could not start the rerun viewer ({e}); open {rrd} with `rerun {rrd}`") from e


def serve_web(path, run_id=None, limit=None, port=None, bind=None, echo=print):
    """Resolve the recording and serve it to a browser (web_view.serve) until Ctrl-C; 0.
    ViewError (one line) when the recording or the server cannot be had."""
    from trackbench.cli import web_view
    rrd = resolve_recording(path, run_id, limit)
    try:
        return web_view.serve(rrd, web_view.DEFAULT_PORT if port is None else port,
                              web_view.LOCALHOST if bind is None else bind, echo=echo)
    except web_view.WebViewError as e:
        raise ViewError(str(e)) from None
