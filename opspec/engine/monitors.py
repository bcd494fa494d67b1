"""Monitors: safety properties checked while a run happens, as trace listeners.

A :class:`Monitor` is a declarative property ("no dispense within 4 h of the previous one");
:meth:`Monitor.start` gives a fresh :class:`MonitorRun` for one run, a trace listener with a
``selects`` attribute (so the engine builds only the events the monitor needs) that records
each :class:`Violation` with its time and the few relevant events before it.

The text form (the value of a package ``ExtendedAttribute Name="opspec:Monitor"``, one
monitor per line, ``#`` starts a comment) is read by :func:`parse_monitor`::

    min_gap dispense 4h                              no two occurrences closer than 4 h
    never notify_caregiver                           it never happens
    never_while dispense after record_missed until sound_alarm
    max_count dispense 4 per 24h                     at most 4 in any 24 h window
    bounded_response sound_alarm dispense|record_missed 15 min

A *subject* is an activity id (its completion), a trigger name (raised) or a process id (an
instance started), resolved against the spec's names by :meth:`Monitor.bind`; it may be made
explicit: ``activity:dispense``, ``trigger:trg_2``, ``process:notify_workflow``, and
``a|b`` means either. Durations are read by :mod:`opspec.clock` (``90``, ``90s``, ``5 min``,
``1h30m``, ``PT4H``), as everywhere else.

Over many runs, violations become a hazard: :func:`opspec.statistics.poisson_interval` gives
the exact (Garwood) interval of a rate of events per unit of exposure (e.g. per user-day).

Pure Python, no wall clock: importable by any layer above the engine.
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Protocol

from opspec.clock import parse_duration, span
from opspec.engine.trace import EventKind, TraceEvent
from opspec.errors import ConfigurationError, SourceLocation

__all__ = [
    "MONITOR_ATTRIBUTE",
    "BoundedResponse",
    "MaxCount",
    "MinGap",
    "Monitor",
    "MonitorResult",
    "MonitorRun",
    "Names",
    "Never",
    "NeverWhile",
    "Subject",
    "Violation",
    "declared_monitors",
    "package_monitors",
    "parse_monitor",
    "parse_subject",
]

#: the package ExtendedAttribute holding monitors in their text form
MONITOR_ATTRIBUTE = "opspec:Monitor"
#: how many relevant events a violation keeps (its trace slice)
SLICE = 8
#: violations kept with their slice per run (all are counted)
KEEP = 50

_KINDS = {"activity": EventKind.ACTIVITY_COMPLETED, "trigger": EventKind.TRIGGER_RAISED,
          "process": EventKind.PROCESS_STARTED}


class Names(Protocol):
    """The names a spec defines (``opspec.testing.simulation.SpecNames`` is one)."""

    @property
    def activities(self) -> tuple[str, ...]: ...
    @property
    def triggers(self) -> tuple[str, ...]: ...
    @property
    def processes(self) -> tuple[str, ...]: ...


@dataclass(frozen=True, slots=True)
class Subject:
    """What a monitor or predicate counts: completions of an activity, raises of a trigger,
    starts of a process; ``what`` is ``None`` until resolved (then any of the three match).
    ``alternatives`` holds the others of ``a|b``."""

    name: str
    what: str | None = None
    alternatives: tuple[Subject, ...] = ()

    def __str__(self) -> str:
        own = f"{self.what} {self.name}" if self.what else self.name
        return " or ".join([own, *map(str, self.alternatives)])

    def matches(self, event: TraceEvent) -> bool:
        if self._own(event):
            return True
        return any(alt.matches(event) for alt in self.alternatives)

    def _own(self, event: TraceEvent) -> bool:
        what, kind = self.what, event.kind
        if kind == EventKind.ACTIVITY_COMPLETED:
            return what in (None, "activity") and event.activity == self.name
        if kind == EventKind.TRIGGER_RAISED:
            return what in (None, "trigger") and event.data.get("name") == self.name
        if kind == EventKind.PROCESS_STARTED:
            return what in (None, "process") and event.process == self.name
        return False

    @property
    def selects(self) -> frozenset[tuple[str, str | None, str | None]]:
        """Engine selectors of the events this subject may match."""
        own: set[tuple[str, str | None, str | None]] = set()
        if self.what in (None, "activity"):
            own.add((EventKind.ACTIVITY_COMPLETED, None, self.name))
        if self.what in (None, "trigger"):
            own.add((EventKind.TRIGGER_RAISED, None, None))
        if self.what in (None, "process"):
            own.add((EventKind.PROCESS_STARTED, self.name, None))
        for alt in self.alternatives:
            own |= alt.selects
        return frozenset(own)

    def bind(self, names: Names) -> Subject:
        """This subject with ``what`` resolved (activity, then trigger, then process);
        :class:`ConfigurationError` listing the spec's names when it has no such name."""
        alternatives = tuple(alt.bind(names) for alt in self.alternatives)
        table = {"activity": names.activities, "trigger": names.triggers,
                 "process": names.processes}
        if self.what is not None:
            if self.name not in table[self.what]:
                raise ConfigurationError(
                    f"the spec has no {self.what} {self.name!r}",
                    hint=f"its {self.what} names are: {', '.join(table[self.what]) or '(none)'}")
            return replace(self, alternatives=alternatives)
        for what, known in table.items():
            if self.name in known:
                return Subject(self.name, what, alternatives)
        raise ConfigurationError(
            f"the spec has no activity, trigger or process {self.name!r}",
            hint="its activities are: " + ", ".join(names.activities)
                 + "; triggers: " + (", ".join(names.triggers) or "(none)")
                 + "; processes: " + ", ".join(names.processes))


