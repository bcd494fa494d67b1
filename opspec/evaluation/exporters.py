"""Streaming trace exporters: IEEE 1849-2016 XES for process-mining tools, and JSON Lines.

Both writers share one interface::

    with XesWriter(out / "traces.xes", log_attributes={"concept:name": "dispenser"}) as xes:
        for case_id, events in cases:          # e.g. one case per simulated user
            xes.add_case(case_id, events, attributes={"user": 3, "seed": 1})

``add_case`` consumes its events once and writes them at once; nothing but the case being
written is ever held in memory, so exporting 10,000 users costs what exporting one does. XES is
written with lxml's incremental writer (``lxml.etree.xmlfile``): every element and attribute
is serialised and escaped by lxml, never assembled from strings.
The output goes to ``<path>.partial`` and is renamed to ``path`` by :meth:`close`, so a
reader never sees half a file; when the ``with`` block ends with an exception the partial
file is left in place (closed, for inspection) and ``path`` is not touched.

An export never grows past the trace cap (1 GiB, or ``OPSPEC_TRACE_MAX_BYTES``; see
``docs/trace-format.md``): the write that would pass it raises an
:class:`~opspec.errors.EvaluationError` saying so, and the ``.partial`` file is left. A write
the disk refuses (full, gone) is an EvaluationError too, also when it happens while closing
or abandoning the file: never a bare OSError.

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
from typing import IO, TYPE_CHECKING, Any, Self

from opspec.engine.trace import TRACE_FORMAT_VERSION, EventKind, TraceEvent
from opspec.engine.trace_sinks import TRACE_MAX_BYTES_ENV, header_line, trace_max_bytes
from opspec.errors import EvaluationError

if TYPE_CHECKING:
    from lxml import etree

    #: an event's model-dependent part, with its timestamp, time and instance elements
    _Template = tuple[etree._Element, etree._Element, etree._Element, etree._Element | None]

__all__ = [
    "DEFAULT_EPOCH",
    "DEFAULT_XES_KINDS",
    "LIFECYCLE_TRANSITIONS",
    "XES_NAMESPACE",
    "JsonlTraceWriter",
    "XesWriter",
    "qualified_name",
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

# characters XML 1.0 cannot carry at all (control characters, surrogates, U+FFFE/U+FFFF):
# lxml refuses them, so they become U+FFFD
_XML_INVALID = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
_XS_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.\-:]*")
_LONG_MIN, _LONG_MAX = -(2**63), 2**63 - 1


def _text(value: object) -> str:
    """Text XML can carry (invalid characters become U+FFFD); lxml escapes the rest."""
    return _XML_INVALID.sub("\ufffd", str(value))


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


def _typed(key: str, value: Any) -> tuple[str, str, str] | None:
    """(XES type tag, key, value text) of one attribute for a Python value; None for a
    missing value."""
    if value is None:
        return None
    k = _text(_key(key))
    if isinstance(value, bool):     # before int: bool is an int subclass
        return "boolean", k, "true" if value else "false"
    if isinstance(value, int) and _LONG_MIN <= value <= _LONG_MAX:
        return "int", k, str(value)
    if isinstance(value, float):
        return "float", k, _double(value)
    if isinstance(value, datetime) and value.tzinfo is not None:
        return "date", k, value.isoformat(timespec="milliseconds")
    if isinstance(value, str):
        return "string", k, _text(value)
    try:
        text = json.dumps(value, default=str, sort_keys=True, allow_nan=True)
    except (TypeError, ValueError):
        text = str(value)
    return "string", k, _text(text)


def _add(parent: etree._Element, attribute: tuple[str, str, str] | None) -> None:
    if attribute is not None:
        tag, key, value = attribute
        from lxml import etree  # lxml loads with the first XES export, not on import

        etree.SubElement(parent, tag, key=key, value=value)


def qualified_name(process: str | None, activity: str) -> str:
    """An activity's name in exports: qualified by its process (``user_workflow/take_pill``),
    since activity ids are unique only within their process."""
    return f"{process}/{activity}" if process else activity


class _DiskFile:
    """The binary file under an export: counts bytes against the cap, and turns the disk's
    refusals (full, gone) into EvaluationErrors naming the export."""

    def __init__(self, owner: _StreamingWriter, handle: IO[bytes]) -> None:
        self.owner = owner
        self.handle = handle
        self.written = 0

    def write(self, data: bytes | str) -> int:
        raw = data.encode("utf-8") if isinstance(data, str) else data
        self.written += len(raw)
        if self.written > self.owner.max_bytes:
            raise self.owner._over_cap()
        try:
            return self.handle.write(raw)
        except OSError as error:
            raise self.owner._error(error) from None


class _StreamingWriter:
    """Opens ``<path>.partial``, renames it to ``path`` on a clean close."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._partial = self.path.with_name(self.path.name + ".partial")
        self.cases = 0
        self.events = 0
        self.max_bytes = trace_max_bytes()
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            handle = open(self._partial, "wb")  # noqa: SIM115  (closed by close())
        except OSError as error:
            raise self._error(error) from None
        self._file: _DiskFile | None = _DiskFile(self, handle)

    @property
    def bytes_written(self) -> int:
        return self._file.written if self._file is not None else 0

    def _error(self, error: OSError) -> EvaluationError:
        return EvaluationError(f"cannot write the trace export {self.path}: "
                               f"{error.strerror or error}",
                               hint="check that the output folder is writable and the disk "
                                    "is not full")

    def _over_cap(self) -> EvaluationError:
        self._abandon()
        return EvaluationError(
            f"the trace export {self.path} reached its cap of {self.max_bytes:,} bytes "
            f"after {self.cases:,} case(s); it is left as {self._partial.name}",
            hint=f"set {TRACE_MAX_BYTES_ENV} to a larger number of bytes, or export "
                 "fewer users or days")

    def _check_open(self) -> _DiskFile:
        if self._file is None:
            raise EvaluationError(f"the trace export {self.path} is already closed",
                                  hint="add every case before close()")
        return self._file

    def _write(self, text: str) -> None:
        self._check_open().write(text)

    def _finish(self) -> None:
        """Write what ends the file (subclasses)."""

    def close(self) -> None:
        """Finish the file and move it into place; calling it again does nothing."""
        if self._file is None:
            return
        file = self._file
        try:
            self._finish()
            file.handle.close()
            os.replace(self._partial, self.path)
        except OSError as error:
            raise self._error(error) from None
        finally:
            self._file = None
            if not file.handle.closed:
                self._close_quietly(file.handle)

    def _abandon(self) -> None:
        """Stop writing: the ``.partial`` file stays as it is, for inspection."""
        if self._file is not None:
            handle, self._file = self._file.handle, None
            self._close_quietly(handle)

    @staticmethod
    def _close_quietly(handle: IO[bytes]) -> None:
        # abandoning after an error: a disk that refuses the last buffered bytes too must
        # not replace the error being raised
        try:
            handle.close()
        except OSError:
            pass

    def __enter__(self) -> Self:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if exc_type is None:
            self.close()
        else:
            self._abandon()


