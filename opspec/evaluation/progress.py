"""Progress of an evaluation: a bar on a terminal (rich), plain log lines otherwise."""

from __future__ import annotations

import sys
import time
from typing import IO, Any

from opspec.evaluation.runner import Progress

__all__ = ["LogProgress", "make_progress"]


class LogProgress(Progress):
    """One line every ``every`` seconds (and at the end): done, rate, time left."""

    def __init__(self, stream: IO[str], every: float = 5.0, label: str = "replications"
                 ) -> None:
        self.stream = stream
        self.label = label
        self.every = every
        self.total = self.done = self.already = 0
        self._start = self._last = 0.0

    def start(self, total: int, already: int) -> None:
        self.total, self.already, self.done = total, already, already
        self._start = self._last = time.perf_counter()
        if already:
            print(f"opspec evaluate: resuming, {already} of {total} {self.label} already stored",
                  file=self.stream, flush=True)

    def advance(self, n: int) -> None:
        self.done += n
        now = time.perf_counter()
        if now - self._last >= self.every:
            self._last = now
            self._line(now)

    def _line(self, now: float) -> None:
        ran = self.done - self.already
        rate = ran / (now - self._start) if now > self._start else 0.0
        if self.done >= self.total:
            left = "done"
        elif rate > 0:
            left = f"about {(self.total - self.done) / rate:.0f} s left"
        else:
            left = "time left not known yet"
        print(f"opspec evaluate: {self.done}/{self.total} {self.label} ({rate:.0f}/s, {left})",
              file=self.stream, flush=True)

    def finish(self) -> None:
        if self.done == self.already >= self.total:
            return      # nothing ran: start() said every one was stored ("0/s, done" was all)
        self._line(time.perf_counter())


class _RichProgress(Progress):
    def __init__(self, stream: IO[str], label: str) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, TextColumn, TimeRemainingColumn
        from rich.progress import Progress as Bar

        self._bar = Bar(TextColumn(label), BarColumn(), MofNCompleteColumn(),
                        TextColumn("{task.fields[rate]}"), TimeRemainingColumn(),
                        console=Console(file=stream), transient=False)
        self._task: Any = None
        self._start = 0.0
        self._ran = 0

    def start(self, total: int, already: int) -> None:
        self._bar.start()
        self._task = self._bar.add_task("evaluate", total=total, completed=already, rate="")
        self._start = time.perf_counter()

    def advance(self, n: int) -> None:
        self._ran += n
        elapsed = time.perf_counter() - self._start
        rate = f"{self._ran / elapsed:.0f}/s" if elapsed > 0 else ""
        self._bar.update(self._task, advance=n, rate=rate)

    def finish(self) -> None:
        self._bar.stop()


def make_progress(stream: IO[str] | None = None, *, quiet: bool = False,
                  label: str = "users") -> Progress:
    """A bar when ``stream`` is a terminal, log lines when it is not, nothing when quiet.
    ``label`` names what is counted (users; replications when two designs run)."""
    stream = stream or sys.stderr
    if quiet:
        return Progress()
    if stream.isatty():
        return _RichProgress(stream, label)
    return LogProgress(stream, label=label)