_SUBJECT = re.compile(r"(?:(?P<what>activity|trigger|process):)?(?P<name>[\w.-]+)")


def parse_subject(text: str) -> Subject:
    """``dispense``, ``activity:dispense``, ``trigger:trg_2``, ``process:p``, ``a|b``."""
    parts = [p.strip() for p in text.split("|")]
    subjects = []
    for part in parts:
        match = _SUBJECT.fullmatch(part)
        if match is None:
            raise ConfigurationError(
                f"cannot read {part!r} as an activity, trigger or process name",
                hint="write a name, optionally prefixed: activity:NAME, trigger:NAME, "
                     "process:NAME; 'a|b' for either")
        subjects.append(Subject(match["name"], match["what"]))
    return replace(subjects[0], alternatives=tuple(subjects[1:]))


def _seconds(text: str) -> float:
    value = parse_duration(text, error=ConfigurationError)
    if value <= 0:
        raise ConfigurationError(f"{text!r} is not a positive duration",
                                 hint="write e.g. 90s, 5 min, 4h or PT4H")
    return value


def clock(seconds: float) -> str:
    """``day 1 08:00:00.0`` for simulated seconds (the format of trace listings)."""
    seconds = round(seconds, 1)         # 59.96 s is shown as the next minute, not "60.0"
    day, rest = divmod(seconds, 86_400.0)
    hours, rest = divmod(rest, 3600.0)
    minutes, secs = divmod(rest, 60.0)
    return f"day {int(day) + 1} {int(hours):02d}:{int(minutes):02d}:{secs:04.1f}"


# ---------------------------------------------------------------- violations and runs
@dataclass(frozen=True, slots=True)
class Violation:
    """One violation of ``monitor`` at simulated ``time`` in ``replication``, with the
    relevant events that led to it (oldest first)."""

    monitor: str
    time: float
    message: str
    events: tuple[TraceEvent, ...] = ()
    replication: int = 0

    def __str__(self) -> str:
        return f"{clock(self.time)}: {self.monitor}: {self.message}"


@dataclass(frozen=True, slots=True)
class MonitorResult:
    """What one monitor saw in one run: ``count`` violations, the first of them kept."""

    monitor: str
    replication: int
    count: int
    violations: tuple[Violation, ...] = ()


