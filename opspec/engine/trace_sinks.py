"""Trace sinks: in memory, and JSON Lines files with a versioned header; a reader.

A JSON Lines trace starts with one header line::

    {"format": "opspec-trace", "version": 1, "package": "...", "seed": 1, ...}

followed by one :meth:`TraceEvent.to_json` object per line. The file is flushed every
``flush_every`` events and on close, so a crash loses at most that many events. See
``docs/trace-format.md``.

A trace file never grows past ``max_bytes`` (:data:`TRACE_MAX_BYTES`, 1 GiB, or
``OPSPEC_TRACE_MAX_BYTES``): the event that would pass it is replaced by one
``trace.truncated`` line saying so, later events are counted (:attr:`JsonlSink.dropped`) but
not written, and :attr:`JsonlSink.truncated` tells the command to say so in one line.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import IO, Any, Self

from opspec.engine.trace import TRACE_FORMAT, TRACE_FORMAT_VERSION, TraceEvent
from opspec.errors import ExecutionError, SourceLocation

__all__ = [
    "TRACE_MAX_BYTES",
    "TRACE_MAX_BYTES_ENV",
    "JsonlSink",
    "MemorySink",
    "header_line",
    "read_trace",
    "read_trace_header",
    "trace_max_bytes",
]

#: The most a JSON Lines trace file may hold, in bytes (1 GiB: some 5 million events).
TRACE_MAX_BYTES = 1 << 30
#: The environment variable that sets another cap (a positive number of bytes).
TRACE_MAX_BYTES_ENV = "OPSPEC_TRACE_MAX_BYTES"


def trace_max_bytes() -> int:
    """The cap: ``OPSPEC_TRACE_MAX_BYTES`` when it is a positive integer, else 1 GiB."""
    raw = os.environ.get(TRACE_MAX_BYTES_ENV, "")
    try:
        value = int(raw) if raw.strip() else TRACE_MAX_BYTES
    except ValueError:
        value = TRACE_MAX_BYTES
    return value if value > 0 else TRACE_MAX_BYTES


class MemorySink:
    """Keeps every event it receives in ``events`` (a list)."""

    selects = None   # wants everything

    def __init__(self) -> None:
        self.events: list[TraceEvent] = []

    def __call__(self, event: TraceEvent) -> None:
        self.events.append(event)


def header_line(header: Mapping[str, Any] | None = None, **fixed: Any) -> dict[str, Any]:
    """A trace file's header object: ``format`` and ``version`` first, then ``fixed`` and
    ``header``; a ``seed`` is written as an integer whoever writes the file."""
    head: dict[str, Any] = {"format": TRACE_FORMAT, "version": TRACE_FORMAT_VERSION, **fixed}
    for key, value in (header or {}).items():
        head.setdefault(key, value)
    if "seed" in head and head["seed"] is not None:
        head["seed"] = int(head["seed"])
    return head


class JsonlSink:
    """Writes events to a JSON Lines file. Use as a context manager or call :meth:`close`.

    ``max_bytes`` caps the file (default :func:`trace_max_bytes`); see the module docstring."""

    selects = None

    def __init__(self, path: str | Path, header: Mapping[str, Any] | None = None,
                 flush_every: int = 256, max_bytes: int | None = None) -> None:
        self.path = Path(path)
        self._handle: IO[str] = open(self.path, "w", encoding="utf-8")  # noqa: SIM115
        self._flush_every = max(1, flush_every)
        self._pending = 0
        self.max_bytes = max_bytes if max_bytes is not None else trace_max_bytes()
        #: the time of the first event not written (the cap was reached), or None
        self.truncated: float | None = None
        self.dropped = 0
        #: why writing failed (a full disk, a lost device), or None: the run goes on and
        #: its results are reported; the trace ends where the failure was
        self.failure: str | None = None
        head = header_line(header)
        line = json.dumps(head, default=str) + "\n"
        self._handle.write(line)
        self._handle.flush()
        self._bytes = len(line)

    def __call__(self, event: TraceEvent) -> None:
        if self.truncated is not None:
            self.dropped += 1
            return
        line = json.dumps(event.to_json(), default=str, allow_nan=True) + "\n"
        self._bytes += len(line)         # ensure_ascii: characters are bytes
        if self._bytes > self.max_bytes:
            self._truncate(event)
            return
        try:
            self._handle.write(line)
            self._pending += 1
            if self._pending >= self._flush_every:
                self._handle.flush()
                self._pending = 0
        except OSError as error:           # a disk that fills: keep the run, end the trace
            self._failed(event.time, error)

    def _failed(self, time: float, error: OSError) -> None:
        self.truncated = time
        self.dropped = max(1, self.dropped)
        self.failure = error.strerror or str(error)

    def _truncate(self, event: TraceEvent) -> None:
        self.truncated = event.time
        self.dropped = 1
        self._handle.write(json.dumps({
            "seq": event.seq, "time": event.time, "kind": "trace.truncated",
            "data": {"max_bytes": self.max_bytes, "message": self.message()}}) + "\n")
        self._handle.flush()

    def message(self) -> str:
        """One line saying that (and where) the trace was cut, and what to do."""
        if self.failure is not None:
            return (f"writing the trace {self.path} failed at t={self.truncated or 0.0:.3f} s "
                    f"({self.failure}); the events from then on are not in it (free space "
                    "where it goes, or give --trace another place)")
        return (f"the trace {self.path} reached its cap of {self.max_bytes:,} bytes at "
                f"t={self.truncated or 0.0:.3f} s; later events were not written "
                f"(set {TRACE_MAX_BYTES_ENV} to a larger number of bytes, or run for less time)")

    def close(self) -> None:
        if not self._handle.closed:
            try:
                self._handle.flush()
            except OSError as error:
                if self.failure is None:
                    self._failed(self.truncated or 0.0, error)
            try:
                self._handle.close()
            except OSError:
                pass                       # what could not be written is said in .failure

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
