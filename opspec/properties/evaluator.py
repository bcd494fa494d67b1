"""The one evaluator of the property language: a property judged over one run, event by event.

:class:`Property` is a claim about one run's trace: what it refers to (its subjects), the
events it needs (``selects``), and how it is judged — :meth:`Property.start` gives a
:class:`MonitorRun`, the trace listener a monitor is while a run happens, and
:meth:`Property.judge` feeds the same :class:`MonitorRun` a stored trace's events one by one.
What a run finds is a :class:`MonitorResult`: its violations (:class:`Violation`), each with
its witness (the events that show it), and the obligations the end of the run left open.

Each kind of property (:mod:`opspec.properties.occurrence`, :mod:`opspec.properties.order`)
is a :class:`Property` subclass with its own :class:`MonitorRun`.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

from opspec.clock import clock_time, span
from opspec.engine.trace import EventKind, TraceEvent
from opspec.properties.subjects import Names, Selector, Selects, Subject

__all__ = [
    "KEEP",
    "MonitorResult",
    "MonitorRun",
    "Property",
    "Violation",
    "clock",
    "duration_text",
    "trace_end",
]

#: violations kept with their witness per run (all are counted)
KEEP = 50


def clock(seconds: float) -> str:
    """``d1 08:00:00`` for simulated seconds: :func:`opspec.clock.clock_time`, the one way
    opspec shows a point of the run (kept under this name for the predicates' imports)."""
    return clock_time(seconds)


def duration_text(seconds: float) -> str:
    """A property's time as its text form writes it (``4h``, ``15min``, ``1d``)."""
    return span(seconds).replace(" days", "d").replace(" day", "d").replace(" ", "")


def trace_end(events: Sequence[TraceEvent]) -> float:
    """Where a stored trace ends: its ``run.ended`` event (written at the run's horizon),
    else its last event."""
    for event in reversed(events):
        if event.kind == EventKind.RUN_ENDED:
            return event.time
    return events[-1].time if events else 0.0


# ---------------------------------------------------------------- violations and runs
@dataclass(frozen=True, slots=True)
class Violation:
    """One violation of the property named ``monitor`` (its text) at simulated ``time`` in
    ``replication``; ``events`` is its witness: the events that show it (oldest first)."""

    monitor: str
    time: float
    message: str
    events: tuple[TraceEvent, ...] = ()
    replication: int = 0

    def __str__(self) -> str:
        return f"{clock(self.time)}: {self.monitor}: {self.message}"


@dataclass(frozen=True, slots=True)
class MonitorResult:
    """What one property saw in one run: ``count`` violations (the first :data:`KEEP` kept
    with their witness) and ``open``: obligations whose time window the end of the run cut
    off (not judged). It holds when ``count`` is 0."""

    monitor: str
    replication: int
    count: int
    violations: tuple[Violation, ...] = ()
    open: tuple[TraceEvent, ...] = ()

    @property
    def holds(self) -> bool:
        return self.count == 0


class MonitorRun:
    """One property evaluated over one run, event by event: a trace listener (online) that
    is also fed stored traces (offline, :meth:`Property.judge`). Subclasses implement
    :meth:`observe` (called with the events the property's selectors match, in trace order)
    and :meth:`finish` when the end of the run decides something."""

    def __init__(self, monitor: Property, replication: int = 0) -> None:
        self.monitor = monitor
        self.replication = replication
        self.selects = monitor.selects
        self.violations: list[Violation] = []
        self.count = 0
        self.open: tuple[TraceEvent, ...] = ()
        self._relevant = monitor.relevant

    def __call__(self, event: TraceEvent) -> None:
        if self._relevant(event):
            self.observe(event)

    def observe(self, event: TraceEvent) -> None:
        raise NotImplementedError

    def finish(self, end: float) -> None:
        """The run ended at simulated time ``end`` (judge what is still pending)."""

    def evidence(self) -> tuple[TraceEvent, ...]:
        """Events showing that the property *holds* (``eventually``: the first occurrence),
        for a predicate's negation."""
        return ()

    def result(self) -> MonitorResult:
        """The frozen outcome (call after :meth:`finish`)."""
        return MonitorResult(self.monitor.text or self.monitor.describe(), self.replication,
                             self.count, tuple(self.violations), self.open)

    def violate(self, time: float, message: str, events: Iterable[TraceEvent]) -> None:
        self.count += 1
        if len(self.violations) < KEEP:
            self.violations.append(Violation(self.monitor.text or self.monitor.describe(),
                                             time, message, tuple(events), self.replication))


# ---------------------------------------------------------------- properties
@dataclass(frozen=True, slots=True)
class Property:
    """A claim about one run's trace; ``text`` is its text form (its name in reports; empty
    for one built in Python without it, then :meth:`describe` writes it)."""

    text: str = field(default="", kw_only=True)

    #: how a run of this property is evaluated (a MonitorRun subclass)
    _run: ClassVar[type[MonitorRun]]
    #: the fields that are subjects, in order
    _subject_fields: ClassVar[tuple[str, ...]] = ("subject",)

    def subjects(self) -> tuple[Selector, ...]:
        """What the property refers to, in the order of its fields."""
        return tuple(getattr(self, name) for name in self._subject_fields)

    def _with(self, subjects: Sequence[Selector]) -> Property:
        changes: dict[str, Any] = dict(zip(self._subject_fields, subjects, strict=True))
        return replace(self, **changes)

    def describe(self) -> str:
        """The text form (``text`` when given)."""
        raise NotImplementedError

    def __str__(self) -> str:
        return self.text or self.describe()

    def bind(self, names: Names) -> Property:
        """This property with its subjects resolved against the spec's names."""
        return self._with([s.bind(names) if isinstance(s, Subject) else s
                           for s in self.subjects()])

    @property
    def selects(self) -> Selects | None:
        """The engine selectors of the events it needs (``None``: every event, when a
        subject is a predicate's selector rather than a name)."""
        out: Selects = frozenset()
        for subject in self.subjects():
            if not isinstance(subject, Subject):
                return None
            out |= subject.selects
        return out

    def relevant(self, event: TraceEvent) -> bool:
        return any(s.matches(event) for s in self.subjects())

    def start(self, replication: int = 0) -> MonitorRun:
        """A fresh evaluation for one run (a trace listener)."""
        return self._run(self, replication)

    def judge(self, events: Iterable[TraceEvent], end: float | None = None,
              replication: int = 0) -> MonitorResult:
        """The verdict over a stored trace: its events fed, in order, to the evaluation a
        monitor runs online; ``end`` is where the run ended (default :func:`trace_end`)."""
        run = self.start(replication)
        events = events if isinstance(events, Sequence) else list(events)
        for event in events:
            run(event)
        run.finish(trace_end(events) if end is None else end)
        return run.result()