class MonitorRun:
    """One monitor watching one run: a trace listener. Subclasses implement
    :meth:`observe` (and :meth:`finish` when a violation can be due to something that did not
    happen). ``violations`` keeps the first :data:`KEEP`; ``count`` counts all."""

    def __init__(self, monitor: Monitor, replication: int) -> None:
        self.monitor = monitor
        self.replication = replication
        self.selects = monitor.selects
        self.violations: list[Violation] = []
        self.count = 0
        self.recent: deque[TraceEvent] = deque(maxlen=SLICE)

    def __call__(self, event: TraceEvent) -> None:
        if self.monitor.relevant(event):
            self.recent.append(event)
            self.observe(event)

    def observe(self, event: TraceEvent) -> None:
        raise NotImplementedError

    def finish(self, end: float) -> None:
        """The run ended at simulated time ``end`` (judge what is still pending)."""

    def result(self) -> MonitorResult:
        """The frozen outcome (call after :meth:`finish`)."""
        return MonitorResult(self.monitor.text, self.replication, self.count,
                             tuple(self.violations))

    def violate(self, time: float, message: str,
                events: Iterable[TraceEvent] | None = None) -> None:
        self.count += 1
        if len(self.violations) < KEEP:
            chosen = tuple(self.recent) if events is None else tuple(events)
            self.violations.append(Violation(self.monitor.text, time, message, chosen,
                                             self.replication))


@dataclass(frozen=True, slots=True)
class Monitor:
    """A safety property; ``text`` is its text form (also its name in reports)."""

    text: str = field(default="", kw_only=True)

    def subjects(self) -> tuple[Subject, ...]:
        raise NotImplementedError

    def _with(self, subjects: Sequence[Subject]) -> Monitor:
        raise NotImplementedError

    def bind(self, names: Names) -> Monitor:
        """This monitor with its subjects resolved against the spec's names."""
        return self._with([s.bind(names) for s in self.subjects()])

    @property
    def selects(self) -> frozenset[tuple[str, str | None, str | None]]:
        out: frozenset[tuple[str, str | None, str | None]] = frozenset()
        for subject in self.subjects():
            out |= subject.selects
        return out

    def relevant(self, event: TraceEvent) -> bool:
        return any(s.matches(event) for s in self.subjects())

    def start(self, replication: int = 0) -> MonitorRun:
        """A fresh listener for one run."""
        raise NotImplementedError


@dataclass(frozen=True, slots=True)
class MinGap(Monitor):
    """No two occurrences of ``subject`` closer than ``seconds``."""

    subject: Subject
    seconds: float

    def subjects(self) -> tuple[Subject, ...]:
        return (self.subject,)

    def _with(self, subjects: Sequence[Subject]) -> Monitor:
        return replace(self, subject=subjects[0])

    def start(self, replication: int = 0) -> MonitorRun:
        return _MinGapRun(self, replication)


class _MinGapRun(MonitorRun):
    monitor: MinGap

    def __init__(self, monitor: MinGap, replication: int) -> None:
        super().__init__(monitor, replication)
        self.last: TraceEvent | None = None

    def observe(self, event: TraceEvent) -> None:
        last, gap = self.last, self.monitor.seconds
        if last is not None and event.time - last.time < gap:
            self.violate(event.time, f"{self.monitor.subject} at {clock(last.time)} and again "
                         f"at {clock(event.time)}, {span(event.time - last.time)} apart "
                         f"(at least {span(gap)} required)", (last, event))
        self.last = event


@dataclass(frozen=True, slots=True)
class Never(Monitor):
    """``subject`` never happens."""

    subject: Subject

    def subjects(self) -> tuple[Subject, ...]:
        return (self.subject,)

    def _with(self, subjects: Sequence[Subject]) -> Monitor:
        return replace(self, subject=subjects[0])

    def start(self, replication: int = 0) -> MonitorRun:
        return _NeverRun(self, replication)


class _NeverRun(MonitorRun):
    monitor: Never

    def observe(self, event: TraceEvent) -> None:
        self.violate(event.time, f"{self.monitor.subject} happened at {clock(event.time)}")


