"""The ``then`` lines of scenario files: readable expectations over a simulation result.

Each line is one of (keywords in any case; ``OP`` is ``==``, ``!=``, ``<``, ``<=``, ``>``,
``>=``; times are durations such as ``300s``, ``5 min``, ``4h``)::

    doses_taken == 1                          a metric (count total, duration mean, ratio)
    report_latency_s.p95 <= 600               a metric field (n, mean, p95, min, max, ...)
    alarms_per_dose in [1, 1.5]               a closed interval
    never activity notify_caregiver           no completion of it in any replication
    eventually activity record_taken          a completion in every replication
    count activity sound_alarm == 3           completions, summed over replications
    activity press_report before activity dispense     first completions, in order
    activity dispense within 300s after activity sound_alarm
    never activity dispense twice within 4h   no two completions closer than that
    rate doses_taken/doses_due >= 0.95 with 95% confidence
    mean alarms_per_dose in [1.1, 1.25] with 95% confidence
    p95 report_latency_s <= 600 with 95% confidence

``activity X`` may also be ``trigger X`` (a message or signal raised) or ``process X`` (an
instance started). Metric comparisons use the metrics pooled over all replications; ``==``
allows a relative error of 1e-9. The statistical lines are decided by
:mod:`opspec.testing.intervals`: they pass when the one-sided bound at that confidence is on
the right side, fail when the claim is refuted at that confidence, and otherwise fail saying
how many replications would decide it.
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import pairwise

from opspec.engine.monitors import clock
from opspec.engine.trace import EventKind, TraceEvent
from opspec.errors import ConfigurationError, SourceLocation
from opspec.testing.simulation import FIELDS, SimulationResult, SpecNames

__all__ = ["Expectation", "expect", "format_events", "parse_expectation"]

_OPS: dict[str, Callable[[float, float], bool]] = {
    "==": lambda a, b: math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-9),
    "!=": lambda a, b: not math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-9),
    "<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge,
}
_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_OP = r"==|!=|<=|>=|<|>"
_SUBJECT = r"(?P<{0}kind>activity|trigger|process)\s+(?P<{0}name>[\w.:-]+)"
_TARGET = rf"(?:(?P<op>{_OP})\s*(?P<num>{_NUM})|in\s*\[\s*(?P<lo>{_NUM})\s*,\s*(?P<hi>{_NUM})\s*\])"
_CONF = r"\s+with\s+(?P<conf>\d+(?:\.\d+)?)\s*%\s+confidence"
_FORMS: list[tuple[str, re.Pattern[str]]] = [
    ("rate", re.compile(rf"rate\s+(?P<num_m>\w+)\s*/\s*(?P<den_m>\w+)\s*{_TARGET}{_CONF}", re.IGNORECASE)),
    ("mean", re.compile(rf"mean\s+(?P<metric>[\w.]+)\s*{_TARGET}{_CONF}", re.IGNORECASE)),
    ("quantile", re.compile(rf"p(?P<q>\d+(?:\.\d+)?)\s+(?P<metric>\w+)\s*{_TARGET}{_CONF}",
                            re.IGNORECASE)),
    ("twice", re.compile(rf"never\s+{_SUBJECT.format('a')}\s+twice\s+within\s+(?P<gap>.+)",
                         re.IGNORECASE)),
    ("never", re.compile(rf"never\s+{_SUBJECT.format('a')}", re.IGNORECASE)),
    ("eventually", re.compile(rf"eventually\s+{_SUBJECT.format('a')}", re.IGNORECASE)),
    ("count", re.compile(rf"count\s+{_SUBJECT.format('a')}\s*{_TARGET}", re.IGNORECASE)),
    ("within", re.compile(rf"{_SUBJECT.format('b')}\s+within\s+(?P<gap>.+?)\s+after\s+"
                          rf"{_SUBJECT.format('a')}", re.IGNORECASE)),
    ("before", re.compile(rf"{_SUBJECT.format('a')}\s+before\s+{_SUBJECT.format('b')}",
                          re.IGNORECASE)),
    ("metric", re.compile(rf"(?P<metric>[\w]+(?:\.\w+)?)\s*{_TARGET}", re.IGNORECASE)),
]
_KIND_EVENT = {"activity": EventKind.ACTIVITY_COMPLETED, "trigger": EventKind.TRIGGER_RAISED,
               "process": EventKind.PROCESS_STARTED}
_HINT = "see the list of expectation forms in docs/spec-testing.md"
_SLICE = 12


@dataclass(frozen=True, slots=True)
class Expectation:
    """One parsed ``then`` line; :meth:`check` returns ``None`` or a failure message."""

    text: str
    form: str
    groups: dict[str, str]

    # ------------------------------------------------------------ helpers
    def _target(self) -> tuple[str, float, float | None]:
        g = self.groups
        if g.get("op"):
            return g["op"], float(g["num"]), None
        return "in", float(g["lo"]), float(g["hi"])

    def _describe_target(self) -> str:
        op, a, b = self._target()
        return f"in [{a:g}, {b:g}]" if op == "in" else f"{op} {a:g}"

    def _holds(self, value: float) -> bool:
        op, a, b = self._target()
        if op == "in":
            assert b is not None
            return a - 1e-12 <= value <= b + 1e-12
        return _OPS[op](value, a)

    def names(self) -> list[tuple[str, str]]:
        """(what, name) pairs this expectation refers to: metrics, activities, ..."""
        g = self.groups
        out = []
        for key in ("metric", "num_m", "den_m"):
            if g.get(key):
                out.append(("metric", g[key].split(".")[0]))
        for prefix in ("a", "b"):
            if g.get(f"{prefix}kind"):
                out.append((g[f"{prefix}kind"].lower(), g[f"{prefix}name"]))
        return out

    def check_names(self, names: SpecNames, where: str) -> None:
        """Raise :class:`ConfigurationError` naming what the spec has instead."""
        table = {"metric": names.metrics, "activity": names.activities,
                 "trigger": names.triggers, "process": names.processes}
        for what, name in self.names():
            if name not in table[what]:
                known = ", ".join(table[what]) or "(none)"
                raise ConfigurationError(
                    f"{self.text!r} names {what} {name!r}, which the spec does not have",
                    location=_loc(where), hint=f"the spec's {what} names are: {known}")

    # ------------------------------------------------------------ checking
    def check(self, result: SimulationResult) -> str | None:
        return getattr(self, f"_check_{self.form}")(result)  # type: ignore[no-any-return]

    def _check_metric(self, result: SimulationResult) -> str | None:
        metric = self.groups["metric"]
        name = metric.split(".")[0]
        value = result.value(metric)
        if value is not None and self._holds(value):
            return None
        over = f" (pooled over {result.replications} replications)" if (
            result.replications > 1) else ""
        lines = [f"expected {self.text}", f"  but {metric} = {_fmt(value)}{over}",
                 f"  {name}: {_metric_line(result.metrics[name])}"]
        return _with_slice(lines, result, _metric_events(result, name))

    def _events(self, result: SimulationResult, prefix: str) -> list[list[TraceEvent]]:
        kind = _KIND_EVENT[self.groups[f"{prefix}kind"].lower()]
        name = self.groups[f"{prefix}name"]
        out = []
        for trace in result.traces:
            out.append([e for e in trace if e.kind == kind and _named(e, name)])
        return out

    def _subject(self, prefix: str) -> str:
        return f"{self.groups[f'{prefix}kind'].lower()} {self.groups[f'{prefix}name']}"

    def _check_never(self, result: SimulationResult) -> str | None:
        for rep, events in enumerate(self._events(result, "a")):
            if events:
                lines = [f"expected {self.text}",
                         f"  but {self._subject('a')} happened {len(events)} time(s)"
                         + _in_rep(result, rep) + f", first at {_time(events[0].time)}"]
                return _with_slice(lines, result, _around(result.traces[rep], events[0]))
        return None

    def _check_eventually(self, result: SimulationResult) -> str | None:
        for rep, events in enumerate(self._events(result, "a")):
            if not events:
                trace = result.traces[rep]
                lines = [f"expected {self.text}",
                         f"  but {self._subject('a')} never happened" + _in_rep(result, rep)
                         + f" (run to {_time(result.horizon or 0.0)})"]
                return _with_slice(lines, result, list(trace[-_SLICE:]), "the trace ends with")
        return None

    def _check_count(self, result: SimulationResult) -> str | None:
        per = [len(events) for events in self._events(result, "a")]
        total = sum(per)
        if self._holds(float(total)):
            return None
        lines = [f"expected {self.text}", f"  but it happened {total} time(s)"
                 + (f" over {len(per)} replications" if len(per) > 1 else "")]
        first = next((i for i, n in enumerate(per) if n), None)
        events = self._events(result, "a")[first] if first is not None else []
        return _with_slice(lines, result, events[:_SLICE])

    def _check_before(self, result: SimulationResult) -> str | None:
        firsts, seconds = self._events(result, "a"), self._events(result, "b")
        for rep, (a, b) in enumerate(zip(firsts, seconds, strict=True)):
            if b and (not a or a[0].seq > b[0].seq):
                lines = [f"expected {self.text}",
                         f"  but {self._subject('b')} happened at {_time(b[0].time)}"
                         + (f", before {self._subject('a')} ({_time(a[0].time)})" if a
                            else f" and {self._subject('a')} never did") + _in_rep(result, rep)]
                return _with_slice(lines, result, _around(result.traces[rep], b[0]))
        return None

    def _check_within(self, result: SimulationResult) -> str | None:
        gap = _duration(self.groups["gap"])
        causes, effects = self._events(result, "a"), self._events(result, "b")
        end = result.horizon if result.horizon is not None else math.inf
        for rep, (a, b) in enumerate(zip(causes, effects, strict=True)):
            for cause in a:
                if cause.time + gap > end:
                    continue   # the run ended before the window closed: not decided
                if not any(cause.time <= e.time <= cause.time + gap and e.seq > cause.seq
                           for e in b):
                    lines = [f"expected {self.text}",
                             f"  but after {self._subject('a')} at {_time(cause.time)}"
                             f" no {self._subject('b')} followed within {_span(gap)}"
                             + _in_rep(result, rep)]
                    window = [e for e in result.traces[rep]
                              if cause.time <= e.time <= cause.time + gap
                              and e.instance == cause.instance and e.seq >= cause.seq]
                    return _with_slice(lines, result, window[:_SLICE])
        return None

    def _check_twice(self, result: SimulationResult) -> str | None:
        gap = _duration(self.groups["gap"])
        for rep, events in enumerate(self._events(result, "a")):
            for first, second in pairwise(events):
                if second.time - first.time < gap:
                    lines = [f"expected {self.text}",
                             f"  but {self._subject('a')} happened at {_time(first.time)} and "
                             f"again at {_time(second.time)}, "
                             f"{_span(second.time - first.time)} apart" + _in_rep(result, rep)]
                    return _with_slice(lines, result, [first, second])
        return None

    def _check_rate(self, result: SimulationResult) -> str | None:
        from opspec.testing.intervals import decide_rate

        num, den = self.groups["num_m"], self.groups["den_m"]
        successes, trials = result.value(num), result.value(den)
        op, a, b = self._target()
        return decide_rate(self.text, int(successes or 0), int(trials or 0), op, a, b,
                           float(self.groups["conf"]) / 100.0, units=f"{den}",
                           replications=result.replications)

    def _check_mean(self, result: SimulationResult) -> str | None:
        from opspec.testing.intervals import decide_mean

        op, a, b = self._target()
        return decide_mean(self.text, result.samples(self.groups["metric"]), op, a, b,
                           float(self.groups["conf"]) / 100.0)

    def _check_quantile(self, result: SimulationResult) -> str | None:
        from opspec.testing.intervals import decide_quantile

        op, a, b = self._target()
        return decide_quantile(self.text, result.observations(self.groups["metric"]),
                               float(self.groups["q"]) / 100.0, op, a, b,
                               float(self.groups["conf"]) / 100.0)


def parse_expectation(text: str, *, where: str = "<then>") -> Expectation:
    """Parse one ``then`` line; :class:`ConfigurationError` at ``where`` if unreadable."""
    if not isinstance(text, str):
        raise ConfigurationError(f"an expectation is text, not {text!r}", location=_loc(where),
                                 hint='write e.g. "doses_taken == 1"')
    cleaned = " ".join(text.split())
    for form, pattern in _FORMS:
        match = pattern.fullmatch(cleaned)
        if match is None:
            continue
        groups = {k: v for k, v in match.groupdict().items() if v is not None}
        if form in ("metric", "mean") and "." in groups.get("metric", ""):
            _, field = groups["metric"].split(".", 1)
            if not any(field in fields for fields in FIELDS.values()):
                raise ConfigurationError(
                    f"{text!r}: {field!r} is not a metric field", location=_loc(where),
                    hint="fields: " + ", ".join(sorted({f for fs in FIELDS.values()
                                                         for f in fs})))
        if "conf" in groups and not 50.0 <= float(groups["conf"]) < 100.0:
            raise ConfigurationError(f"{text!r}: the confidence must be at least 50% and "
                                     "below 100%", location=_loc(where))
        if "gap" in groups:
            try:
                _duration(groups["gap"])
            except ConfigurationError as error:
                raise ConfigurationError(f"{text!r}: {error.message}", location=_loc(where),
                                         hint=error.hint) from None
        if "lo" in groups and float(groups["lo"]) > float(groups["hi"]):
            raise ConfigurationError(f"{text!r}: the interval is empty", location=_loc(where))
        return Expectation(cleaned, form, groups)
    raise ConfigurationError(f"cannot read the expectation {text!r}", location=_loc(where),
                             hint=_HINT)


# ---------------------------------------------------------------- formatting
def _loc(where: str) -> SourceLocation:
    path, _, key = where.partition(": ")
    return SourceLocation(path, key=key or None)


def _duration(text: str) -> float:
    from opspec.clock import parse_duration

    return parse_duration(text, error=ConfigurationError)


def _named(event: TraceEvent, name: str) -> bool:
    if event.kind == EventKind.TRIGGER_RAISED:
        return event.data.get("name") == name
    if event.kind == EventKind.PROCESS_STARTED:
        return event.process == name
    return event.activity == name


def _fmt(value: float | None) -> str:
    return "undefined (no samples)" if value is None else f"{value:g}"


def _metric_line(values: dict[str, object]) -> str:
    return ", ".join(f"{k}={_fmt(v) if isinstance(v, (int, float)) or v is None else v}"
                     for k, v in values.items() if k != "kind")


def _time(seconds: float) -> str:
    return clock(seconds)


def _span(seconds: float) -> str:
    if seconds >= 3600:
        return f"{seconds / 3600:g} h"
    if seconds >= 60:
        return f"{seconds / 60:g} min"
    return f"{seconds:g} s"


def _in_rep(result: SimulationResult, rep: int) -> str:
    return f" (replication {rep})" if result.replications > 1 else ""


def format_events(events: Sequence[TraceEvent]) -> list[str]:
    """One short line per event: time, instance, process, kind, activity, key data."""
    out = []
    for e in events:
        what = e.activity or ""
        if e.kind == EventKind.TRIGGER_RAISED:
            what = f"{e.data.get('name', '?')}" + (f" (by {e.activity})" if e.activity else "")
        detail = ""
        for key in ("exception", "reason", "message", "choice"):
            if key in e.data:
                detail = f"  ({key}: {e.data[key]})"
                break
        inst = f"#{e.instance}" if e.instance is not None else ""
        out.append(f"    {_time(e.time)}  {inst:>4} {e.process or '':<18} {e.kind:<20} "
                   f"{what}{detail}".rstrip())
    return out


def _with_slice(lines: list[str], result: SimulationResult, events: Sequence[TraceEvent],
                title: str = "") -> str:
    if events:
        title = title or f"trace ({len(events)} relevant event(s))"
        lines = [*lines, f"  {title}:", *format_events(events)]
    return "\n".join(lines)


def _around(trace: Sequence[TraceEvent], event: TraceEvent) -> list[TraceEvent]:
    """The events of ``event``'s instance up to it, plus the few just before it."""
    same = [e for e in trace if e.instance == event.instance and e.seq <= event.seq]
    return same[-_SLICE:]


