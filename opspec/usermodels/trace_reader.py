"""Reading recorded traces for ``opspec fit`` and ``opspec model-check``: the files a command
line names and the events of each.

A trace file is JSON Lines (``docs/trace-format.md``): a header line
``{"format": "opspec-trace", "version": 1, ...}`` then one ``TraceEvent.to_json()`` object per
line. :func:`read_trace` streams its events and names ``path:line`` for what it cannot read;
:func:`iter_paths` expands the folders a command line gives to the trace files inside.
"""

from __future__ import annotations

import io
import json
from collections.abc import Iterable, Iterator
from pathlib import Path

from opspec.engine.trace import TRACE_FORMAT, TRACE_FORMAT_VERSION, TraceEvent
from opspec.errors import SourceLocation, UserModelError
from opspec.files import json_loads, json_problem

__all__ = ["iter_paths", "read_trace"]


def read_trace(path: str | Path) -> Iterator[TraceEvent]:
    """The events of one JSON Lines trace file, streamed; :class:`UserModelError` naming
    ``path:line`` for an unreadable file, a missing/foreign header or a malformed line."""
    from opspec.files import open_regular, reason

    name = str(path)
    try:
        # a pipe or device is refused, never read (it would block); closed in the finally
        handle = io.TextIOWrapper(open_regular(path), encoding="utf-8")
    except OSError as error:
        raise UserModelError(f"cannot read trace: {reason(error)}",
                             location=SourceLocation(name)) from None
    try:
        header_seen = False
        for number, line in enumerate(handle, start=1):
            if not line.strip():
                continue
            try:
                obj = json_loads(line)
            except json.JSONDecodeError as error:
                raise UserModelError(f"not valid JSON: {json_problem(error, one_line=True)}",
                                     location=SourceLocation(name, number),
                                     hint="each line of a trace is one JSON object") from None
            if not header_seen:
                if not isinstance(obj, dict) or obj.get("format") != TRACE_FORMAT:
                    raise UserModelError(
                        "not an opspec trace: the first line must be a header "
                        f'{{"format": "{TRACE_FORMAT}", "version": {TRACE_FORMAT_VERSION}, ...}}',
                        location=SourceLocation(name, number),
                        hint="record traces with `opspec run --trace FILE` or "
                        "`opspec evaluate --export jsonl`")
                if obj.get("version") != TRACE_FORMAT_VERSION:
                    raise UserModelError(
                        f"unsupported trace version {obj.get('version')!r}",
                        location=SourceLocation(name, number),
                        hint=f"this opspec reads version {TRACE_FORMAT_VERSION}")
                header_seen = True
                continue
            try:
                yield TraceEvent.from_json(obj)
            except (KeyError, TypeError, ValueError) as error:
                raise UserModelError(f"not a trace event ({error})",
                                     location=SourceLocation(name, number),
                                     hint='an event needs at least "time" and "kind"') from None
        if not header_seen:
            raise UserModelError("empty trace: no header and no events",
                                 location=SourceLocation(name),
                                 hint="record the trace again; the run may have been killed "
                                 "before it started")
    except UnicodeDecodeError:
        raise UserModelError("not a text trace (it is not UTF-8)",
                             location=SourceLocation(name)) from None
    finally:
        handle.close()


def iter_paths(values: Iterable[str]) -> list[Path]:
    """Expand directories given on the command line to the ``*.jsonl`` files inside."""
    out: list[Path] = []
    for value in values:
        path = Path(value)
        out.extend(sorted(path.glob("*.jsonl")) if path.is_dir() else [path])
    return out
