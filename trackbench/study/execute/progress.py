"""The live progress of `study run`: a rich progress bar on a terminal, one plain line per
finished run otherwise; a search's line (how far it is) beside it."""

import sys
import time


class StudyProgress:
    """A live rich progress bar on a terminal (done, failed, running, elapsed, ETA); one plain
    line per finished run otherwise (a log, a pipe, CI)."""

    def __init__(self, total, skipped, quiet=False, stream=None, workers=1, terminal=None, flag=None,
                 line=None):
        from rich.console import Console
        self.console = Console(file=stream or sys.stderr, force_terminal=terminal)
        self.console.soft_wrap = not self.console.is_terminal   # a log keeps one line per run, however long
        self.total, self.done, self.failed, self.workers, self.in_flight = 0, 0, 0, workers, None
        self.quiet, self.t0, self.flag, self.compiled = quiet, time.perf_counter(), flag, 0.0
        self.bar, self.label = None, "runs"
        if line:
            self.search(line)
        self.more(total, skipped)

    def more(self, total, skipped):
        """``total`` runs more to do (a search's next wave), ``skipped`` of its runs already completed."""
        self.total += total
        if self.bar is not None:
            self.bar.update(self.task, total=self.total, counts=self._counts())
        elif not self.quiet and self.console.is_terminal and self.total:
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

            self.bar = Progress(
                TextColumn("[bold]{task.description}"),
                BarColumn(),
                _counts_column(self),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                console=self.console,
            )
            self.task = self.bar.add_task(self.label, total=self.total, counts=self._counts())
            self.bar.start()
        elif not self.quiet:
            self.console.print(f"{total} runs to do, {skipped} already completed", highlight=False)

    def search(self, text):
        """The search's line: the bar's label on a terminal, a line of the log otherwise."""
        self.label = text
        if self.bar is not None:
            self.bar.update(self.task, description=text)
        else:
            self.note(text)

    def _running(self):
        left = self.total - self.done - self.failed
        return min(left, self.workers if self.in_flight is None else self.in_flight)

    def _counts(self):
        return f"done {self.done}  failed {self.failed}  running {self._running()}  of {self.total}"

    def running(self, n):
        """The executor's count of runs in flight (without it: one per worker)."""
        self.in_flight = n
        if self.bar is not None:
            self.bar.update(self.task, counts=self._counts())

    def compiling(self):
        """(compiling now, seconds compiled so far) from the fork server's flag file."""
        import json
        try:
            said = json.loads(self.flag.read_text())
        except (OSError, ValueError, AttributeError):
            return False, self.compiled
        self.compiled = max(self.compiled, float(said.get("seconds", 0.0)))
        return bool(said.get("compiling")), self.compiled

    def update(self, rec):
        if rec["status"] == "completed":
            self.done += 1
        else:
            self.failed += 1
        if self.bar is not None:
            self.bar.update(self.task, advance=1, counts=self._counts())
        elif not self.quiet:
            n = self.done + self.failed
            _, compiled = self.compiling()
            if n == 1 and compiled > 0.0:
                self.console.print(
                    f"(the workers waited {compiled:.0f} s for the model to compile: once per "
                    "machine and version; later studies load it from the cache)",
                    highlight=False,
                )
            el = max(
                time.perf_counter() - self.t0 - compiled, 0.0
            )  # the compiling is not what every run takes
            eta = el / n * (self.total - n)
            msg = "" if rec["status"] == "completed" else f": {rec.get('status_message', '')}"
            self.console.print(f"[{n}/{self.total}] {rec['run_id']} {rec['status']}{msg}  ({self._counts()}, "
                               f"ETA {eta:.0f} s)", highlight=False, markup=False)

    def note(self, text):
        if not self.quiet:
            self.console.print(text, highlight=False, markup=False)

    def close(self):
        if self.bar is not None:
            self.bar.stop()


def _counts_column(progress):
    """The bar's counts; while the fork server compiles the model, that instead (the workers
    wait for it: "running" would say otherwise)."""
    from rich.progress import TextColumn
    from rich.text import Text

    class Counts(TextColumn):
        def render(self, task):
            if progress.compiling()[0]:
                return Text("compiling the model (once, 1-2 min)", style="yellow")
            return super().render(task)

    return Counts("{task.fields[counts]}")