@dataclass(frozen=True, slots=True)
class NeverWhile(Monitor):
    """``subject`` never happens after ``after`` until the next ``until`` (a window that is
    open from the first ``after`` until an ``until`` closes it)."""

    subject: Subject
    after: Subject
    until: Subject

    def subjects(self) -> tuple[Subject, ...]:
        return (self.subject, self.after, self.until)

    def _with(self, subjects: Sequence[Subject]) -> Monitor:
        return replace(self, subject=subjects[0], after=subjects[1], until=subjects[2])

    def start(self, replication: int = 0) -> MonitorRun:
        return _NeverWhileRun(self, replication)


class _NeverWhileRun(MonitorRun):
    monitor: NeverWhile

    def __init__(self, monitor: NeverWhile, replication: int) -> None:
        super().__init__(monitor, replication)
        self.opened: TraceEvent | None = None

    def observe(self, event: TraceEvent) -> None:
        m = self.monitor
        if self.opened is not None and m.subject.matches(event):
            self.violate(event.time, f"{m.subject} at {clock(event.time)}, after {m.after} at "
                         f"{clock(self.opened.time)} and before any {m.until}")
        if m.until.matches(event):
            self.opened = None
        elif m.after.matches(event) and self.opened is None:
            self.opened = event


@dataclass(frozen=True, slots=True)
class MaxCount(Monitor):
    """At most ``limit`` occurrences of ``subject`` in any window of ``seconds``."""

    subject: Subject
    limit: int
    seconds: float

    def subjects(self) -> tuple[Subject, ...]:
        return (self.subject,)

    def _with(self, subjects: Sequence[Subject]) -> Monitor:
        return replace(self, subject=subjects[0])

    def start(self, replication: int = 0) -> MonitorRun:
        return _MaxCountRun(self, replication)


class _MaxCountRun(MonitorRun):
    monitor: MaxCount

    def __init__(self, monitor: MaxCount, replication: int) -> None:
        super().__init__(monitor, replication)
        self.window: deque[TraceEvent] = deque()

    def observe(self, event: TraceEvent) -> None:
        m = self.monitor
        self.window.append(event)
        while event.time - self.window[0].time >= m.seconds:
            self.window.popleft()
        if len(self.window) > m.limit:
            self.violate(event.time, f"{m.subject} happened {len(self.window)} times within "
                         f"{span(event.time - self.window[0].time)} (from "
                         f"{clock(self.window[0].time)}); at most {m.limit} per "
                         f"{span(m.seconds)} allowed", tuple(self.window)[-SLICE:])


@dataclass(frozen=True, slots=True)
class BoundedResponse(Monitor):
    """Every ``trigger`` is followed by a ``response`` within ``seconds`` (one response
    answers every trigger pending before it). A window cut off by the end of the run is not
    judged."""

    trigger: Subject
    response: Subject
    seconds: float

    def subjects(self) -> tuple[Subject, ...]:
        return (self.trigger, self.response)

    def _with(self, subjects: Sequence[Subject]) -> Monitor:
        return replace(self, trigger=subjects[0], response=subjects[1])

    def start(self, replication: int = 0) -> MonitorRun:
        return _ResponseRun(self, replication)


class _ResponseRun(MonitorRun):
    monitor: BoundedResponse

    def __init__(self, monitor: BoundedResponse, replication: int) -> None:
        super().__init__(monitor, replication)
        self.pending: deque[TraceEvent] = deque()

    def _expire(self, now: float, inclusive: bool) -> None:
        m = self.monitor
        while self.pending and (self.pending[0].time + m.seconds < now or (
                inclusive and self.pending[0].time + m.seconds <= now)):
            cause = self.pending.popleft()
            due = cause.time + m.seconds
            self.violate(due, f"{m.trigger} at {clock(cause.time)} got no {m.response} "
                         f"within {span(m.seconds)} (due by {clock(due)})",
                         [e for e in self.recent if e.seq >= cause.seq])

    def observe(self, event: TraceEvent) -> None:
        m = self.monitor
        self._expire(event.time, inclusive=False)
        if m.response.matches(event):
            self.pending.clear()
        if m.trigger.matches(event):
            self.pending.append(event)

    def finish(self, end: float) -> None:
        # windows that closed before the end are judged; ones still open are not
        self._expire(end, inclusive=False)


