"""Streaming trace exporters: IEEE 1849-2016 XES for process-mining tools, and JSON Lines.

Both writers share one interface::

    with XesWriter(out / "traces.xes", log_attributes={"concept:name": "dispenser"}) as xes:
        for case_id, events in cases:          # e.g. one case per simulated user
            xes.add_case(case_id, events, attributes={"user": 3, "seed": 1})

``add_case`` consumes its events once and writes them at once; nothing but the case being
written is ever held in memory, so exporting 10,000 users costs what exporting one does.
The output goes to ``<path>.partial`` and is renamed to ``path`` by :meth:`close`, so a
reader never sees half a file; when the ``with`` block ends with an exception the partial
file is left in place (closed, for inspection) and ``path`` is not touched.

An export never grows past the trace cap (1 GiB, or ``OPSPEC_TRACE_MAX_BYTES``; see
``docs/trace-format.md``): the write that would pass it raises an
:class:`~opspec.errors.EvaluationError` saying so, and the ``.partial`` file is left.

The XES mapping (which events, which lifecycle transitions, timestamps, attribute types) is
documented in ``docs/xes-export.md``; the constants below are its single source.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Collection, Iterable, Mapping
from datetime import UTC, datetime, timedelta
from pathlib import Path
from types import TracebackType
from typing import IO, Any, Self

from opspec.engine.trace import TRACE_FORMAT_VERSION, EventKind, TraceEvent
from opspec.engine.trace_sinks import TRACE_MAX_BYTES_ENV, header_line, trace_max_bytes
from opspec.errors import EvaluationError

__all__ = [
    "DEFAULT_EPOCH",
    "DEFAULT_XES_KINDS",
    "LIFECYCLE_TRANSITIONS",
    "XES_NAMESPACE",
    "JsonlTraceWriter",
    "XesWriter",
]

XES_NAMESPACE = "http://www.xes-standard.org/"

#: Simulated time 0 is midnight at the start of this day (a Monday), in UTC.
DEFAULT_EPOCH = datetime(2026, 1, 5, tzinfo=UTC)

#: opspec event kind → XES standard lifecycle transition (lifecycle:model "standard").
LIFECYCLE_TRANSITIONS: Mapping[str, str] = {
    EventKind.QUEUED: "schedule",                 # pooled model: waiting for a free worker
    EventKind.ACTIVITY_OFFERED: "assign",       # handed to its performer (user, device)
    EventKind.ACTIVITY_STARTED: "start",
    EventKind.ACTIVITY_COMPLETED: "complete",
    EventKind.ACTIVITY_WITHDRAWN: "withdraw",   # offer cancelled: deadline, other branch won
    EventKind.ACTIVITY_OMITTED: "manualskip",   # the performer did not do it
    EventKind.ACTIVITY_FAILED: "ate_abort",     # the activity instance ended in a failure
    EventKind.ACTIVITY_ABORTED: "ate_abort",
    EventKind.DEADLINE_EXPIRED: "complete",     # atomic events: they happen, then are done
    EventKind.FAULT: "complete",
    EventKind.PROCESS_ABORTED: "pi_abort",      # the whole workflow instance was aborted
}

#: The kinds exported by default: activity life cycles plus deadlines, faults and aborts.
#: Left out: run/process start and end (the trace boundaries say it), triggers and
#: exceptions (the activities and deadlines they connect are there), data changes (attached
#: to the next event of the same activity as attributes), mode changes and deadlock notes.
DEFAULT_XES_KINDS: frozenset[str] = frozenset(LIFECYCLE_TRANSITIONS)

_EXTENSIONS = (("Concept", "concept"), ("Time", "time"), ("Lifecycle", "lifecycle"),
               ("Organizational", "org"))

# characters XML 1.0 cannot carry at all (control characters, surrogates, U+FFFE/U+FFFF)
_XML_INVALID = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
_XML_ATTR_ESCAPES = str.maketrans({"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;",
                                   "\n": "&#10;", "\r": "&#13;", "\t": "&#9;"})
_XS_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.\-:]*")
_LONG_MIN, _LONG_MAX = -(2**63), 2**63 - 1


def _attr(text: object) -> str:
    """Text as the body of a double-quoted XML attribute (invalid characters become U+FFFD)."""
    return _XML_INVALID.sub("\ufffd", str(text)).translate(_XML_ATTR_ESCAPES)


def _key(name: str) -> str:
    """A valid ``xs:Name`` attribute key: other characters become ``_``."""
    if _XS_NAME.fullmatch(name):
        return name
    cleaned = re.sub(r"[^A-Za-z0-9_.\-:]", "_", name)
    return cleaned if _XS_NAME.fullmatch(cleaned) else f"_{cleaned}"


def _double(value: float) -> str:
    if math.isnan(value):
        return "NaN"
    if math.isinf(value):
        return "INF" if value > 0 else "-INF"
    return repr(value)


def _typed(key: str, value: Any) -> str | None:
    """One XES attribute element for a Python value, or None for a missing value."""
    if value is None:
        return None
    k = _attr(_key(key))
    if isinstance(value, bool):     # before int: bool is an int subclass
        return f'<boolean key="{k}" value="{"true" if value else "false"}"/>'
    if isinstance(value, int) and _LONG_MIN <= value <= _LONG_MAX:
        return f'<int key="{k}" value="{value}"/>'
    if isinstance(value, float):
        return f'<float key="{k}" value="{_double(value)}"/>'
    if isinstance(value, datetime) and value.tzinfo is not None:
        return f'<date key="{k}" value="{value.isoformat(timespec="milliseconds")}"/>'
    if isinstance(value, str):
        return f'<string key="{k}" value="{_attr(value)}"/>'
    try:
        text = json.dumps(value, default=str, sort_keys=True, allow_nan=True)
    except (TypeError, ValueError):
        text = str(value)
    return f'<string key="{k}" value="{_attr(text)}"/>'


class _StreamingWriter:
    """Opens ``<path>.partial``, renames it to ``path`` on a clean close."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._partial = self.path.with_name(self.path.name + ".partial")
        self.cases = 0
        self.events = 0
        self.max_bytes = trace_max_bytes()
        self._bytes = 0
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._handle: IO[str] | None = open(  # noqa: SIM115  (closed by close())
                self._partial, "w", encoding="utf-8", newline="\n")
        except OSError as error:
            raise self._error(error) from None

    def _error(self, error: OSError) -> EvaluationError:
        return EvaluationError(f"cannot write the trace export {self.path}: "
                               f"{error.strerror or error}",
                               hint="check that the output folder is writable and the disk "
                                    "is not full")

    def _check_open(self) -> IO[str]:
        if self._handle is None:
            raise EvaluationError(f"the trace export {self.path} is already closed",
                                  hint="add every case before close()")
        return self._handle

    def _write(self, text: str) -> None:
        handle = self._check_open()
        self._bytes += len(text)
        if self._bytes > self.max_bytes:
            self._abandon()
            raise EvaluationError(
                f"the trace export {self.path} reached its cap of {self.max_bytes:,} bytes "
                f"after {self.cases:,} case(s); it is left as {self._partial.name}",
                hint=f"set {TRACE_MAX_BYTES_ENV} to a larger number of bytes, or export "
                     "fewer users or days")
        try:
            handle.write(text)
        except OSError as error:
            raise self._error(error) from None

    def _footer(self) -> str:
        return ""

    def close(self) -> None:
        """Finish the file and move it into place; calling it again does nothing."""
        if self._handle is None:
            return
        try:
            self._handle.write(self._footer())
            self._handle.close()
            os.replace(self._partial, self.path)
        except OSError as error:
            raise self._error(error) from None
        finally:
            self._handle = None

    def _abandon(self) -> None:
        if self._handle is not None:
            try:
                self._handle.close()
            finally:
                self._handle = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if exc_type is None:
            self.close()
        else:
            self._abandon()


