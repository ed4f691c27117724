"""The process's entry: a command line run in this process, its exit status, and the exit."""

from __future__ import annotations

from typing import Any, List, NoReturn

import typer

from trackbench.cli.app import app


def _usage_error() -> type[Exception]:
    """Click's UsageError, as the installed Typer has it (recent Typers carry their own Click)."""
    return next(c for c in typer.BadParameter.__mro__
                if c.__name__ == "UsageError" and issubclass(c, Exception))


def main() -> NoReturn:
    """The command, in this process."""
    import sys
    _leave(command(sys.argv[1:]))


def command(argv: List[str]) -> int:
    """Run the command ``argv``; its exit status. Click's own usage errors (an option of the
    wrong type, an unknown option or command) in one line like the command's own, instead of
    a framed panel."""
    if argv[:1] == ["run"]:   # a process that runs one scenario holds numpy arrays only
        from trackbench.warm.startup import without_dask_arrays
        without_dask_arrays()
    try:
        code = app(args=list(argv), standalone_mode=False, prog_name="trackbench")
    except _usage_error() as err:
        e: Any = err
        if type(e).__name__ == "NoArgsIsHelpError":    # `trackbench study` alone: its help
            e.show()
            return 0
        where = e.ctx.command_path if e.ctx is not None else "trackbench"
        typer.secho(
            f"error: {where}: {e.format_message()} (see '{where} --help')", fg=typer.colors.RED, err=True
        )
        code = 2
    except typer.Abort:
        typer.secho("error: interrupted", fg=typer.colors.RED, err=True)
        code = 130
    return code if isinstance(code, int) else 0


def _leave(code: int) -> NoReturn:
    """Exit without the interpreter's teardown of numpy, pandas, pyarrow and rich (0.1-0.2 s of
    every study command, after its last word): by now the command has written and closed its
    files, and its worker pool and threads are done. Not once rerun is loaded (`run`, `record`,
    `view`): it flushes recordings at exit."""
    import os
    import sys
    if "rerun" in sys.modules:
        sys.exit(code)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)

