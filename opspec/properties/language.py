"""One property language for monitors, trace predicates and scenario ``then`` lines.

A :class:`Property` is a claim about one run's trace ("no two dispenses closer than 4 h",
"every alarm is answered within 15 min"). The same property is

* watched **online** while a simulation runs: :meth:`Property.start` gives a
  :class:`MonitorRun`, a trace listener with a ``selects`` set (the engine builds only the
  events it needs) - what ``opspec:Monitor``, ``opspec run``, ``opspec evaluate`` and
  ``simulate(monitors=...)`` use;
* judged **offline** over a stored trace: :meth:`Property.judge` feeds the same
  :class:`MonitorRun` the trace's events one by one - what the trace predicates
  (:mod:`opspec.testing.predicates`) and the ``then`` lines of scenario files use.

One evaluator, fed the same events, so a monitor and a predicate with the same text give the
same verdict and the same witness (the events that show a violation) on the same run.

The text form (``min_gap dispense 4h``, ``bounded_response sound_alarm dispense 15 min``)
is read by :mod:`opspec.properties.text_form`; what a property counts (a *subject*: an
activity, a trigger or a process) is :mod:`opspec.properties.subjects`.

The verdicts follow the specification patterns of Dwyer, Avrunin and Corbett (ICSE 1999) read
over the finite trace, in its order (``seq``: events at the same instant count in the order
the engine emitted them), and docs/spec-testing.md ("What a property means") states the
boundary cases: an event exactly at a bound is in time, an event that is both ``A`` and ``B``
answers (or precedes) itself, and a time window the end of the run cuts off is *open* - not
judged - while an untimed obligation (``eventually``, ``response``, ``count ... >=``) still
open at the end is a violation, because the run is the whole time it talks about.

Pure Python, no wall clock: importable by any layer above the engine.
"""

from __future__ import annotations

import math
import operator
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

from opspec.clock import clock_time, span
from opspec.engine.trace import EventKind, TraceEvent
from opspec.errors import ConfigurationError
from opspec.properties.subjects import (
    Names,
    Selector,
    Selects,
    Subject,
    parse_subject,
    spell,
)

__all__ = [
    "COMPARISONS",
    "KEEP",
    "BoundedResponse",
    "CountBound",
    "Eventually",
    "MaxCount",
    "MinGap",
    "MonitorResult",
    "MonitorRun",
    "Names",
    "Never",
    "NeverWhile",
    "Precedence",
    "Property",
    "Selector",
    "Subject",
    "Violation",
    "clock",
    "parse_subject",
    "trace_end",
]

#: violations kept with their witness per run (all are counted)
KEEP = 50
#: events a witness of a window (max_count) or a count keeps at most
SLICE = 8


def clock(seconds: float) -> str:
    """``d1 08:00:00`` for simulated seconds: :func:`opspec.clock.clock_time`, the one way
    opspec shows a point of the run (kept under this name for the predicates' imports)."""
    return clock_time(seconds)


def _duration_text(seconds: float) -> str:
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


class _NeverRun(MonitorRun):
    monitor: Never

    def observe(self, event: TraceEvent) -> None:
        self.violate(event.time, f"{self.monitor.subject} happened at {clock(event.time)}",
                     (event,))


@dataclass(frozen=True, slots=True)
class Never(Property):
    """Absence: ``subject`` never happens. Each occurrence is a violation."""

    _run: ClassVar[type[MonitorRun]] = _NeverRun

    subject: Selector

    def describe(self) -> str:
        return f"never {spell(self.subject)}"


class _EventuallyRun(MonitorRun):
    monitor: Eventually

    def __init__(self, monitor: Eventually, replication: int) -> None:
        super().__init__(monitor, replication)
        self.first: TraceEvent | None = None

    def observe(self, event: TraceEvent) -> None:
        if self.first is None:
            self.first = event

    def finish(self, end: float) -> None:
        if self.first is None:
            self.violate(end, f"{self.monitor.subject} never happened (the run went to "
                         f"{clock(end)})", ())

    def evidence(self) -> tuple[TraceEvent, ...]:
        return () if self.first is None else (self.first,)


@dataclass(frozen=True, slots=True)
class Eventually(Property):
    """Existence: ``subject`` happens at least once in the run (decided at its end)."""

    _run: ClassVar[type[MonitorRun]] = _EventuallyRun

    subject: Selector

    def describe(self) -> str:
        return f"eventually {spell(self.subject)}"


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
class MinGap(Property):
    """No two occurrences of ``subject`` closer than ``seconds`` (exactly ``seconds`` apart
    is allowed); each occurrence too close to the previous one is a violation."""

    _run: ClassVar[type[MonitorRun]] = _MinGapRun

    subject: Selector
    seconds: float

    def describe(self) -> str:
        return f"min_gap {spell(self.subject)} {_duration_text(self.seconds)}"


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


COMPARISONS: dict[str, Callable[[float, float], bool]] = {
    "==": operator.eq, "!=": operator.ne, "<": operator.lt, "<=": operator.le,
    ">": operator.gt, ">=": operator.ge}


