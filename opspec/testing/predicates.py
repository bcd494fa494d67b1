"""Trace predicates that read like the spec, for ``assert holds(result, ...)`` and ``check``.

::

    from opspec.testing.predicates import check, count, happens_before, holds, never, within

    assert holds(result, within("sound_alarm", "press_report", 60))
    check(result, happens_before("sound_alarm", "press_report") & never("notify_caregiver"))
    check(result, (count("dispense") == 1).per_instance("notify_workflow"))

A predicate is judged on each trace of what it is given - a
:class:`~opspec.testing.simulation.SimulationResult` (every replication), an engine
:class:`~opspec.engine.simulation.RunResult`, a plain sequence of
:class:`~opspec.engine.trace.TraceEvent`, or the path of a JSON Lines trace written by
``opspec run --trace`` - and holds when it holds on every one.

The temporal predicates are the properties of :mod:`opspec.properties.language`, the language
of monitors: ``within(a, b, 60)`` is ``bounded_response a b 60s``, ``happens_before(a, b)`` is
``a before b``, ``never(x)`` is ``never x``, ``count(x) <= 4`` is ``count x <= 4``. Each is
judged by feeding the trace to the evaluator a monitor runs online, so both give the same
verdict and the same witness on the same run. The text form and monitor objects are
predicates too: ``holds(result, "min_gap dispense 4h")``, ``check(result,
min_gap("dispense", hours=4))``.

Events are named like monitors: a bare name is an activity's completion, a trigger's raise or
a process's start (``activity:``, ``trigger:``, ``process:`` make it explicit; ``a|b`` is
either); :func:`activity_completed`, :func:`event` and any ``Callable[[TraceEvent], bool]``
select events too. Names are checked against the spec (of a
``SimulationResult``, or ``spec=``): one the spec lacks raises
:class:`~opspec.errors.ConfigurationError` listing the names it has.

:func:`check` raises ``AssertionError`` with the claim, why it failed, and the few events
around the violation (marked ``>``), not the whole trace.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from opspec.engine.trace import EventKind, TraceEvent
from opspec.errors import ConfigurationError
from opspec.properties.language import (
    BoundedResponse,
    CountBound,
    Eventually,
    MonitorRun,
    Never,
    Precedence,
    Property,
    Subject,
    clock,
    parse_property,
    parse_subject,
    trace_end,
)

__all__ = [
    "Count",
    "Match",
    "Predicate",
    "activity_completed",
    "activity_started",
    "check",
    "count",
    "event",
    "eventually",
    "happens_before",
    "holds",
    "never",
    "per_instance",
    "process_started",
    "trigger_raised",
    "within",
]

#: events shown before / after each focus event of a failure, and at most in all
BEFORE, AFTER, MAX_LINES = 4, 2, 14


@dataclass(frozen=True, slots=True)
class Failure:
    """Why a predicate failed on one trace: message lines and the events to show."""

    lines: tuple[str, ...]
    focus: tuple[TraceEvent, ...] = ()
    trace: Sequence[TraceEvent] = ()


@dataclass(frozen=True, slots=True)
class _Run:
    label: str                          # "" or " (replication 3)"
    events: Sequence[TraceEvent]
    end: float                          # simulated end of the run (windows after it: unjudged)


class Predicate:
    """A property of one trace. Combine with ``&``, ``|``, ``~``; scope with
    :meth:`per_instance`. Subclasses implement :meth:`describe`, :meth:`fail` and
    :meth:`subjects`."""

    def describe(self) -> str:
        raise NotImplementedError

    def subjects(self) -> tuple[Subject, ...]:
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

    def __repr__(self) -> str:
        return self.describe()

    def __and__(self, other: Predicate) -> Predicate:
        return _All((self, _as_predicate(other)))

    def __or__(self, other: Predicate) -> Predicate:
        return _Any((self, _as_predicate(other)))

    def __invert__(self) -> Predicate:
        return _Not(self)

    def per_instance(self, process: str) -> Predicate:
        """This predicate on each instance of ``process`` (its own events only)."""
        return per_instance(process, self)


# ---------------------------------------------------------------- selecting events
class Match(Predicate):
    """A selector of events; as a predicate it means "happens at least once"."""

    def __init__(self, test: Callable[[TraceEvent], bool], text: str,
                 subject: Subject | None = None, process: str | None = None) -> None:
        self._test = test
        self.text = text
        self.subject = subject
        self.process = process

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

    def subjects(self) -> tuple[Subject, ...]:
        return (self.subject,) if self.subject is not None else ()

    def processes(self) -> tuple[str, ...]:
        return (self.process,) if self.process is not None else ()

    def all(self, events: Iterable[TraceEvent]) -> list[TraceEvent]:
        return [e for e in events if self._test(e)]

    def fail(self, events: Sequence[TraceEvent], end: float) -> Failure | None:
        return _Holds(Eventually(self)).fail(events, end)

    def witness(self, events: Sequence[TraceEvent]) -> tuple[TraceEvent, ...]:
        return tuple(self.all(events)[:1])

    def __invert__(self) -> Predicate:
        return never(self)


def _subject_match(subject: Subject) -> Match:
    return Match(subject.matches, str(subject), subject)


def _as_match(what: str | Match | Callable[[TraceEvent], bool]) -> Match:
    if isinstance(what, Match):
        return what
    if isinstance(what, str):
        return _subject_match(parse_subject(what))
    if callable(what):
        return Match(what, getattr(what, "__name__", repr(what)))
    raise TypeError(f"expected an event name, a Match or a callable, not {what!r}")


def _as_predicate(what: Any) -> Predicate:
    """A predicate, a property (a monitor), a property's text (it has spaces: ``"never
    notify_caregiver"``), or an event name (``"dispense"``: it happens)."""
    if isinstance(what, Predicate):
        return what
    if isinstance(what, Property):
        return _Holds(what)
    if isinstance(what, str) and len(what.split()) > 1:
        return _Holds(parse_property(what))
    return _as_match(what)


