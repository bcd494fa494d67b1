"""Reading recorded traces for ``opspec fit`` and ``opspec model-check``: the files a command
line names and the events of each.

A trace file is JSON Lines (``docs/trace-format.md``): a header line
``{"format": "opspec-trace", "version": 1, ...}`` then one ``TraceEvent.to_json()`` object per
line. :func:`read_trace` streams its events and names ``path:line`` for what it cannot read;
:func:`expand_traces` expands the folders a command line gives to the trace files inside
(subfolders included, a study's broken-off sessions left out, each file once).
"""

from __future__ import annotations

import io
import json
import re
from collections.abc import Iterable, Iterator
from pathlib import Path

from opspec.engine.trace import TRACE_FORMAT, TRACE_FORMAT_VERSION, TraceEvent
from opspec.errors import SourceLocation, UserModelError
from opspec.files import json_loads, json_problem

__all__ = ["expand_traces", "iter_paths", "read_trace", "trace_header"]


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
                if not header_seen and _is_script(path):
                    raise _script_error(path) from None
                # the last line, after whole events, without its newline: cut, not wrong
                cut = header_seen and not line.endswith("\n")
                raise UserModelError(
                    f"not valid JSON: {json_problem(error, one_line=True)}"
                    + ("; the file's last line is cut short" if cut else ""),
                    location=SourceLocation(name, number),
                    hint="the recording stopped in the middle of a line (a crash, a full "
                    "disk): remove that last line, the events before it are whole" if cut
                    else "each line of a trace is one JSON object") from None
            if not header_seen:
                if not isinstance(obj, dict) or obj.get("format") != TRACE_FORMAT:
                    if _is_script(path):
                        raise _script_error(path)
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


def trace_header(path: str | Path) -> dict[str, object]:
    """The first JSON line of a trace file (an empty dict when it cannot be read: the trace
    reader then says what is wrong with the file, naming it)."""
    from opspec.files import open_regular

    try:
        # a pipe or device is refused, never read (it would block); read_trace then says so
        with io.TextIOWrapper(open_regular(path), encoding="utf-8") as handle:
            for line in handle:
                if line.strip():
                    head = json_loads(line)
                    return head if isinstance(head, dict) else {}
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return {}
    return {}


def _is_script(path: str | Path) -> bool:
    """Whether ``path`` is a script: a walkthrough's recording (``{"steps": [...]}``, the
    actions to replay), which people give for the trace written beside it."""
    from opspec.files import open_regular

    try:
        with io.TextIOWrapper(open_regular(path), encoding="utf-8") as handle:
            text = handle.read(4 * 1024 * 1024)
        doc = json_loads(text)
    except (OSError, UnicodeDecodeError, ValueError):
        return False
    return isinstance(doc, dict) and isinstance(doc.get("steps"), list)


def _script_error(path: str | Path) -> UserModelError:
    beside = Path(path).with_suffix(".trace.jsonl")
    return UserModelError(
        "a walkthrough recording or script (the actions to replay), not a trace",
        location=SourceLocation(str(path), 1),
        hint=(f"its trace is {beside}: give that, or the folder holding both"
              if beside.is_file() else "give the trace written beside the recording "
              "(NAME.trace.jsonl), or record one with `opspec run --trace FILE`"))


#: the trace of a study session that broke off (``opspec study``: ``VARIANT.partial-N.*``)
_BROKEN_OFF = re.compile(r"\.partial-\d+\.trace\.jsonl$")


def expand_traces(values: Iterable[str]) -> tuple[list[Path], list[Path]]:
    """The trace files the command line names: ``(traces, left_out)``. A folder stands for
    the ``*.jsonl`` files in it and in its subfolders (a study's
    ``RECORDINGS/PARTICIPANT/VARIANT.trace.jsonl``), except the traces of study sessions
    that broke off (``*.partial-N.trace.jsonl``, done again in full), which are
    ``left_out``; a file named itself is always taken. A file reached twice (named, and in a
    folder also named) is read once: its sessions would otherwise count twice."""
    out: list[Path] = []
    left_out: list[Path] = []
    seen: set[Path] = set()

    def take(path: Path) -> None:
        try:
            key = path.resolve()
        except OSError:
            key = path
        if key not in seen:
            seen.add(key)
            out.append(path)

    for value in values:
        path = Path(value)
        if not path.is_dir():
            take(path)
            continue
        for found in sorted(path.rglob("*.jsonl")):
            if _BROKEN_OFF.search(found.name):
                left_out.append(found)
            else:               # a pipe or a folder so named: read_trace says what it is
                take(found)
    return out, [p for p in left_out if p.resolve() not in seen]


def iter_paths(values: Iterable[str]) -> list[Path]:
    """The trace files of :func:`expand_traces`, without those it leaves out."""
    return expand_traces(values)[0]
