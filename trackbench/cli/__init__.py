"""The command line: app.py (the Typer commands, thin), entry.py (the process's entry),
single_run.py (`trackbench run`: one scenario, its files and its one-screen summary), view.py
(`trackbench view`). The only room that imports the start-up corner (trackbench/warm)."""

from .entry import main

__all__ = ["main"]
