"""The trackbench command line (Typer). Commands only: every piece of work lives in the package."""

from pathlib import Path
from typing import List, Optional

import typer

app = typer.Typer(add_completion=False, no_args_is_help=True,
                  help="Dynamics of high-mobility tracked vehicles (K. Lee, 2000).")
study_app = typer.Typer(no_args_is_help=True, help="Run and read parameter studies (TOML).")
app.add_typer(study_app, name="study")


def _fail(msg: str, code: int = 2):
    typer.secho(f"error: {msg}", fg=typer.colors.RED, err=True)
    raise typer.Exit(code)


@app.command()
def run(
    set_: List[str] = typer.Option([], "--set", "-s", help="Override a parameter by dotted name: --set speed=15 --set terrain.height=0.15"),
    duration: Optional[float] = typer.Option(None, help="Simulated time (s); default: the scenario's (0.5 s)."),
    out: Path = typer.Option(Path("out"), "--out", "-o", help="Folder for the netCDF file."),
    name: str = typer.Option("paper_step", help="Scenario name, used for the file name."),
):
    """Run one scenario (the paper's paper_step by default) and write OUT/NAME.nc."""
    from .runner import run_one
    from .scenario import ScenarioError
    try:
        text = run_one(set_, duration, out, name)
    except ScenarioError as e:
        _fail(str(e))
    typer.echo(text)


@app.command()
def params():
    """List every parameter name with its paper value and what is allowed."""
    from .runner import parameter_table
    typer.echo(parameter_table())


# --- study commands (issue 4) -------------------------------------------------------

# --- replay commands (issue 5) ------------------------------------------------------


def main():
    app()


if __name__ == "__main__":
    main()