def _metric_events(result: SimulationResult, name: str) -> list[TraceEvent]:
    """The events a metric counts (first replication that has a trace), capped."""
    if result.runs and result.runs[0].trace is None:
        return []
    metric = next(m for m in result.spec.metrics if m.name == name)
    selectors = [s for s in (metric.select, metric.start, metric.end) if s is not None]
    if not selectors:
        parts = [p for p in (metric.numerator, metric.denominator) if p]
        return [e for p in parts for e in _metric_events(result, p)][:_SLICE]
    trace = result.traces[0]
    picked = [e for e in trace if any(
        e.kind == s.event and (s.process is None or s.process == e.process)
        and (s.activity is None or s.activity == e.activity) for s in selectors)]
    if not picked:
        return list(trace[-_SLICE:])
    return picked[:_SLICE]


def expect(result: SimulationResult, *lines: str) -> None:
    """Assert ``then`` lines on a result from Python (``AssertionError`` with every failure
    message), e.g. ``expect(result, "rate doses_taken/doses_due >= 0.99 with 95% confidence")``.
    A line naming something the spec lacks raises :class:`ConfigurationError` listing the
    names it has."""
    __tracebackhide__ = True     # pytest: the failure is the test's line, not ours
    failures = []
    for line in lines:
        expectation = parse_expectation(line, where="expect()")
        expectation.check_names(result.names, "expect()")
        message = expectation.check(result)
        if message is not None:
            failures.append(message)
    if failures:
        failures.append(f"(seed {result.seed}, {result.replications} replication(s))")
        raise AssertionError("\n\n".join(failures))