def _selector(kind: str, what: str, name: str, process: str | None,
              test: Callable[[TraceEvent], bool]) -> Match:
    in_process = f" in {process}" if process else ""
    return Match(lambda e: e.kind == kind and test(e) and (process is None or e.process == process),
                 f"{what} {name} {kind.split('.')[1]}{in_process}", Subject(name, what), process)


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
    subject = Subject(activity, "activity") if activity else None
    return Match(test, " ".join(parts), subject, process)


# ---------------------------------------------------------------- properties as predicates
class _Holds(Predicate):
    """A :class:`~opspec.properties.language.Property` judged on a trace: its events fed to the
    evaluator a monitor runs online, so the verdict and the witness (the events marked in a
    failure) are the monitor's. ``label`` is how Python spelt it (``within(a, b, 60 s)``)."""

    def __init__(self, prop: Property, label: str | None = None) -> None:
        self.property = prop
        self.label = label

    def describe(self) -> str:
        return self.label or str(self.property)

    def subjects(self) -> tuple[Subject, ...]:
        out: list[Subject] = []
        for selector in self.property.subjects():
            if isinstance(selector, Subject):
                out.append(selector)
            elif isinstance(selector, Match):
                out.extend(selector.subjects())
        return tuple(out)

    def processes(self) -> tuple[str, ...]:
        return tuple(p for s in self.property.subjects() if isinstance(s, Match)
                     for p in s.processes())

    def judge(self, events: Sequence[TraceEvent], end: float) -> MonitorRun:
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
        return self.judge(events, trace_end(events)).evidence()

    def bind(self, names: Any) -> Predicate:
        return _Holds(self.property._with([s.bind(names) if isinstance(s, (Subject, Match))
                                           else s for s in self.property.subjects()]),
                      self.label)

    def __invert__(self) -> Predicate:
        prop = self.property
        if isinstance(prop, Never):
            return _Holds(Eventually(prop.subject), f"eventually({prop.subject})")
        if isinstance(prop, Eventually):
            return _Holds(Never(prop.subject), f"never({prop.subject})")
        return _Not(self)


def eventually(what: str | Match | Predicate | Callable[[TraceEvent], bool]) -> Predicate:
    """``what`` happens at least once (a predicate is returned as it is)."""
    if isinstance(what, Predicate) and not isinstance(what, Match):
        return what
    match = _as_match(what)
    return _Holds(Eventually(match), f"eventually({match.describe()})")


