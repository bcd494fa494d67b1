"""Trace sinks: in memory, and JSON Lines files with a versioned header; a reader.

A JSON Lines trace starts with one header line::

    {"format": "opspec-trace", "version": 1, "package": "...", "seed": 1, ...}

followed by one :meth:`TraceEvent.to_json` object per line. The file is flushed every
``flush_every`` events and on close, so a crash loses at most that many events. See
``docs/trace-format.md``.
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import IO, Any, Self

from opspec.engine.trace import TRACE_FORMAT, TRACE_FORMAT_VERSION, TraceEvent
from opspec.errors import ExecutionError, SourceLocation

__all__ = ["JsonlSink", "MemorySink", "read_trace", "read_trace_header"]


class MemorySink:
    """Keeps every event it receives in ``events`` (a list)."""

    selects = None   # wants everything

    def __init__(self) -> None:
        self.events: list[TraceEvent] = []

    def __call__(self, event: TraceEvent) -> None:
        self.events.append(event)


class JsonlSink:
    """Writes events to a JSON Lines file. Use as a context manager or call :meth:`close`."""

    selects = None

    def __init__(self, path: str | Path, header: Mapping[str, Any] | None = None,
                 flush_every: int = 256) -> None:
        self.path = Path(path)
        self._handle: IO[str] = open(self.path, "w", encoding="utf-8")  # noqa: SIM115
        self._flush_every = max(1, flush_every)
        self._pending = 0
        head = {"format": TRACE_FORMAT, "version": TRACE_FORMAT_VERSION, **(header or {})}
        self._handle.write(json.dumps(head, default=str) + "\n")
        self._handle.flush()

    def __call__(self, event: TraceEvent) -> None:
        self._handle.write(json.dumps(event.to_json(), default=str, allow_nan=True) + "\n")
        self._pending += 1
        if self._pending >= self._flush_every:
            self._handle.flush()
            self._pending = 0

    def close(self) -> None:
        if not self._handle.closed:
            self._handle.flush()
            self._handle.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_trace_header(path: str | Path) -> dict[str, Any]:
    """The header of a JSON Lines trace (format and version checked)."""
    with open(path, encoding="utf-8") as handle:
        first = handle.readline()
    return _header(first, str(path))


def _header(line: str, where: str) -> dict[str, Any]:
    try:
        head = json.loads(line)
    except json.JSONDecodeError:
        head = None
    if not isinstance(head, dict) or head.get("format") != TRACE_FORMAT:
        raise ExecutionError("not an opspec trace (first line is not its header)",
                             location=SourceLocation(where, 1),
                             hint="write traces with opspec run --trace FILE")
    if head.get("version") != TRACE_FORMAT_VERSION:
        raise ExecutionError(f"trace format version {head.get('version')} is not supported "
                             f"(this opspec reads version {TRACE_FORMAT_VERSION})",
                             location=SourceLocation(where, 1))
    return head


def read_trace(path: str | Path) -> Iterator[TraceEvent]:
    """The events of a JSON Lines trace, in file order (a truncated last line is skipped)."""
    where = str(path)
    with open(path, encoding="utf-8") as handle:
        _header(handle.readline(), where)
        for number, line in enumerate(handle, start=2):
            if not line.strip():
                continue
            try:
                obj = json.loads(line)
            except json.JSONDecodeError:
                if not line.endswith("\n"):
                    return            # the run crashed while writing this line
                raise ExecutionError("trace line is not JSON",
                                     location=SourceLocation(where, number)) from None
            yield TraceEvent.from_json(obj)