@dataclass(frozen=True, slots=True)
class MaxCount(Property):
    """At most ``limit`` occurrences of ``subject`` in any window of ``seconds`` (a window is
    half-open: two events exactly ``seconds`` apart are never in the same one, as for
    :class:`MinGap`; ``max_count A 1 per D`` is ``min_gap A D``). Each occurrence that
    makes a window hold too many is a violation."""

    _run: ClassVar[type[MonitorRun]] = _MaxCountRun

    subject: Selector
    limit: int
    seconds: float

    def describe(self) -> str:
        return f"max_count {spell(self.subject)} {self.limit} per {_duration_text(self.seconds)}"


class _CountRun(MonitorRun):
    monitor: CountBound

    def __init__(self, monitor: CountBound, replication: int) -> None:
        super().__init__(monitor, replication)
        self.n = 0
        self.most = monitor.most()
        self.head: list[TraceEvent] = []            # the first 3 occurrences
        self.tail: deque[TraceEvent] = deque(maxlen=2)
        self.broke: TraceEvent | None = None

    def observe(self, event: TraceEvent) -> None:
        self.n += 1
        if len(self.head) < 3:
            self.head.append(event)
        else:
            self.tail.append(event)
        if self.broke is None and self.n > self.most:
            self.broke = event

    def finish(self, end: float) -> None:
        m = self.monitor
        if m.allows(self.n):
            return
        where = (f" (the one too many at {clock(self.broke.time)})" if self.broke is not None
                 else f" (the run went to {clock(end)})")
        self.violate(self.broke.time if self.broke is not None else end,
                     f"{m.subject} happened {self.n} time(s){where}; count {m.target()} "
                     "required", (*self.head, *self.tail))

    def evidence(self) -> tuple[TraceEvent, ...]:
        return (*self.head, *self.tail)


@dataclass(frozen=True, slots=True)
class CountBound(Property):
    """The number of ``subject`` in the run compares so with ``a`` (``op`` is ``==``, ``!=``,
    ``<``, ``<=``, ``>``, ``>=``, or ``in`` for ``a <= n <= b``). One violation at most per
    run: at the occurrence that broke an upper bound, else at the end of the run."""

    _run: ClassVar[type[MonitorRun]] = _CountRun

    subject: Selector
    op: str
    a: float
    b: float | None = None

    def __post_init__(self) -> None:
        if self.op not in COMPARISONS and self.op != "in":
            raise ConfigurationError(f"unknown comparison {self.op!r}",
                                     hint="use ==, !=, <, <=, >, >= or in [lo, hi]")
        if self.op == "in" and (self.b is None or self.a > self.b):
            raise ConfigurationError(f"count in [{self.a:g}, {self.b or 0:g}]: the range is "
                                     "empty")

    def target(self) -> str:
        """``<= 4``, ``in [1, 3]``."""
        return f"in [{self.a:g}, {self.b:g}]" if self.op == "in" else f"{self.op} {self.a:g}"

    def describe(self) -> str:
        return f"count {spell(self.subject)} {self.target()}"

    def allows(self, n: float) -> bool:
        if self.op == "in":
            assert self.b is not None
            return self.a <= n <= self.b
        return COMPARISONS[self.op](n, self.a)

    def most(self) -> float:
        """The largest count allowed when the bound is an upper one (else infinity): the
        occurrence after it is where the claim broke."""
        if self.op == "in":
            assert self.b is not None
            return math.floor(self.b)
        if self.op in ("<=", "=="):
            return math.floor(self.a)
        if self.op == "<":
            return math.ceil(self.a) - 1
        return math.inf


class _ResponseRun(MonitorRun):
    monitor: BoundedResponse

    def __init__(self, monitor: BoundedResponse, replication: int) -> None:
        super().__init__(monitor, replication)
        self.pending: deque[TraceEvent] = deque()
        # triggers whose window closed unanswered: reported with the next response (their
        # witness), or at the end; only as many as can still be kept are held back
        self.overdue: list[TraceEvent] = []

    def _expire(self, now: float) -> None:
        seconds = self.monitor.seconds
        while self.pending and self.pending[0].time + seconds < now:
            cause = self.pending.popleft()
            if len(self.violations) + len(self.overdue) < KEEP:
                self.overdue.append(cause)
            else:
                self.count += 1               # counted; beyond what is kept anyway

    def _report(self, response: TraceEvent | None, end: float) -> None:
        m = self.monitor
        for cause in self.overdue:
            due = cause.time + m.seconds
            if response is not None:
                nxt = (f"; the next came at {clock(response.time)}, "
                       f"{span(response.time - cause.time)} after it")
            else:
                nxt = f"; none came before the end ({clock(end)})"
            self.violate(due, f"{m.trigger} at {clock(cause.time)} was not followed by "
                         f"{m.response} within {span(m.seconds)}{nxt}",
                         (cause,) if response is None else (cause, response))
        self.overdue.clear()

    def observe(self, event: TraceEvent) -> None:
        m = self.monitor
        self._expire(event.time)
        if m.response.matches(event):
            if self.overdue:
                self._report(event, event.time)
            self.pending.clear()
        elif m.trigger.matches(event):
            self.pending.append(event)

    def finish(self, end: float) -> None:
        m = self.monitor
        if math.isinf(m.seconds):
            for cause in self.pending:
                self.violate(end, f"{m.trigger} at {clock(cause.time)} was not followed by "
                             f"{m.response} before the end ({clock(end)})", (cause,))
            self.pending.clear()
            return
        # a window that closed before the end is judged; one the end cut off is open (the
        # run stops before events at its end, so a response at ``end`` was still possible)
        self._expire(end)
        self._report(None, end)
        self.open = tuple(self.pending)


