"""A trace predicate and how predicates combine: ``&``, ``|``, ``~`` and per instance.

A :class:`Predicate` is a property of one trace as the spec tests use it: it holds on a
trace or it fails with a :class:`Failure` (message lines and the events to show). Combined,
``p & q`` fails with the first part that fails, ``p | q`` when every alternative fails,
``~p`` when ``p`` holds (showing why it does), and :func:`per_instance` judges a predicate on
each instance of a process, seeing that instance's events only. A combination is judged on
stored traces only: a monitor is one property.

The predicates combined are made in :mod:`opspec.properties.simple_predicates` (an event
that happens, a property that holds) and the modules that spell the language in Python
(:mod:`opspec.properties.vocabulary`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from opspec.engine.trace import EventKind, TraceEvent
from opspec.errors import ConfigurationError
from opspec.properties import language

if TYPE_CHECKING:
    from opspec.properties.simple_predicates import Match

__all__ = ["Failure", "Negation", "Predicate", "per_instance"]


@dataclass(frozen=True, slots=True)
class Failure:
    """Why a predicate failed on one trace: message lines and the events to show."""

    lines: tuple[str, ...]
    focus: tuple[TraceEvent, ...] = ()
    trace: Sequence[TraceEvent] = ()


class Predicate:
    """A property of one trace. Combine with ``&``, ``|``, ``~``; scope with
    :meth:`per_instance`. Subclasses implement :meth:`describe`, :meth:`fail` and
    :meth:`subjects`."""

    def describe(self) -> str:
        raise NotImplementedError

    def subjects(self) -> tuple[language.Subject, ...]:
        """Named things this predicate refers to (checked against the spec)."""
        return ()

    def processes(self) -> tuple[str, ...]:
        """Process names this predicate scopes to (checked against the spec)."""
        return ()

    def fail(self, events: Sequence[TraceEvent], end: float) -> Failure | None:
        """``None`` when the predicate holds on ``events`` (a run ending at ``end``)."""
        raise NotImplementedError

    def witness(self, events: Sequence[TraceEvent]) -> tuple[TraceEvent, ...]:
        """Events showing why the predicate holds (for a failing ``~p``)."""
        return ()

    def bind(self, names: Any) -> Predicate:
        """This predicate with its bare names resolved against the spec's (an activity, then
        a trigger, then a process), as a monitor's are."""
        return self

    def monitor(self) -> language.Property:
        """This predicate as a monitor, watched while a run happens: the one property it is.
        A combination (``&``, ``|``, ``~``, ``per_instance``) is judged on stored traces only:
        :class:`ConfigurationError` saying to pass its parts as separate monitors."""
        raise ConfigurationError(
            f"{self.describe()} cannot be watched as a monitor: a monitor is one property",
            hint="pass each part as its own monitor (monitors=[p, q] for p & q), or judge the "
                 "combination on the result with check(result, ...)")

    def __repr__(self) -> str:
        return self.describe()

    def __and__(self, other: Predicate) -> Predicate:
        return _All((self, _as_predicate(other)))

    def __or__(self, other: Predicate) -> Predicate:
        return _Any((self, _as_predicate(other)))

    def __invert__(self) -> Predicate:
        return Negation(self)

    def per_instance(self, process: str) -> Predicate:
        """This predicate on each instance of ``process`` (its own events only)."""
        return per_instance(process, self)


def _as_predicate(what: Any) -> Predicate:
    """What a combination is made of (:func:`~opspec.properties.simple_predicates.as_predicate`),
    imported when one is made: what it makes, an event or a property, are predicates defined
    on top of this module."""
    from opspec.properties.simple_predicates import as_predicate

    return as_predicate(what)


