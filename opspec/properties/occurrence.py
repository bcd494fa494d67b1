"""The properties about how often one subject happens: never, at least once, a count, not
too close together, not too many in a window.

``never A`` (:class:`Never`), ``eventually A`` (:class:`Eventually`), ``count A <= 4``
(:class:`CountBound`, any of :data:`COMPARISONS` or ``in [lo, hi]``), ``min_gap A 4h``
(:class:`MinGap`) and ``max_count A 4 per 24h`` (:class:`MaxCount`): Dwyer's absence,
existence and bounded existence, over the whole run or (``min_gap``, ``max_count``) any
window of the given length. Each is judged by its own
:class:`~opspec.properties.evaluator.MonitorRun`; docs/spec-testing.md ("What a property
means") states the boundary cases.
"""

from __future__ import annotations

import math
import operator
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

from opspec.clock import span
from opspec.engine.trace import TraceEvent
from opspec.errors import ConfigurationError
from opspec.properties.evaluator import MonitorRun, Property, clock, duration_text
from opspec.properties.subjects import Selector, spell

__all__ = ["COMPARISONS", "SLICE", "CountBound", "Eventually", "MaxCount", "MinGap", "Never"]

#: events a witness of a window (max_count) or a count keeps at most
SLICE = 8


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
        return f"min_gap {spell(self.subject)} {duration_text(self.seconds)}"


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
        return f"max_count {spell(self.subject)} {self.limit} per {duration_text(self.seconds)}"


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
