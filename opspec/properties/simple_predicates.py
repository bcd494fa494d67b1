"""The simple predicates every other is made of: an event that happens, a property that holds.

A :class:`Match` selects events (a name such as ``dispense``, ``activity:dispense`` or
``a|b``, or any ``Callable[[TraceEvent], bool]``); as a predicate it means "happens at least
once", and as a property's subject it is what the property counts. :class:`Holds` is a
:class:`~opspec.properties.language.Property` judged on a trace: its events fed to the
evaluator a monitor runs online, so the verdict and the witness are the monitor's.
:func:`eventually` and :func:`never` are the two a ``~`` turns into each other;
:func:`as_predicate` makes a predicate of whatever a user writes (a predicate, a property,
its text, an event name).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import replace
from typing import Any

from opspec.engine.trace import TraceEvent
from opspec.errors import ConfigurationError
from opspec.properties import language, text_form
from opspec.properties.predicate import Failure, Negation, Predicate
from opspec.properties.term_arguments import described

__all__ = ["Holds", "Match", "as_match", "as_predicate", "eventually", "never"]


class Match(Predicate):
    """A selector of events; as a predicate it means "happens at least once"."""

    def __init__(self, test: Callable[[TraceEvent], bool], text: str,
                 subject: language.Subject | None = None, process: str | None = None) -> None:
        self._test = test
        self.text = text
        self.subject = subject
        self.process = process

    def selector(self) -> language.Subject | Match:
        """What a property built from this selects by: the name itself when it is one (so
        the property equals its text form's, and a monitor of it asks the engine for the
        events it needs only), else this selector."""
        if self.subject is not None and self._test == self.subject.matches:
            return self.subject
        return self

    def bind(self, names: Any) -> Match:
        if self.subject is not None and self._test == self.subject.matches:   # a name
            bound = self.subject.bind(names)
            return Match(bound.matches, self.text, bound, self.process)
        return self

    def __call__(self, event: TraceEvent) -> bool:
        return self._test(event)

    def matches(self, event: TraceEvent) -> bool:
        """As a property's selector (:class:`~opspec.properties.language.Selector`)."""
        return self._test(event)

    def describe(self) -> str:
        return self.text

    def subjects(self) -> tuple[language.Subject, ...]:
        return (self.subject,) if self.subject is not None else ()

    def processes(self) -> tuple[str, ...]:
        return (self.process,) if self.process is not None else ()

    def all(self, events: Iterable[TraceEvent]) -> list[TraceEvent]:
        return [e for e in events if self._test(e)]

    def fail(self, events: Sequence[TraceEvent], end: float) -> Failure | None:
        return Holds(language.Eventually(self.selector())).fail(events, end)

    def witness(self, events: Sequence[TraceEvent]) -> tuple[TraceEvent, ...]:
        return tuple(self.all(events)[:1])

    def monitor(self) -> language.Property:
        return language.Eventually(self.selector())

    def __invert__(self) -> Predicate:
        return never(self)


def _subject_match(subject: language.Subject) -> Match:
    return Match(subject.matches, str(subject), subject)


def as_match(what: str | Match | Callable[[TraceEvent], bool], term: str = "an event") -> Match:
    """``what`` as the events it selects; ``term`` (``"count()"``) names the term it is given
    to when it selects none (a number, None: a :class:`ConfigurationError`)."""
    if isinstance(what, Match):
        return what
    if isinstance(what, str):
        return _subject_match(language.parse_subject(what))
    if callable(what):
        return Match(what, getattr(what, "__name__", repr(what)))
    raise ConfigurationError(f"{term}: expected an event name, a Match or a callable, not "
                             f"{described(what)}",
                             hint="name an event by text: 'dispense', 'trigger:trg_1', 'a|b'")