class XesWriter(_StreamingWriter):
    """Writes an IEEE 1849-2016 XES log, one ``<trace>`` per case, streaming.

    - ``log_attributes``: log-level attributes, typed as their values (``seed`` an int;
      ``concept:name`` defaults to ``"opspec traces"``);
    - ``epoch``: the wall-clock instant of simulated time 0 (timezone-aware; default
      :data:`DEFAULT_EPOCH`, 2026-01-05T00:00:00+00:00);
    - ``kinds``: the opspec event kinds exported (default :data:`DEFAULT_XES_KINDS`; only
      kinds in :data:`LIFECYCLE_TRANSITIONS` can be exported);
    - ``activity_names``: optional ``(process id, activity id) → name`` for ``concept:name``
      (the activity id is used otherwise).
    """

    def __init__(self, path: Path, *, log_attributes: Mapping[str, Any] | None = None,
                 epoch: datetime = DEFAULT_EPOCH, kinds: Collection[str] = DEFAULT_XES_KINDS,
                 activity_names: Mapping[tuple[str, str], str] | None = None) -> None:
        if epoch.tzinfo is None or epoch.utcoffset() is None:
            raise EvaluationError(f"XES epoch {epoch.isoformat()} has no time zone",
                                  hint="give a timezone-aware datetime, e.g. "
                                       "datetime(2026, 1, 5, tzinfo=UTC)")
        unknown = sorted(set(kinds) - set(LIFECYCLE_TRANSITIONS))
        if unknown:
            raise EvaluationError(f"cannot export event kinds {', '.join(unknown)} to XES",
                                  hint="choose from " + ", ".join(sorted(LIFECYCLE_TRANSITIONS)))
        self.epoch = epoch
        self.kinds = frozenset(kinds)
        self._names = dict(activity_names or {})
        self._static: dict[tuple[str, str | None, str | None, str | None, str | None], str] = {}
        self._last_time: float | None = None
        self._last_stamp = ""
        super().__init__(path)
        self._write(self._header(dict(log_attributes or {})))

    def _header(self, log_attributes: dict[str, Any]) -> str:
        lines = ['<?xml version="1.0" encoding="UTF-8"?>',
                 f'<log xes.version="1849-2016" xes.features="" xmlns="{XES_NAMESPACE}">']
        lines += [f'  <extension name="{name}" prefix="{prefix}" '
                  f'uri="{XES_NAMESPACE}{prefix}.xesext"/>' for name, prefix in _EXTENSIONS]
        stamp = self.epoch.isoformat(timespec="milliseconds")
        lines += ['  <global scope="trace">', '    <string key="concept:name" value="UNKNOWN"/>',
                  "  </global>",
                  '  <global scope="event">',
                  '    <string key="concept:name" value="UNKNOWN"/>',
                  '    <string key="lifecycle:transition" value="complete"/>',
                  f'    <date key="time:timestamp" value="{stamp}"/>',
                  '    <string key="opspec:kind" value="unknown"/>',
                  "  </global>",
                  '  <classifier name="Activity" keys="concept:name"/>',
                  ('  <classifier name="ActivityLifecycle" '
                  'keys="concept:name lifecycle:transition"/>')]
        attributes: dict[str, Any] = {"concept:name": "opspec traces",
                                      "lifecycle:model": "standard"}
        attributes.update(log_attributes)
        attributes["opspec:epoch"] = self.epoch
        attributes["opspec:trace-format-version"] = TRACE_FORMAT_VERSION
        lines += [f"  {_typed(k, v)}" for k, v in attributes.items() if v is not None]
        return "\n".join(lines) + "\n"

    def _footer(self) -> str:
        return "</log>\n"

    def _timestamp(self, seconds: float) -> str:
        return (self.epoch + timedelta(seconds=seconds)).isoformat(timespec="milliseconds")

    def _name(self, event: TraceEvent) -> str:
        kind, process, activity = event.kind, event.process or "", event.activity
        if kind == EventKind.PROCESS_ABORTED:
            return f"process:{process}"
        if kind == EventKind.DEADLINE_EXPIRED:
            return f"deadline:{activity or process}"
        if kind == EventKind.FAULT:
            return f"fault:{activity or event.participant or event.lane or 'run'}"
        if activity is None:
            return kind
        return self._names.get((process, activity), activity)

    def add_case(self, case_id: str, events: Iterable[TraceEvent],
                 attributes: Mapping[str, Any] | None = None) -> None:
        """Write one ``<trace>``: its attributes, then each exported event in input order.

        ``data.changed`` values are held until the next exported event of the same instance
        and activity (normally its completion) and written on it as typed attributes named
        after the data field; changes with no such later event are dropped. If ``events``
        raises, the writer is abandoned (the ``.partial`` file stays, ``path`` is untouched)
        and the exception propagates: a half-written trace cannot be completed.
        """
        out = ["  <trace>", f'    <string key="concept:name" value="{_attr(case_id)}"/>']
        for key, value in (attributes or {}).items():
            if key != "concept:name":
                element = _typed(key, value)
                if element is not None:
                    out.append(f"    {element}")
        self._write("\n".join(out) + "\n")
        pending: dict[tuple[int | None, str | None], dict[str, Any]] = {}
        written = 0
        try:
            for event in events:
                if event.kind == EventKind.DATA_CHANGED:
                    pending.setdefault((event.instance, event.activity), {}).update(event.data)
                    continue
                if event.kind not in self.kinds:
                    continue
                data = pending.pop((event.instance, event.activity), None)
                if event.activity is not None:
                    data = {**pending.pop((event.instance, None), {}), **(data or {})}
                self._write(self._event(event, data))
                written += 1
        except BaseException:
            # half a <trace> cannot be finished into valid XML: stop here, keep the
            # .partial file for inspection, and refuse further cases
            self._abandon()
            raise
        self._write("  </trace>\n")
        self.cases += 1
        self.events += written

    def _event(self, event: TraceEvent, data: Mapping[str, Any] | None) -> str:
        # The attributes that depend only on the model (name, transition, resource, lane,
        # kind, process, activity) are rendered once per distinct combination and cached:
        # it is bounded by the size of the spec and makes export about twice as fast.
        static_key = (event.kind, event.process, event.activity, event.participant, event.lane)
        head = self._static.get(static_key)
        if head is None:
            head = self._static[static_key] = self._static_part(event)
        if event.time != self._last_time:
            self._last_time = event.time
            self._last_stamp = self._timestamp(event.time)
        parts = [head,
                 f'      <date key="time:timestamp" value="{self._last_stamp}"/>',
                 f'      <float key="opspec:time" value="{_double(float(event.time))}"/>']
        if event.instance is not None:
            parts.append(f'      <int key="opspec:instance" value="{int(event.instance)}"/>')
        fields: dict[str, Any] = {f"opspec:{key}": value for key, value in event.data.items()}
        for key, value in (data or {}).items():
            name = key
            if ":" in key or name in fields:
                name = f"data:{key}"
            fields[name] = value
        for key, value in fields.items():
            element = _typed(key, value)
            if element is not None:
                parts.append(f"      {element}")
        parts.append("    </event>\n")
        return "\n".join(parts)

    def _static_part(self, event: TraceEvent) -> str:
        parts = ["    <event>",
                 f'      <string key="concept:name" value="{_attr(self._name(event))}"/>',
                 (f'      <string key="lifecycle:transition" '
                 f'value="{LIFECYCLE_TRANSITIONS[event.kind]}"/>')]
        if event.participant is not None:
            parts.append(f'      <string key="org:resource" value="{_attr(event.participant)}"/>')
        if event.lane is not None:
            parts.append(f'      <string key="org:group" value="{_attr(event.lane)}"/>')
        parts.append(f'      <string key="opspec:kind" value="{_attr(event.kind)}"/>')
        if event.process is not None:
            parts.append(f'      <string key="opspec:process" value="{_attr(event.process)}"/>')
        if event.activity is not None:
            parts.append(f'      <string key="opspec:activity" value="{_attr(event.activity)}"/>')
        return "\n".join(parts)


