"""The properties about what comes before or after what: a response (in time), a precedence,
an absence between an opening and a closing event.

``bounded_response A B 15min`` and ``response A B`` (:class:`BoundedResponse`), ``A before
B`` and ``A before each B`` (:class:`Precedence`), ``never_while A after B until C``
(:class:`NeverWhile`): Dwyer's response, precedence and absence in an "after Q until R"
scope. Each is judged by its own :class:`~opspec.properties.evaluator.MonitorRun`;
docs/spec-testing.md ("What a property means") states the boundary cases (an event that is
both answers, or precedes, itself; a window the end of the run cuts off is open).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import ClassVar

from opspec.clock import span
from opspec.engine.trace import TraceEvent
from opspec.properties.evaluator import KEEP, MonitorRun, Property, clock, duration_text
from opspec.properties.subjects import Selector, spell

__all__ = ["BoundedResponse", "NeverWhile", "Precedence"]

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
                f"{duration_text(self.seconds)}")


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
