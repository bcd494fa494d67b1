"""The property language in Python: one set of constructors for every use of a property.

::

    from opspec.testing import check, count, min_gap, never, simulate, within

    result = simulate(spec, users=50, monitors=[min_gap("dispense", hours=4)])   # online
    check(result, within("sound_alarm", "press_report", 60) & never("notify_caregiver"))

Each constructor gives a :class:`Predicate`: a claim about one run's trace, judged by the
evaluator of :mod:`opspec.properties.language` (so it has the same verdict and the same
witness as the property's text form). The same object serves every use:

* as a **monitor**, watched while a run happens (``simulate(monitors=[...])``, the spec's
  ``opspec:Monitor``): :meth:`Predicate.monitor` is its
  :class:`~opspec.properties.language.Property`;
* as a **trace predicate** on stored traces (``holds``, ``check`` in :mod:`opspec.testing`),
  combined with ``&``, ``|``, ``~`` and scoped with :meth:`Predicate.per_instance` (a
  combination is a predicate only: a monitor is one property).

=============================================  =============================================
Python                                         text form
=============================================  =============================================
``never("A")``, ``eventually("A")``            ``never A``, ``eventually A``
``within("A", "B", 900)``                      ``bounded_response A B 15min``
``within("A", "B", math.inf)``                 ``response A B``
``happens_before("A", "B", each=False)``       ``A before B`` (``A before each B``)
``count("A") <= 4``, ``.between(lo, hi)``      ``count A <= 4``, ``count A in [lo, hi]``
``min_gap("A", hours=4)``                      ``min_gap A 4h``
``max_count_per("A", 4, hours=24)``            ``max_count A 4 per 24h``
``never_while("A", after="B", until="C")``     ``never_while A after B until C``
``monitor("...")``                             any text form
=============================================  =============================================

Events are named like monitors: a bare name is an activity's completion, a trigger's raise or
a process's start (``activity:``, ``trigger:``, ``process:`` make it explicit; ``a|b`` is
either); :func:`activity_completed`, :func:`event` and any ``Callable[[TraceEvent], bool]``
select events too (such a predicate is judged on every event, so as a monitor it sees the
whole trace).

Pure Python (no pytest): usable by any layer above the property language.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from typing import Any

from opspec.engine.trace import EventKind, TraceEvent
from opspec.errors import ConfigurationError
from opspec.properties import language, text_form

__all__ = [
    "Count",
    "Failure",
    "Match",
    "Predicate",
    "activity_completed",
    "activity_started",
    "as_predicate",
    "count",
    "event",
    "eventually",
    "happens_before",
    "max_count_per",
    "min_gap",
    "monitor",
    "never",
    "never_while",
    "per_instance",
    "process_started",
    "trigger_raised",
    "within",
]


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
        return _All((self, as_predicate(other)))

    def __or__(self, other: Predicate) -> Predicate:
        return _Any((self, as_predicate(other)))

    def __invert__(self) -> Predicate:
        return _Not(self)

    def per_instance(self, process: str) -> Predicate:
        """This predicate on each instance of ``process`` (its own events only)."""
        return per_instance(process, self)


# ---------------------------------------------------------------- selecting events
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
        return _Holds(language.Eventually(self.selector())).fail(events, end)

    def witness(self, events: Sequence[TraceEvent]) -> tuple[TraceEvent, ...]:
        return tuple(self.all(events)[:1])

    def monitor(self) -> language.Property:
        return language.Eventually(self.selector())

    def __invert__(self) -> Predicate:
        return never(self)


def _subject_match(subject: language.Subject) -> Match:
    return Match(subject.matches, str(subject), subject)


def _as_match(what: str | Match | Callable[[TraceEvent], bool]) -> Match:
    if isinstance(what, Match):
        return what
    if isinstance(what, str):
        return _subject_match(language.parse_subject(what))
    if callable(what):
        return Match(what, getattr(what, "__name__", repr(what)))
    raise TypeError(f"expected an event name, a Match or a callable, not {what!r}")


def as_predicate(what: Any) -> Predicate:
    """A predicate, a property (a monitor), a property's text (it has spaces: ``"never
    notify_caregiver"``), or an event name (``"dispense"``: it happens)."""
    if isinstance(what, Predicate):
        return what
    if isinstance(what, language.Property):
        return _Holds(what)
    if isinstance(what, str) and len(what.split()) > 1:
        return _Holds(text_form.parse_property(what))
    return _as_match(what)


def _selector(kind: str, what: str, name: str, process: str | None,
              test: Callable[[TraceEvent], bool]) -> Match:
    in_process = f" in {process}" if process else ""
    return Match(lambda e: e.kind == kind and test(e) and (process is None or e.process == process),
                 f"{what} {name} {kind.split('.')[1]}{in_process}", language.Subject(name, what),
                 process)