class JsonlTraceWriter(_StreamingWriter):
    """Writes the cases as one JSON Lines trace (``docs/trace-format.md``), streaming.

    The header line is ``{"format": "opspec-trace", "version": 1, "cases": true, ...}`` with
    ``log_attributes`` added; every event line is :meth:`TraceEvent.to_json` plus ``"case"``.
    A case given ``attributes`` starts with a ``{"kind": "case.started", "case": ...,
    "data": {attributes}}`` line (readers ignore kinds they do not know).
    """

    def __init__(self, path: Path, *, log_attributes: Mapping[str, Any] | None = None) -> None:
        super().__init__(path)
        head = header_line(log_attributes, cases=True)
        self._write(json.dumps(head, default=str) + "\n")

    def add_case(self, case_id: str, events: Iterable[TraceEvent],
                 attributes: Mapping[str, Any] | None = None) -> None:
        """Write every event of one case (all kinds, input order), tagged with ``case``."""
        self._check_open()
        dumps = json.dumps
        if attributes:
            self._write(dumps({"seq": 0, "time": 0.0, "kind": "case.started",
                               "case": case_id, "data": dict(attributes)},
                              default=str, allow_nan=True) + "\n")
        written = 0
        for event in events:
            obj = event.to_json()
            obj["case"] = case_id
            self._write(dumps(obj, default=str, allow_nan=True) + "\n")
            written += 1
        self.cases += 1
        self.events += written