# ---------------------------------------------------------------- the text form
_FORMS: list[tuple[str, re.Pattern[str]]] = [
    ("min_gap", re.compile(r"min_gap\s+(?P<a>\S+)\s+(?P<d>.+)")),
    ("never_while", re.compile(r"never_while\s+(?P<a>\S+)\s+after\s+(?P<b>\S+)\s+until\s+"
                               r"(?P<c>\S+)")),
    ("never", re.compile(r"never\s+(?P<a>\S+)")),
    ("max_count", re.compile(r"max_count\s+(?P<a>\S+)\s+(?P<n>\d+)\s+per\s+(?P<d>.+)")),
    ("bounded_response", re.compile(r"bounded_response\s+(?P<a>\S+)\s+(?P<b>\S+)\s+"
                                    r"(?:within\s+)?(?P<d>.+)")),
]
_HELP = ("monitor forms: 'min_gap A 4h', 'never A', 'never_while A after B until C', "
         "'max_count A 4 per 24h', 'bounded_response A B 15min'")


def parse_monitor(text: str, *, location: SourceLocation | None = None) -> Monitor:
    """A monitor from its text form; :class:`ConfigurationError` at ``location`` when the
    text cannot be read (listing the forms)."""
    cleaned = " ".join(text.split())
    for form, pattern in _FORMS:
        match = pattern.fullmatch(cleaned)
        if match is None:
            continue
        try:
            g = match.groupdict()
            a = parse_subject(g["a"])
            if form == "min_gap":
                return MinGap(a, _seconds(g["d"]), text=cleaned)
            if form == "never":
                return Never(a, text=cleaned)
            if form == "never_while":
                return NeverWhile(a, parse_subject(g["b"]), parse_subject(g["c"]),
                                  text=cleaned)
            if form == "max_count":
                return MaxCount(a, int(g["n"]), _seconds(g["d"]), text=cleaned)
            return BoundedResponse(a, parse_subject(g["b"]), _seconds(g["d"]), text=cleaned)
        except ConfigurationError as error:
            raise ConfigurationError(f"monitor {cleaned!r}: {error.message}",
                                     location=location, hint=error.hint) from None
    raise ConfigurationError(f"cannot read the monitor {cleaned!r}", location=location,
                             hint=_HELP)


def package_monitors(attributes: Iterable[object], *, path: str | None = None
                     ) -> list[Monitor]:
    """The monitors declared by ``ExtendedAttribute Name="opspec:Monitor"`` in
    ``attributes`` (a package's ``extended_attributes``): the ``Value``, or the text with one
    monitor per line (``#`` comments)."""
    out = []
    for attribute in attributes:
        if getattr(attribute, "name", None) != MONITOR_ATTRIBUTE:
            continue
        location = getattr(attribute, "location", None) or (
            SourceLocation(path) if path else None)
        body = "\n".join(x for x in (getattr(attribute, "value", None),
                                     getattr(attribute, "text", None)) if x)
        for line in body.splitlines():
            line = line.split("#", 1)[0].strip()
            if line:
                out.append(parse_monitor(line, location=location))
    return out


def declared_monitors(compiled: Any) -> list[Monitor]:
    """The monitors ``compiled`` (a :class:`~opspec.engine.compiled.CompiledPackage`) declares
    as ``opspec:Monitor``, bound to its names: :class:`ConfigurationError` at the attribute's
    ``file:line`` when one cannot be read or names something the spec does not have."""
    from opspec.engine.names import spec_names

    package = compiled.package
    names = spec_names(compiled)
    out = []
    for attribute in getattr(package, "extended_attributes", ()):
        if getattr(attribute, "name", None) != MONITOR_ATTRIBUTE:
            continue
        location = getattr(attribute, "location", None)
        for monitor in package_monitors((attribute,), path=getattr(package, "source", None)):
            try:
                out.append(monitor.bind(names))
            except ConfigurationError as error:
                raise ConfigurationError(f"monitor {monitor.text!r}: {error.message}",
                                         location=location or error.location,
                                         hint=error.hint) from None
    return out
