"""The trackbench command line (Typer). Commands only: every piece of work lives in the package."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, List, NoReturn, Optional

import typer
from typer.core import TyperCommand, TyperGroup

if TYPE_CHECKING:
    from trackbench.study.spec.study_file import Study


def _untyped(option: Any) -> Any:
    """Typer labels its own --help flag `<bool>`; a flag takes no value, so no label."""
    if option is not None:
        option.metavar = ""
    return option


class _Command(TyperCommand):
    def get_help_option(self, ctx: Any) -> Any:
        return _untyped(super().get_help_option(ctx))


class _Group(TyperGroup):
    def get_help_option(self, ctx: Any) -> Any:
        return _untyped(super().get_help_option(ctx))


app = typer.Typer(add_completion=False, no_args_is_help=True, cls=_Group,
                  help="Dynamics of high-mobility tracked vehicles (K. Lee, 2000).")
STORAGE = "full|compact"
study_app = typer.Typer(no_args_is_help=True, cls=_Group, help="Run and read parameter studies (TOML).")
app.add_typer(study_app, name="study")


def _fail(msg: str, code: int = 2) -> NoReturn:
    typer.secho(f"error: {msg}", fg=typer.colors.RED, err=True)
    raise typer.Exit(code)


def _version(value: bool) -> None:
    if value:
        from trackbench.version import MODEL_VERSION, __version__
        typer.echo(f"trackbench {__version__} (model version {MODEL_VERSION})")
        raise typer.Exit()


@app.callback()
def _main(version: bool = typer.Option(False, "--version", metavar="", callback=_version, is_eager=True,
                                       help="Print the version and exit.")) -> None:
    """Dynamics of high-mobility tracked vehicles (K. Lee, 2000)."""


@app.command(cls=_Command)
def run(
    set_: List[str] = typer.Option(
        [],
        "--set",
        "-s",
        metavar="NAME=VALUE",
        help="Override a parameter by dotted name: --set speed=15 --set terrain.height=0.15",
    ),
    duration: Optional[float] = typer.Option(
        None, help="Simulated time (s); default: the scenario's (0.5 s)."
    ),
    out: Path = typer.Option(
        Path("out"), "--out", "-o", help="Folder for the netCDF file and the recording."
    ),
    name: Optional[str] = typer.Option(
        None, help="Scenario name, used for the file names; default: --set name=..., else paper_step."
    ),
    force: bool = typer.Option(
        False, "--force", metavar="", help="Replace OUT/NAME.nc (and .rrd) if they exist."
    ),
    storage: str = typer.Option(
        "full",
        metavar=STORAGE,
        help="full (lossless) or compact (time histories at the resolution "
        "results_schema.md states, a thinner recording).",
    ),
) -> None:
    """Run one scenario (the paper's paper_step by default) and write OUT/NAME.nc."""
    from trackbench.cli.single_run import run_one
    from trackbench.scenario import ScenarioError
    from trackbench.status import EquilibriumError
    try:
        text, ok = run_one(set_, duration, out, name, force, storage)
    except ScenarioError as e:
        _fail(str(e))
    except EquilibriumError as e:      # no start: nothing written
        _fail(str(e), 1)
    typer.echo(text)
    if not ok:
        raise typer.Exit(1)


@app.command(cls=_Command)
def params() -> None:
    """List every parameter name with its paper value and what is allowed."""
    from trackbench.cli.single_run import parameter_table
    typer.echo(parameter_table())


# --- vehicles ------------------------------------------------------------------------

vehicle_app = typer.Typer(no_args_is_help=True, cls=_Group, help="One vehicle file: its state at rest.")
app.add_typer(vehicle_app, name="vehicle")


@app.command(cls=_Command)
def vehicles() -> None:
    """List the vehicle catalogue: name, mass, road wheels, track layout, description and source."""
    from trackbench.run.vehicle_report import catalogue_table
    from trackbench.scenario import ScenarioError
    try:
        typer.echo(catalogue_table())
    except ScenarioError as e:
        _fail(str(e))


@vehicle_app.command("show", cls=_Command)
def vehicle_show(
    model: str = typer.Argument(
        ..., help="A catalogue name (trackbench vehicles) or a vehicle file (.toml)."
    ),
    out: Path = typer.Option(Path("."), "--out", "-o", help="Folder for the side view NAME_vehicle.png."),
) -> None:
    """Print a vehicle's static equilibrium (wheel loads, track tension and sag, ground pressure,
    seat height) and write its side view, the parts named."""
    from trackbench.figures.vehicle_figure import vehicle_figure
    from trackbench.run.vehicle_report import describe, statics, vehicle_scenario
    from trackbench.scenario import ScenarioError
    from trackbench.status import EquilibriumError
    try:
        st = statics(vehicle_scenario(model))
    except ScenarioError as e:
        _fail(str(e))
    except EquilibriumError as e:
        _fail(f"vehicle.model = '{model}': the vehicle does not stand: {e}", 1)
    typer.echo(describe(st))
    typer.echo(f"written: {vehicle_figure(st, out / (Path(model).stem + '_vehicle.png'))}")


# --- study commands ----------------------------------------------------------------

def _load_study_or_fail(file: Path, output: Optional[Path] = None) -> Study:
    from trackbench.study import StudyError, load_study
    try:
        return load_study(file, output=output)
    except StudyError as e:
        _fail(str(e))


def _study_folder_or_fail(path: Path) -> tuple[Study, Path]:
    """A study file or results folder -> (study, its results folder, which exists)."""
    from trackbench.study import StudyError
    from trackbench.study.read.folder import study_folder
    try:
        return study_folder(path)
    except StudyError as e:
        _fail(str(e))


@study_app.command("run", cls=_Command)
def study_run(
    file: Path = typer.Argument(..., help="Study file (TOML), e.g. studies/speed_sweep.toml."),
    workers: int = typer.Option(
        2, "--workers", "-w", help="Worker processes (or dask workers of a LocalCluster)."
    ),
    executor: str = typer.Option(
        "local", metavar="local|dask", help="local (process pool) or dask (dask.distributed)."
    ),
    scheduler: Optional[str] = typer.Option(
        None, help="dask scheduler address, e.g. tcp://host:8786; default: a LocalCluster."
    ),
    force: bool = typer.Option(
        False, "--force", metavar="", help="Rerun every run, also those already completed."
    ),
    output: Optional[Path] = typer.Option(
        None,
        "--output",
        "-o",
        help="Results folder; default: the study's "
        "\\[study] output, else results/NAME (relative to the current directory).",
    ),
    storage: Optional[str] = typer.Option(
        None,
        metavar=STORAGE,
        help="full (lossless) or compact (time histories "
        "at the resolution results_schema.md states); default: the "
        "study's \\[study] storage, "
        "else full. Runs already completed keep their files.",
    ),
) -> None:
    """Run every variant of a study (resumable: completed runs are skipped) and print the summary."""
    from trackbench.study.execute.executors import check_arguments
    from trackbench.warm.forkserver import ForkServerPools, started_early
    try:
        check_arguments(workers, executor, scheduler, storage)
    except ValueError as e:
        _fail(str(e))
    try:
        with started_early(executor, scheduler) as tell:
            study = _load_study_or_fail(file, output)
            from trackbench.study import store
            tell(r.scenario for r in study.runs if force or not store.is_completed(study.output, r.run_id))
            from trackbench.study.execute.runner import check_output
            check_output(study)   # a folder that cannot be written, or that holds another study's results
    except ValueError as e:
        _fail(str(e))
    from trackbench.study import StudyError, StudyLocked, run_study
    from trackbench.study.execute.runner import report
    try:
        outcome = run_study(study, workers=workers, executor=executor, scheduler=scheduler, force=force,
                            storage=storage, pools=ForkServerPools())
    except (StudyError, ValueError) as e:
        _fail(str(e))
    except StudyLocked as e:
        _fail(str(e), code=3)
    except RuntimeError as e:  # e.g. the dask scheduler cannot be reached
        _fail(str(e), code=1)
    except KeyboardInterrupt:
        _fail(
            "interrupted: completed runs are kept; run the same command again to finish the study", code=130
        )
    typer.echo(report(outcome))
    if outcome.problem():
        _fail(outcome.problem(), code=1)


@study_app.command("summary", cls=_Command)
def study_summary(file: Path = typer.Argument(..., help="Study file (TOML) or its results folder.")) -> None:
    """Print the study's summary table (rebuilt from the runs' run.json; summary files rewritten)."""
    from trackbench.study.read.summary import format_table, write_summary
    study, _ = _study_folder_or_fail(file)
    df, rep = write_summary(study)
    typer.echo(format_table(df, rep, study.param_names))


@study_app.command("status", cls=_Command)
def study_status(file: Path = typer.Argument(..., help="Study file (TOML) or its results folder.")) -> None:
    """Show how many runs are done, failed and pending (and how far a [search] is)."""
    from trackbench.study.execute.runner import count, other_runs, others_note, status_counts
    from trackbench.study.read.folder import missing_folder
    study = _study_folder_or_fail(file)[0] if file.is_dir() else _load_study_or_fail(file)
    if not study.output.is_dir():
        typer.echo(
            f"study {study.name}: {count(len(study.runs), 'run')}, all pending: {missing_folder(study)}"
        )
        return
    search = ""
    if study.search is not None:   # replayed first: it adds the runs the search asks for next
        from trackbench.study.read.limits import search_state
        search = search_state(study)
    counts, failed = status_counts(study)
    kept = others_note(len(other_runs(study)))
    typer.echo(
        f"study {study.name}: {count(len(study.runs), 'run')}: {counts['completed']} done, "
        f"{counts['failed']} failed, "
        f"{counts['pending']} pending ({study.output}){'; ' + kept if kept else ''}"
    )
    if search:
        typer.echo(search)
    for run_id, why in failed:
        typer.echo(f"  failed {run_id}: {why}")


# --- replay commands ---------------------------------------------------------------

@app.command(cls=_Command)
def view(
    path: Path = typer.Argument(
        ...,
        help="A run folder (recording.rrd inside), an .rrd or .nc file, or a study "
        "(results folder or TOML) followed by RUN_ID.",
    ),
    run_id: Optional[str] = typer.Argument(None, help="Run id within a study (a unique prefix is enough)."),
    run: Optional[str] = typer.Option(None, "--run", metavar="ID", help="The same as RUN_ID."),
    limit: Optional[str] = typer.Option(
        None, "--limit", metavar="POINT", help="A study with \\[search]: the run at the limit of grid point "
        "POINT of limits.csv, its number (1 = the first row) or its values (terrain.height=0.2)."
    ),
    web: bool = typer.Option(False, "--web", metavar="", help="Serve it to a browser (rerun's web viewer) "
                             "instead of opening a window; prints the address and the ssh port-forward."),
    port: int = typer.Option(9090, "--port", help="With --web: the port to listen on."),
    bind: str = typer.Option(
        "127.0.0.1", "--bind", metavar="ADDRESS", help="With --web: the address to listen on; 0.0.0.0 "
        "opens it to the network (anyone who reaches it sees the run)."
    ),
) -> None:
    """Open the rerun viewer on a run's recording (needs a display; otherwise says how to
    open it elsewhere), or with --web serve it to a browser until Ctrl-C."""
    from trackbench.cli.view import ViewError, open_viewer, serve_web
    if run_id and run and run_id != run:
        _fail(f"two run ids: {run_id} and --run {run}; give one")
    run_id = run_id or run
    if path.suffix == ".toml" and path.is_file():
        path = _study_folder_or_fail(path)[1]   # its results folder, as `study run` put it
    try:
        if web:
            code = serve_web(path, run_id, limit, port=port, bind=bind, echo=typer.echo)
        else:
            code = open_viewer(path, run_id, limit=limit)
    except (ViewError, ValueError) as e:
        _fail(str(e), 3)
    raise typer.Exit(code)


@app.command(cls=_Command)
def plot(
    path: Path = typer.Argument(
        ..., help="A run (.nc file or run folder) or a study (results folder or TOML)."
    ),
    out: Optional[Path] = typer.Option(
        None,
        "--out",
        "-o",
        help="Folder for the PNG files; default: "
        "RUN_FOLDER/plots, NAME_plots beside a .nc file, STUDY/plots.",
    ),
    times: Optional[str] = typer.Option(
        None,
        help="Times (s) of the configuration figure, comma-separated; "
        "default: the paper's 0.1,0.35,0.45 for a run of its length, else three "
        "times spread over the run.",
    ),
) -> None:
    """Write PNG figures: a run's Figs. 8-18 of the paper, or a study's peak forces against each grid axis."""
    from trackbench.figures.plots import plot_run, plot_study, remove_stale
    try:
        tt = None if times is None else tuple(float(x) for x in times.split(",") if x.strip())
    except ValueError:
        _fail(f"--times {times!r}: expected numbers separated by commas, e.g. 0.1,0.35,0.45")
    is_study = path.suffix == ".toml" or (
        path.is_dir() and ((path / "summary.csv").exists() or (path / "runs").is_dir())
    )
    if path.suffix == ".toml":
        path = _study_folder_or_fail(path)[1]   # its results folder, as `study run` put it
    if out is None:
        out = (path.parent / (path.stem + "_plots")) if path.is_file() and path.suffix == ".nc" else None
    try:
        if is_study:
            if out is None:
                out = path / "plots"
            paths = plot_study(path, out)
            for p in remove_stale(out, paths):
                typer.echo(f"removed: {p} (not a figure of this study's axes now)")
        else:
            paths = plot_run(path, out if out is not None else path / "plots", times=tt)
    except (FileNotFoundError, ValueError, ImportError) as e:
        _fail(str(e))
    for p in paths:
        typer.echo(f"written: {p}")


@app.command(cls=_Command)
def report(
    path: Path = typer.Argument(..., help="A study: its file (TOML) or its results folder."),
    out: Optional[Path] = typer.Option(
        None, "--out", "-o", help="The HTML file (or a folder for report.html); default: RESULTS/report.html."
    ),
) -> None:
    """Write one HTML page of a study (opens offline): grid, figures, failures, the runs'
    table (sortable) and the command that replays each run."""
    from trackbench.figures.report import write_report
    from trackbench.study import StudyError
    try:
        written, facts = write_report(path, out)
    except (StudyError, ValueError) as e:
        _fail(str(e))
    except OSError as e:
        _fail(f"cannot write the report: {e.strerror or e} ({e.filename or out})", 1)
    typer.echo(f"written: {written} ({facts['runs']} runs, {facts['failed']} failed, {facts['figures']} "
               f"figures, {facts['bytes'] / 1e6:.2f} MB); open it in a browser: {written.resolve().as_uri()}")


@app.command(cls=_Command)
def record(
    nc: Path = typer.Argument(..., help="A run's netCDF file (or a run folder holding timeseries.nc)."),
    out: Optional[Path] = typer.Option(None, "--out", "-o", help="The .rrd file; default: beside the .nc "
                                       "(recording.rrd in a run folder, NAME.rrd otherwise)."),
    every: int = typer.Option(1, "--every", min=1, help="Log the side view at every k-th output frame."),
) -> None:
    """Write (or rewrite) the rerun recording of an existing run."""
    import xarray as xr

    from trackbench.figures.plots import find_timeseries
    from trackbench.outputs.recording.record import RECORDING_NAME, write_recording
    try:
        src = find_timeseries(nc)
    except FileNotFoundError as e:
        _fail(str(e))
    if out is None:
        out = src.parent / (RECORDING_NAME if src.name == "timeseries.nc" else src.stem + ".rrd")
    typer.echo(f"written: {write_recording(xr.load_dataset(src), out, every=every)}")