@dataclass(frozen=True, slots=True)
class BoundedResponse(Property):
    """Every ``trigger`` is followed by a ``response`` within ``seconds`` (a response exactly
    ``seconds`` later is in time; an event that is both answers itself; one response answers
    every trigger pending before it). Each unanswered trigger is a violation at its due time,
    its witness the trigger and the next response, if one came before the end. A window the
    end of the run cuts off is *open*, not judged. With ``seconds`` infinite (``response A
    B``) the window is the rest of the run: a trigger unanswered at the end is a violation."""

    _run: ClassVar[type[MonitorRun]] = _ResponseRun
    _subject_fields: ClassVar[tuple[str, ...]] = ("trigger", "response")

    trigger: Selector
    response: Selector
    seconds: float

    def describe(self) -> str:
        if math.isinf(self.seconds):
            return f"response {spell(self.trigger)} {spell(self.response)}"
        return (f"bounded_response {spell(self.trigger)} {spell(self.response)} "
                f"{_duration_text(self.seconds)}")


class _PrecedenceRun(MonitorRun):
    monitor: Precedence

    def __init__(self, monitor: Precedence, replication: int) -> None:
        super().__init__(monitor, replication)
        self.firsts = 0          # firsts seen
        self.used = 0            # firsts a then has taken (each=True)
        self.thens = 0
        self.last: TraceEvent | None = None

    def observe(self, event: TraceEvent) -> None:
        m = self.monitor
        if m.first.matches(event):
            self.firsts += 1
            self.last = event
        if not m.then.matches(event):
            return
        self.thens += 1
        if self.firsts > self.used if m.each else self.firsts > 0:
            self.used += 1
            return
        if self.firsts == 0:
            why = f"before any {m.first}"
        else:
            why = (f"with no {m.first} of its own before it ({self.firsts} {m.first} for "
                   f"{self.thens} {m.then})")
        witness = (event,) if self.last is None else (self.last, event)
        self.violate(event.time, f"{m.then} happened at {clock(event.time)} {why}", witness)


@dataclass(frozen=True, slots=True)
class Precedence(Property):
    """``first`` precedes ``then``: no ``then`` before the first ``first`` (``then`` need not
    happen; an event that is both precedes itself). ``each``: every ``then`` has a ``first``
    of its own before it (the n-th ``then`` comes after the n-th ``first``). Each ``then``
    without one is a violation."""

    _run: ClassVar[type[MonitorRun]] = _PrecedenceRun
    _subject_fields: ClassVar[tuple[str, ...]] = ("first", "then")

    first: Selector
    then: Selector
    each: bool = False

    def describe(self) -> str:
        return f"{spell(self.first)} before {'each ' if self.each else ''}{spell(self.then)}"


class _NeverWhileRun(MonitorRun):
    monitor: NeverWhile

    def __init__(self, monitor: NeverWhile, replication: int) -> None:
        super().__init__(monitor, replication)
        self.opened: TraceEvent | None = None

    def observe(self, event: TraceEvent) -> None:
        m = self.monitor
        if m.until.matches(event):
            self.opened = None
            return
        if self.opened is None and m.after.matches(event):
            self.opened = event
        if self.opened is not None and m.subject.matches(event):
            self.violate(event.time, f"{m.subject} at {clock(event.time)}, after {m.after} at "
                         f"{clock(self.opened.time)} and before any {m.until}",
                         (self.opened, event) if self.opened is not event else (event,))


@dataclass(frozen=True, slots=True)
class NeverWhile(Property):
    """Absence between: ``subject`` never happens after an ``after`` until the next ``until``
    (the window opens at the first ``after`` and stays open, to the end of the run, until an
    ``until`` closes it). An event that is the ``after`` opening the window is inside it; one
    that is the ``until`` closing it is not (Dwyer's "after Q until R" scope)."""

    _run: ClassVar[type[MonitorRun]] = _NeverWhileRun
    _subject_fields: ClassVar[tuple[str, ...]] = ("subject", "after", "until")

    subject: Selector
    after: Selector
    until: Selector

    def describe(self) -> str:
        return (f"never_while {spell(self.subject)} after {spell(self.after)} "
                f"until {spell(self.until)}")