class _All(Predicate):
    def __init__(self, parts: tuple[Predicate, ...]) -> None:
        flat: list[Predicate] = []
        for p in parts:
            flat.extend(p.parts if type(p) is _All else (p,))   # not an _Any: no flattening
        self.parts: tuple[Predicate, ...] = tuple(flat)

    def describe(self) -> str:
        return " & ".join(_paren(p) for p in self.parts)

    def subjects(self) -> tuple[language.Subject, ...]:
        return tuple(s for p in self.parts for s in p.subjects())

    def processes(self) -> tuple[str, ...]:
        return tuple(s for p in self.parts for s in p.processes())

    def fail(self, events: Sequence[TraceEvent], end: float) -> Failure | None:
        for part in self.parts:
            failure = part.fail(events, end)
            if failure is not None:
                return Failure((f"{part.describe()} does not hold:", *failure.lines),
                               failure.focus, failure.trace)
        return None

    def witness(self, events: Sequence[TraceEvent]) -> tuple[TraceEvent, ...]:
        return tuple(e for p in self.parts for e in p.witness(events))[:4]

    def bind(self, names: Any) -> Predicate:
        return type(self)(tuple(p.bind(names) for p in self.parts))


class _Any(_All):
    def __init__(self, parts: tuple[Predicate, ...]) -> None:
        flat: list[Predicate] = []
        for p in parts:
            flat.extend(p.parts if type(p) is _Any else (p,))
        self.parts = tuple(flat)

    def describe(self) -> str:
        return " | ".join(_paren(p) for p in self.parts)

    def fail(self, events: Sequence[TraceEvent], end: float) -> Failure | None:
        failures = [part.fail(events, end) for part in self.parts]
        if any(f is None for f in failures):
            return None
        lines: list[str] = ["but none of the alternatives holds:"]
        for part, failure in zip(self.parts, failures, strict=True):
            assert failure is not None
            lines.append(f"  {part.describe()}: " + " ".join(failure.lines))
        first = failures[0]
        assert first is not None
        return Failure(tuple(lines), first.focus, first.trace)


class Negation(Predicate):
    """``~p``: holds where ``p`` fails; its failure shows why ``p`` holds."""

    def __init__(self, inner: Predicate) -> None:
        self.inner = inner

    def describe(self) -> str:
        return f"~{_paren(self.inner)}"

    def subjects(self) -> tuple[language.Subject, ...]:
        return self.inner.subjects()

    def processes(self) -> tuple[str, ...]:
        return self.inner.processes()

    def fail(self, events: Sequence[TraceEvent], end: float) -> Failure | None:
        if self.inner.fail(events, end) is not None:
            return None
        return Failure((f"but {self.inner.describe()} holds",), self.inner.witness(events),
                       events)

    def __invert__(self) -> Predicate:
        return self.inner

    def bind(self, names: Any) -> Predicate:
        return Negation(self.inner.bind(names))


def _paren(p: Predicate) -> str:
    text = p.describe()
    return f"({text})" if isinstance(p, (_All, Negation)) or " | " in text else text


class _PerInstance(Predicate):
    def __init__(self, process: str, inner: Predicate) -> None:
        self.process, self.inner = process, inner

    def describe(self) -> str:
        return f"per_instance({self.process!r}, {self.inner.describe()})"

    def bind(self, names: Any) -> Predicate:
        return _PerInstance(self.process, self.inner.bind(names))

    def subjects(self) -> tuple[language.Subject, ...]:
        return self.inner.subjects()

    def processes(self) -> tuple[str, ...]:
        return (self.process, *self.inner.processes())

    def instances(self, events: Sequence[TraceEvent]) -> list[list[TraceEvent]]:
        by_id: dict[int, list[TraceEvent]] = {}
        for e in events:
            if e.instance is not None:
                by_id.setdefault(e.instance, []).append(e)
        return [evs for evs in by_id.values()
                if evs[0].kind == EventKind.PROCESS_STARTED and evs[0].process == self.process]

    def fail(self, events: Sequence[TraceEvent], end: float) -> Failure | None:
        for own in self.instances(events):
            failure = self.inner.fail(own, end)
            if failure is not None:
                head = (f"in {self.process} instance #{own[0].instance} (started "
                        f"{language.clock(own[0].time)}):")
                return Failure((head, *failure.lines), failure.focus, own)
        return None


def per_instance(process: str, predicate: Predicate | str | Match) -> Predicate:
    """``predicate`` on each instance of ``process`` separately, seeing only that instance's
    events (so ``count("dispense") == 1`` means once per dose, not once per run)."""
    from opspec.properties.term_arguments import text

    text("per_instance()", process, "the process is named by text")
    return _PerInstance(process, _as_predicate(predicate))