def as_predicate(what: Any) -> Predicate:
    """A predicate, a property (a monitor), a property's text (it has spaces: ``"never
    notify_caregiver"``), or an event name (``"dispense"``: it happens)."""
    if isinstance(what, Predicate):
        return what
    if isinstance(what, language.Property):
        return Holds(what)
    if isinstance(what, str) and len(what.split()) > 1:
        return Holds(text_form.parse_property(what))
    if not isinstance(what, (str, Match)) and not callable(what):
        raise ConfigurationError(
            f"expected a predicate, a property, its text or an event name, not "
            f"{described(what)}", hint="e.g. never('notify_caregiver') & "
                                       "within('sound_alarm', 'press_report', 60)")
    return as_match(what)


class Holds(Predicate):
    """A :class:`~opspec.properties.language.Property` judged on a trace: its events fed to the
    evaluator a monitor runs online, so the verdict and the witness (the events marked in a
    failure) are the monitor's. ``label`` is how Python spelt it (``within(a, b, 60 s)``)."""

    def __init__(self, prop: language.Property, label: str | None = None) -> None:
        # named by its text form as the user spelt it (a bound property spells its names
        # with their kind), so a monitor's report and assert_no_violations use that name
        self.property = prop if prop.text else replace(prop, text=prop.describe())
        self.label = label

    @property
    def text(self) -> str:
        """The property's text form (its name in monitor reports)."""
        return str(self.property)

    def monitor(self) -> language.Property:
        return self.property

    def __eq__(self, other: object) -> bool:
        # the same property is the same claim, however it was spelt (its text aside)
        if isinstance(other, Holds):
            other = other.property
        if isinstance(other, language.Property):
            return replace(self.property, text="") == replace(other, text="")
        return NotImplemented

    def __hash__(self) -> int:
        return hash(replace(self.property, text=""))

    def describe(self) -> str:
        return self.label or str(self.property)

    def subjects(self) -> tuple[language.Subject, ...]:
        out: list[language.Subject] = []
        for selector in self.property.subjects():
            if isinstance(selector, language.Subject):
                out.append(selector)
            elif isinstance(selector, Match):
                out.extend(selector.subjects())
        return tuple(out)

    def processes(self) -> tuple[str, ...]:
        return tuple(p for s in self.property.subjects() if isinstance(s, Match)
                     for p in s.processes())

    def judge(self, events: Sequence[TraceEvent], end: float) -> language.MonitorRun:
        run = self.property.start()
        for e in events:
            run(e)
        run.finish(end)
        return run

    def fail(self, events: Sequence[TraceEvent], end: float) -> Failure | None:
        run = self.judge(events, end)
        if not run.count:
            return None
        first = run.violations[0]
        more = f" (the first of {run.count} violations)" if run.count > 1 else ""
        return Failure((f"but {first.message}{more}",), first.events, events)

    def witness(self, events: Sequence[TraceEvent]) -> tuple[TraceEvent, ...]:
        return self.judge(events, language.trace_end(events)).evidence()

    def bind(self, names: Any) -> Predicate:
        return Holds(self.property._with([s.bind(names)
                                          if isinstance(s, (language.Subject, Match))
                                          else s for s in self.property.subjects()]),
                     self.label)

    def __invert__(self) -> Predicate:
        prop = self.property
        if isinstance(prop, language.Never):
            return Holds(language.Eventually(prop.subject), f"eventually({prop.subject})")
        if isinstance(prop, language.Eventually):
            return Holds(language.Never(prop.subject), f"never({prop.subject})")
        return Negation(self)


def eventually(what: str | Match | Predicate | Callable[[TraceEvent], bool]) -> Predicate:
    """``what`` happens at least once (a predicate is returned as it is)."""
    if isinstance(what, Predicate) and not isinstance(what, Match):
        return what
    match = as_match(what, "eventually()")
    return Holds(language.Eventually(match.selector()), f"eventually({match.describe()})")


def never(what: str | Match | Predicate | Callable[[TraceEvent], bool]) -> Predicate:
    """``what`` never happens (for a predicate: it does not hold, i.e. ``~what``)."""
    if isinstance(what, Predicate) and not isinstance(what, Match):
        return Negation(what)
    match = as_match(what, "never()")
    return Holds(language.Never(match.selector()), f"never({match.describe()})")