def never(what: str | Match | Predicate | Callable[[TraceEvent], bool]) -> Predicate:
    """``what`` never happens (for a predicate: it does not hold, i.e. ``~what``)."""
    if isinstance(what, Predicate) and not isinstance(what, Match):
        return _Not(what)
    match = _as_match(what)
    return _Holds(Never(match), f"never({match.describe()})")


def happens_before(a: str | Match | Callable[[TraceEvent], bool],
                   b: str | Match | Callable[[TraceEvent], bool], *,
                   each: bool = False) -> Predicate:
    """No ``b`` before the first ``a`` (``b`` may not happen at all; an event that is both
    precedes itself). ``each=True``: every ``b`` has its own earlier ``a`` (the n-th ``b``
    comes after the n-th ``a``). The property ``A before B`` (``A before each B``)."""
    first, then = _as_match(a), _as_match(b)
    label = (f"happens_before({first.describe()}, {then.describe()}"
             f"{', each=True' if each else ''})")
    return _Holds(Precedence(first, then, each), label)


def within(a: str | Match | Callable[[TraceEvent], bool],
           b: str | Match | Callable[[TraceEvent], bool], seconds: float) -> Predicate:
    """Every ``a`` is followed by a ``b`` at most ``seconds`` later (exactly ``seconds`` is in
    time; an event that is both answers itself). An ``a`` whose window is cut off by the end
    of the run is not judged; ``seconds=math.inf``: by the end of the run. The property
    ``bounded_response A B D`` (``B within D after A``)."""
    if isinstance(seconds, bool) or not (isinstance(seconds, (int, float)) and seconds >= 0):
        raise ConfigurationError(f"within(): seconds must be >= 0, not {seconds!r}")
    cause, response = _as_match(a), _as_match(b)
    return _Holds(BoundedResponse(cause, response, float(seconds)),
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
        bound = CountBound(self.match, op, _number(n), None if hi is None else _number(hi))
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

    def subjects(self) -> tuple[Subject, ...]:
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

    def subjects(self) -> tuple[Subject, ...]:
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

    def subjects(self) -> tuple[Subject, ...]:
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
                        f"{clock(own[0].time)}):")
                return Failure((head, *failure.lines), failure.focus, own)
        return None


def per_instance(process: str, predicate: Predicate | str | Match) -> Predicate:
    """``predicate`` on each instance of ``process`` separately, seeing only that instance's
    events (so ``count("dispense") == 1`` means once per dose, not once per run)."""
    return _PerInstance(process, _as_predicate(predicate))


# ---------------------------------------------------------------- judging results
def _runs(obj: Any) -> list[_Run]:
    from opspec.engine.simulation import RunResult

    if isinstance(obj, RunResult):
        if obj.trace is None:
            raise ConfigurationError("this run kept no trace",
                                     hint="run it with keep_trace=True")
        return [_Run("", obj.trace, float(obj.summary.get("time", _end(obj.trace))))]
    traces = getattr(obj, "traces", None)
    if traces is not None and hasattr(obj, "runs"):      # a SimulationResult
        horizon = getattr(obj, "horizon", None)
        many = len(traces) > 1
        return [_Run(f" (replication {i})" if many else "", t,
                     float(horizon) if horizon is not None else _end(t))
                for i, t in enumerate(traces)]
    if isinstance(obj, (str, os.PathLike)):               # a stored trace (opspec run --trace)
        from opspec.engine.trace_sinks import read_trace

        events = list(read_trace(os.fspath(obj)))
        return [_Run("", events, trace_end(events))]
    if isinstance(obj, Sequence) and all(isinstance(e, TraceEvent) for e in obj):
        return [_Run("", obj, trace_end(obj))]
    raise TypeError("expected a SimulationResult, a RunResult, a sequence of TraceEvent or the "
                    f"path of a JSON Lines trace, not {type(obj).__name__}")


def _end(trace: Sequence[TraceEvent]) -> float:
    return trace_end(trace)