class XesWriter(_StreamingWriter):
    """Writes an IEEE 1849-2016 XES log, one ``<trace>`` per case, streaming (lxml's
    incremental writer).

    - ``log_attributes``: log-level attributes, typed as their values (``seed`` an int;
      ``concept:name`` defaults to ``"opspec traces"``);
    - ``epoch``: the wall-clock instant of simulated time 0 (timezone-aware; default
      :data:`DEFAULT_EPOCH`, 2026-01-05T00:00:00+00:00);
    - ``kinds``: the opspec event kinds exported (default :data:`DEFAULT_XES_KINDS`; only
      kinds in :data:`LIFECYCLE_TRANSITIONS` can be exported);
    - ``activity_names``: optional ``(process id, activity id) → name`` for ``concept:name``
      (by default the activity id qualified by its process, :func:`qualified_name`);
    - ``lane_names``: optional lane id → the lane's name for ``org:group`` (a lane without
      one stays its id; :func:`opspec.engine.lane_labels.lane_labels` reads them).
    """

    def __init__(self, path: Path, *, log_attributes: Mapping[str, Any] | None = None,
                 epoch: datetime = DEFAULT_EPOCH, kinds: Collection[str] = DEFAULT_XES_KINDS,
                 activity_names: Mapping[tuple[str, str], str] | None = None,
                 lane_names: Mapping[str, str] | None = None) -> None:
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
        self._lanes = dict(lane_names or {})
        self._static: dict[tuple[str, str | None, str | None, str | None, str | None, bool],
                           _Template] = {}
        self._last_time: float | None = None
        self._last_stamp = ""
        super().__init__(path)
        self._file_context: Any = None     # lxml's xmlfile, entered by hand: a log spans
        self._log: Any = None              # many add_case calls
        from lxml import etree

        try:
            self._file_context = etree.xmlfile(self._check_open(), encoding="utf-8")
            self._xml = self._file_context.__enter__()
            self._xml.write_declaration()
            self._log = self._xml.element("log", {"xes.version": "1849-2016",
                                                  "xes.features": ""},
                                          nsmap={None: XES_NAMESPACE})
            self._log.__enter__()
            self._xml.write("\n")
            self._xml.write(*self._header(dict(log_attributes or {})), pretty_print=True)
        except BaseException:
            self._abandon()
            raise

    def _header(self, log_attributes: dict[str, Any]) -> list[etree._Element]:
        from lxml import etree

        out: list[etree._Element] = []
        for name, prefix in _EXTENSIONS:
            out.append(etree.Element("extension", name=name, prefix=prefix,
                                     uri=f"{XES_NAMESPACE}{prefix}.xesext"))
        trace_globals = etree.Element("global", scope="trace")
        etree.SubElement(trace_globals, "string", key="concept:name", value="UNKNOWN")
        event_globals = etree.Element("global", scope="event")
        stamp = self.epoch.isoformat(timespec="milliseconds")
        for tag, key, value in (("string", "concept:name", "UNKNOWN"),
                                ("string", "lifecycle:transition", "complete"),
                                ("date", "time:timestamp", stamp),
                                ("string", "opspec:kind", "unknown")):
            etree.SubElement(event_globals, tag, key=key, value=value)
        out += [trace_globals, event_globals,
                etree.Element("classifier", name="Activity", keys="concept:name"),
                etree.Element("classifier", name="ActivityLifecycle",
                              keys="concept:name lifecycle:transition")]
        attributes: dict[str, Any] = {"concept:name": "opspec traces",
                                      "lifecycle:model": "standard"}
        attributes.update(log_attributes)
        attributes["opspec:epoch"] = self.epoch
        attributes["opspec:trace-format-version"] = TRACE_FORMAT_VERSION
        holder = etree.Element("log")
        for key, value in attributes.items():
            _add(holder, _typed(key, value))
        return out + list(holder)

    def _finish(self) -> None:
        self._log.__exit__(None, None, None)
        self._file_context.__exit__(None, None, None)

    def _timestamp(self, seconds: float) -> str:
        return (self.epoch + timedelta(seconds=seconds)).isoformat(timespec="milliseconds")

    def _name(self, event: TraceEvent) -> str:
        kind, process, activity = event.kind, event.process or "", event.activity
        if kind == EventKind.PROCESS_ABORTED:
            return f"process:{process}"
        if kind == EventKind.DEADLINE_EXPIRED:
            return f"deadline:{qualified_name(process, activity or process)}"
        if kind == EventKind.FAULT:
            where = activity or event.participant or event.lane or "run"
            return f"fault:{qualified_name(process, where) if activity else where}"
        if activity is None:
            return kind
        return self._names.get((process, activity)) or qualified_name(process, activity)

    def add_case(self, case_id: str, events: Iterable[TraceEvent],
                 attributes: Mapping[str, Any] | None = None) -> None:
        """Write one ``<trace>``: its attributes, then each exported event in input order.

        ``data.changed`` values are held until the next exported event of the same instance
        and activity (normally its completion) and written on it as typed attributes named
        after the data field; changes with no such later event are dropped. If ``events``
        raises, the writer is abandoned (the ``.partial`` file stays, ``path`` is untouched)
        and the exception propagates: a half-written trace cannot be completed.
        """
        self._check_open()
        from lxml import etree

        xml = self._xml
        trace = xml.element("trace")
        head = etree.Element("trace")
        etree.SubElement(head, "string", key="concept:name", value=_text(case_id))
        for key, value in (attributes or {}).items():
            if key != "concept:name":
                _add(head, _typed(key, value))
        pending: dict[tuple[int | None, str | None], dict[str, Any]] = {}
        written = 0
        try:
            trace.__enter__()
            xml.write("\n")
            xml.write(*head, pretty_print=True)
            for event in events:
                if event.kind == EventKind.DATA_CHANGED:
                    pending.setdefault((event.instance, event.activity), {}).update(event.data)
                    continue
                if event.kind not in self.kinds:
                    continue
                data = pending.pop((event.instance, event.activity), None)
                if event.activity is not None:
                    data = {**pending.pop((event.instance, None), {}), **(data or {})}
                xml.write(self._event(event, data), pretty_print=True)
                written += 1
            trace.__exit__(None, None, None)
            xml.write("\n")
        except BaseException:
            # half a <trace> cannot be finished into valid XML: stop here, keep the
            # .partial file for inspection, and refuse further cases
            self._abandon()
            raise
        self.cases += 1
        self.events += written

    def _event(self, event: TraceEvent, data: Mapping[str, Any] | None) -> etree._Element:
        # The attributes that depend only on the model (name, transition, resource, lane,
        # kind, process, activity) are built once per distinct combination (bounded by the
        # size of the spec) into a template <event> that also holds the timestamp, time and
        # instance elements. An event without data of its own is that template with those
        # three values set, written at once by the caller (the incremental writer serialises
        # it before the next event changes it): no element is built per event, a third of
        # the cost of copying the template and adding three elements to the copy.
        static_key = (event.kind, event.process, event.activity, event.participant,
                      event.lane, event.instance is not None)
        template = self._static.get(static_key)
        if template is None:
            template = self._static[static_key] = self._template(event)
        element, stamp, time, instance = template
        if event.time != self._last_time:
            self._last_time = event.time
            self._last_stamp = self._timestamp(event.time)
        stamp.set("value", self._last_stamp)
        time.set("value", _double(float(event.time)))
        if instance is not None:
            instance.set("value", str(int(event.instance)))  # type: ignore[arg-type]
        if not (event.data or data):
            return element
        element = element.__copy__()          # this event's data on a copy of its own
        fields: dict[str, Any] = {f"opspec:{key}": value for key, value in event.data.items()}
        for key, value in (data or {}).items():
            name = key
            if ":" in key or name in fields:
                name = f"data:{key}"
            fields[name] = value
        for key, value in fields.items():
            _add(element, _typed(key, value))
        return element

    def _template(self, event: TraceEvent) -> _Template:
        from lxml import etree

        element = etree.Element("event")
        parts = [("string", "concept:name", _text(self._name(event))),
                 ("string", "lifecycle:transition", LIFECYCLE_TRANSITIONS[event.kind])]
        if event.participant is not None:
            parts.append(("string", "org:resource", _text(event.participant)))
        if event.lane is not None:
            parts.append(("string", "org:group",
                          _text(self._lanes.get(event.lane, event.lane))))
        parts.append(("string", "opspec:kind", _text(event.kind)))
        if event.process is not None:
            parts.append(("string", "opspec:process", _text(event.process)))
        if event.activity is not None:
            parts.append(("string", "opspec:activity", _text(event.activity)))
        for part in parts:
            _add(element, part)
        sub = etree.SubElement
        stamp = sub(element, "date", key="time:timestamp", value="")
        time = sub(element, "float", key="opspec:time", value="")
        instance = (sub(element, "int", key="opspec:instance", value="")
                    if event.instance is not None else None)
        return element, stamp, time, instance


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
        try:
            self._write(json.dumps(head, default=str) + "\n")
        except BaseException:
            self._abandon()
            raise

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