def activity_completed(name: str, *, process: str | None = None) -> Match:
    """Completions of activity ``name`` (in ``process`` only, if given)."""
    return _selector(EventKind.ACTIVITY_COMPLETED, "activity", name, process,
                     lambda e: e.activity == name)


def activity_started(name: str, *, process: str | None = None) -> Match:
    """Starts of activity ``name``."""
    return _selector(EventKind.ACTIVITY_STARTED, "activity", name, process,
                     lambda e: e.activity == name)


def trigger_raised(name: str) -> Match:
    """Raises of the message or signal ``name``."""
    return _selector(EventKind.TRIGGER_RAISED, "trigger", name, None,
                     lambda e: e.data.get("name") == name)


def process_started(name: str) -> Match:
    """Starts of instances of process ``name``."""
    return _selector(EventKind.PROCESS_STARTED, "process", name, None,
                     lambda e: e.process == name)


def event(kind: str, *, activity: str | None = None, process: str | None = None,
          **data: Any) -> Match:
    """Events of ``kind`` (e.g. ``"activity.omitted"``) with these fields and data values."""
    def test(e: TraceEvent) -> bool:
        return (e.kind == kind and (activity is None or e.activity == activity)
                and (process is None or e.process == process)
                and all(e.data.get(k) == v for k, v in data.items()))

    parts = [kind, *(x for x in (activity, process and f"in {process}") if x),
             *(f"{k}={v!r}" for k, v in data.items())]
    subject = language.Subject(activity, "activity") if activity else None
    return Match(test, " ".join(parts), subject, process)


# ---------------------------------------------------------------- properties as predicates
class _Holds(Predicate):
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
        if isinstance(other, _Holds):
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
        return _Holds(self.property._with([s.bind(names)
                                           if isinstance(s, (language.Subject, Match))
                                           else s for s in self.property.subjects()]),
                      self.label)

    def __invert__(self) -> Predicate:
        prop = self.property
        if isinstance(prop, language.Never):
            return _Holds(language.Eventually(prop.subject), f"eventually({prop.subject})")
        if isinstance(prop, language.Eventually):
            return _Holds(language.Never(prop.subject), f"never({prop.subject})")
        return _Not(self)


def eventually(what: str | Match | Predicate | Callable[[TraceEvent], bool]) -> Predicate:
    """``what`` happens at least once (a predicate is returned as it is)."""
    if isinstance(what, Predicate) and not isinstance(what, Match):
        return what
    match = _as_match(what)
    return _Holds(language.Eventually(match.selector()), f"eventually({match.describe()})")


def never(what: str | Match | Predicate | Callable[[TraceEvent], bool]) -> Predicate:
    """``what`` never happens (for a predicate: it does not hold, i.e. ``~what``)."""
    if isinstance(what, Predicate) and not isinstance(what, Match):
        return _Not(what)
    match = _as_match(what)
    return _Holds(language.Never(match.selector()), f"never({match.describe()})")


def happens_before(a: str | Match | Callable[[TraceEvent], bool],
                   b: str | Match | Callable[[TraceEvent], bool], *,
                   each: bool = False) -> Predicate:
    """No ``b`` before the first ``a`` (``b`` may not happen at all; an event that is both
    precedes itself). ``each=True``: every ``b`` has its own earlier ``a`` (the n-th ``b``
    comes after the n-th ``a``). The property ``A before B`` (``A before each B``)."""
    first, then = _as_match(a), _as_match(b)
    label = (f"happens_before({first.describe()}, {then.describe()}"
             f"{', each=True' if each else ''})")
    return _Holds(language.Precedence(first.selector(), then.selector(), each), label)


def within(a: str | Match | Callable[[TraceEvent], bool],
           b: str | Match | Callable[[TraceEvent], bool], seconds: float) -> Predicate:
    """Every ``a`` is followed by a ``b`` at most ``seconds`` later (exactly ``seconds`` is in
    time; an event that is both answers itself). An ``a`` whose window is cut off by the end
    of the run is not judged; ``seconds=math.inf``: by the end of the run. The property
    ``bounded_response A B D`` (``B within D after A``)."""
    if isinstance(seconds, bool) or not (isinstance(seconds, (int, float)) and seconds >= 0):
        raise ConfigurationError(f"within(): seconds must be >= 0, not {seconds!r}")
    cause, response = _as_match(a), _as_match(b)
    return _Holds(language.BoundedResponse(cause.selector(), response.selector(), float(seconds)),
                  f"within({cause.describe()}, {response.describe()}, {seconds:g} s)")