def _names(obj: Any, spec: Any) -> Any:
    if spec is None:
        return getattr(obj, "names", None)
    if hasattr(spec, "activities") and hasattr(spec, "triggers"):
        return spec
    from opspec.engine.compiled import CompiledPackage, compile_package
    from opspec.testing.simulation import load_spec_file, spec_names

    if isinstance(spec, (str, os.PathLike)):
        spec = load_spec_file(os.fspath(spec))
    compiled = spec if isinstance(spec, CompiledPackage) else compile_package(spec)
    return spec_names(compiled)


def check_names(predicate: Predicate, names: Any) -> None:
    """:class:`ConfigurationError` when ``predicate`` names something the spec lacks."""
    for subject in predicate.subjects():
        subject.bind(names)
    for process in predicate.processes():
        if process not in names.processes:
            raise ConfigurationError(f"the spec has no process {process!r}",
                                     hint="its processes are: " + ", ".join(names.processes))


def failures(obj: Any, predicate: Predicate | str | Match, *, spec: Any = None,
             first: bool = True) -> list[str]:
    """The failure messages of ``predicate`` on each trace of ``obj`` (the first only, by
    default); empty when it holds."""
    predicate = _as_predicate(predicate)
    names = _names(obj, spec)
    if names is not None:
        check_names(predicate, names)
        predicate = predicate.bind(names)
    out = []
    for run in _runs(obj):
        failure = predicate.fail(run.events, run.end)
        if failure is None:
            continue
        lines = [f"expected {predicate.describe()}" + run.label,
                 *(f"  {line}" for line in failure.lines)]
        lines.extend(failure_slice(failure.trace or run.events, failure.focus))
        out.append("\n".join(lines))
        if first:
            break
    return out


def holds(obj: Any, predicate: Predicate | str | Match, *, spec: Any = None) -> bool:
    """Whether ``predicate`` holds on every trace of ``obj``. Names the spec lacks raise
    :class:`ConfigurationError` (they are a mistake in the test, not a failed claim)."""
    return not failures(obj, predicate, spec=spec)


def check(obj: Any, *predicates: Predicate | str | Match, spec: Any = None) -> None:
    """Assert every predicate on ``obj``; ``AssertionError`` with each failure's claim,
    reason and trace slice."""
    __tracebackhide__ = True
    messages = [m for p in predicates for m in failures(obj, p, spec=spec)]
    if messages:
        seed = getattr(obj, "seed", None)
        if seed is not None and hasattr(obj, "replications"):
            messages.append(f"(seed {seed}, {obj.replications} replication(s))")
        raise AssertionError("\n\n".join(messages))


def failure_slice(trace: Sequence[TraceEvent], witness: Sequence[TraceEvent]) -> list[str]:
    """What a failure shows of the trace: the witness events marked in their context, or,
    when nothing happened to show (``eventually``), how the trace ends."""
    from opspec.testing.expectations import format_events

    if witness or not trace:
        return trace_slice(trace, witness)
    return ["  the trace ends with:", *format_events(list(trace[-BEFORE:]))]


def trace_slice(trace: Sequence[TraceEvent], focus: Sequence[TraceEvent]) -> list[str]:
    """A few events around each focus event (marked ``>``), ``...`` between the pieces."""
    from opspec.testing.expectations import format_events

    if not focus or not trace:
        return []
    index = {id(e): i for i, e in enumerate(trace)}
    marked = {index[id(e)] for e in focus if id(e) in index}
    if not marked:
        return ["  trace (relevant events):", *format_events(list(focus)[:MAX_LINES])]
    keep: set[int] = set()
    for i in sorted(marked):
        keep.update(range(max(0, i - BEFORE), min(len(trace), i + AFTER + 1)))
    rows = sorted(keep)
    if len(rows) > MAX_LINES:      # keep the marked rows and their closest neighbours
        rows = sorted(sorted(rows, key=lambda r: min(abs(r - m) for m in marked))[:MAX_LINES])
    lines = [f"  trace around it ({len(marked)} marked event(s) of {len(trace)}):"]
    previous = None
    for r in rows:
        if previous is not None and r != previous + 1:
            lines.append("    ...")
        (text,) = format_events([trace[r]])
        lines.append((">" + text[1:]) if r in marked else text)
        previous = r
    return lines