# ---------------------------------------------------------------- counting
class Count:
    """``count(x)``: compare with ``==``, ``!=``, ``<``, ``<=``, ``>``, ``>=``, or use
    :meth:`between`, :meth:`at_least`, :meth:`at_most`; each gives a :class:`Predicate`
    judged per trace (per replication, or per instance with ``per_instance``): the property
    ``count A OP n``."""

    __hash__ = None  # type: ignore[assignment]

    def __init__(self, match: Match) -> None:
        self.match = match

    def __repr__(self) -> str:
        return f"count({self.match.describe()})"

    def _bound(self, op: str, n: object, hi: object = None) -> Predicate:
        bound = language.CountBound(self.match.selector(), op, _number(n),
                                    None if hi is None else _number(hi))
        target = (f"between {bound.a:g} and {bound.b:g}" if op == "in"
                  else f"{op} {bound.a:g}")
        return _Holds(bound, f"count({self.match.describe()}) {target}")

    def __eq__(self, n: object) -> Predicate:  # type: ignore[override]
        return self._bound("==", n)

    def __ne__(self, n: object) -> Predicate:  # type: ignore[override]
        return self._bound("!=", n)

    def __lt__(self, n: float) -> Predicate:
        return self._bound("<", n)

    def __le__(self, n: float) -> Predicate:
        return self._bound("<=", n)

    def __gt__(self, n: float) -> Predicate:
        return self._bound(">", n)

    def __ge__(self, n: float) -> Predicate:
        return self._bound(">=", n)

    def between(self, lo: float, hi: float) -> Predicate:
        """``lo <= count <= hi``."""
        if lo > hi:
            raise ConfigurationError(f"count().between({lo}, {hi}): the range is empty")
        return self._bound("in", lo, hi)

    def at_least(self, n: float) -> Predicate:
        return self >= n

    def at_most(self, n: float) -> Predicate:
        return self <= n

    def exactly(self, n: float) -> Predicate:
        return self == n

    def of(self, events: Sequence[TraceEvent]) -> int:
        """How many events of ``events`` match."""
        return len(self.match.all(events))


def _number(n: object) -> float:
    if isinstance(n, bool) or not isinstance(n, (int, float)):
        raise TypeError(f"count() compares with a number, not {n!r}")
    return float(n)


def count(what: str | Match | Callable[[TraceEvent], bool]) -> Count:
    """How many times ``what`` happens in a trace (see :class:`Count`)."""
    return Count(_as_match(what))


# ---------------------------------------------------------------- composition and scope
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


class _Not(Predicate):
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
        return _Not(self.inner.bind(names))


def _paren(p: Predicate) -> str:
    text = p.describe()
    return f"({text})" if isinstance(p, (_All, _Not)) or " | " in text else text


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
    return _PerInstance(process, as_predicate(predicate))




# ---------------------------------------------------------------- the monitors' shapes
def _seconds(what: str, seconds: float, minutes: float, hours: float) -> float:
    total = float(seconds) + 60.0 * minutes + 3600.0 * hours
    if not total > 0:
        raise ConfigurationError(f"{what}(): the time must be positive",
                                 hint="give seconds=, minutes= or hours=")
    return total


def _span_text(seconds: float) -> str:
    return f"{seconds / 3600:g}h" if seconds >= 3600 else f"{seconds:g}s"


def monitor(text: str) -> Predicate:
    """A property from its text form (``"min_gap dispense 4h"``, any form of
    :mod:`opspec.properties.language`)."""
    return _Holds(text_form.parse_property(text, what="monitor"))


def min_gap(subject: str, *, seconds: float = 0, minutes: float = 0, hours: float = 0
            ) -> Predicate:
    """No two ``subject`` closer than the given time: ``min_gap("dispense", hours=4)``."""
    gap = _seconds("min_gap", seconds, minutes, hours)
    return _Holds(language.MinGap(language.parse_subject(subject), gap,
                                  text=f"min_gap {subject} {_span_text(gap)}"))


def never_while(subject: str, *, after: str, until: str) -> Predicate:
    """``subject`` never happens after an ``after`` and before the next ``until``."""
    return _Holds(language.NeverWhile(
        language.parse_subject(subject), language.parse_subject(after),
        language.parse_subject(until), text=f"never_while {subject} after {after} until {until}"))


def max_count_per(subject: str, limit: int, *, seconds: float = 0, minutes: float = 0,
                  hours: float = 0) -> Predicate:
    """At most ``limit`` ``subject`` in any window of the given length."""
    if isinstance(limit, bool) or not isinstance(limit, int) or limit < 0:
        raise ConfigurationError(f"max_count_per(): limit must be a whole number >= 0, "
                                 f"not {limit!r}")
    window = _seconds("max_count_per", seconds, minutes, hours)
    return _Holds(language.MaxCount(language.parse_subject(subject), limit, window,
                                    text=f"max_count {subject} {limit} per {_span_text(window)}"))
