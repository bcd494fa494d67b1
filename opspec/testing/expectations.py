"""The ``then`` lines of scenario files: readable expectations over a simulation result.

Each line is one of (keywords in any case; ``OP`` is ``==``, ``!=``, ``<``, ``<=``, ``>``,
``>=``; times are durations such as ``300s``, ``5 min``, ``4h``)::

    doses_taken == 1                          a metric (count total, duration mean, ratio)
    report_latency_s.p95 <= 600               a metric field (n, mean, p95, min, max, ...)
    alarms_per_dose in [1, 1.5]               a closed interval
    never activity notify_caregiver           no completion of it in any replication
    eventually activity record_taken          a completion in every replication
    count activity sound_alarm == 3           completions, in every replication
    activity press_report before activity dispense     no dispense before the first report
    activity dispense within 300s after activity sound_alarm
    never activity dispense twice within 4h   no two completions closer than that
    rate doses_taken/doses_due >= 0.95 with 95% confidence
    mean alarms_per_dose in [1.1, 1.25] with 95% confidence
    p95 report_latency_s <= 600 with 95% confidence

The trace lines are the property language of monitors (:mod:`opspec.properties.language`):
any monitor's text is a ``then`` line too (``min_gap dispense 4h``, ``bounded_response
sound_alarm dispense 15min``, ``never_while ...``), judged on each replication's trace by the
evaluator a monitor runs online (same verdict, same witness), and holding when it holds in
every replication (``count`` too: a total over all replications is a count metric's line,
``alarms == 12``). ``activity X`` may also be ``trigger X`` (a message or signal raised),
``process X`` (an instance started) or a bare name. Metric comparisons use the metrics pooled over all
replications; ``==`` and ``!=`` allow an error of 1e-9, relative, or absolute near 0. The statistical lines are decided by
:mod:`opspec.statistics.claims`: they pass when the one-sided bound at that confidence is on
the right side, fail when the claim is refuted at that confidence, and otherwise fail saying
how many replications would decide it.
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from opspec.engine.trace import TraceEvent
from opspec.errors import ConfigurationError, SourceLocation
from opspec.properties.language import (
    BoundedResponse,
    CountBound,
    Eventually,
    MaxCount,
    MinGap,
    Never,
    NeverWhile,
    Precedence,
    Property,
    Subject,
    trace_end,
)
from opspec.properties.text_form import looks_like_property, read_property
from opspec.testing.simulation import FIELDS, SimulationResult, SpecNames, require_result

__all__ = ["Expectation", "expect", "format_events", "parse_expectation"]

_OPS: dict[str, Callable[[float, float], bool]] = {
    "==": lambda a, b: math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-9),
    "!=": lambda a, b: not math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-9),
    "<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge,
}
_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_OP = r"==|!=|<=|>=|<|>"
_TARGET = rf"(?:(?P<op>{_OP})\s*(?P<num>{_NUM})|in\s*\[\s*(?P<lo>{_NUM})\s*,\s*(?P<hi>{_NUM})\s*\])"
_CONF = r"\s+with\s+(?P<conf>\d+(?:\.\d+)?)\s*%\s+confidence"
_STATISTICAL: list[tuple[str, re.Pattern[str]]] = [
    ("rate", re.compile(rf"rate\s+(?P<num_m>\w+)\s*/\s*(?P<den_m>\w+)\s*{_TARGET}{_CONF}", re.IGNORECASE)),
    ("mean", re.compile(rf"mean\s+(?P<metric>[\w.]+)\s*{_TARGET}{_CONF}", re.IGNORECASE)),
    ("quantile", re.compile(rf"p(?P<q>\d+(?:\.\d+)?)\s+(?P<metric>\w+)\s*{_TARGET}{_CONF}",
                            re.IGNORECASE)),
]
_METRIC = re.compile(rf"(?P<metric>[\w]+(?:\.\w+)?)\s*{_TARGET}", re.IGNORECASE)
#: the name of each trace line's form (``Expectation.form``)
_PROPERTY_FORMS: dict[type[Property], str] = {
    Never: "never", Eventually: "eventually", CountBound: "count", Precedence: "before",
    BoundedResponse: "within", MinGap: "twice", MaxCount: "max_count",
    NeverWhile: "never_while"}
_HINT = "see the list of expectation forms in docs/spec-testing.md"
_SLICE = 12


@dataclass(frozen=True, slots=True)
class Expectation:
    """One parsed ``then`` line; :meth:`check` returns ``None`` or a failure message.
    ``property`` is the trace property of a trace line (``None`` for metric and statistical
    lines); ``groups`` holds the parts of the text (``gap``: a trace line's duration)."""

    text: str
    form: str
    groups: dict[str, str]
    property: Property | None = None

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
        """(what, name) pairs this expectation refers to: metrics, activities, ...; ``what``
        is ``"name"`` for a bare name (an activity, trigger or process)."""
        g = self.groups
        out = []
        for key in ("metric", "num_m", "den_m"):
            if g.get(key):
                out.append(("metric", g[key].split(".")[0]))
        for selector in self.property.subjects() if self.property is not None else ():
            if isinstance(selector, Subject):
                for one in (selector, *selector.alternatives):
                    out.append((one.what or "name", one.name))
        return out

    def check_names(self, names: SpecNames, where: str) -> None:
        """Raise :class:`ConfigurationError` naming what the spec has instead."""
        table = {"metric": names.metrics, "activity": names.activities,
                 "trigger": names.triggers, "process": names.processes}
        for what, name in self.names():
            if what == "name":
                if not any(name in known for known in (names.activities, names.triggers,
                                                       names.processes)):
                    raise ConfigurationError(
                        f"{self.text!r} names {name!r}, which the spec does not have as an "
                        "activity, trigger or process", location=_loc(where),
                        hint="its activities are: " + ", ".join(names.activities)
                             + "; triggers: " + (", ".join(names.triggers) or "(none)")
                             + "; processes: " + ", ".join(names.processes))
                continue
            if name not in table[what]:
                known = ", ".join(table[what]) or "(none)"
                raise ConfigurationError(
                    f"{self.text!r} names {what} {name!r}, which the spec does not have",
                    location=_loc(where), hint=f"the spec's {what} names are: {known}")

    # ------------------------------------------------------------ checking
    def check(self, result: SimulationResult) -> str | None:
        if self.property is not None:
            return self._check_property(result)
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

    def _check_property(self, result: SimulationResult) -> str | None:
        """Each replication's trace fed to the property's evaluator (the monitor's): the
        first replication with a violation fails, showing its first violation's witness."""
        from opspec.testing.predicates import failure_slice

        assert self.property is not None
        prop = self.property.bind(result.names)
        for rep, trace in enumerate(result.traces):
            end = result.horizon if result.horizon is not None else trace_end(trace)
            verdict = prop.judge(trace, end, replication=rep)
            if not verdict.count:
                continue
            first = verdict.violations[0]
            more = f" (the first of {verdict.count} violations)" if verdict.count > 1 else ""
            lines = [f"expected {self.text}", f"  but {first.message}{more}"
                     + _in_rep(result, rep)]
            return "\n".join([*lines, *failure_slice(trace, first.events)])
        return None

    def _check_rate(self, result: SimulationResult) -> str | None:
        from opspec.statistics.claims import decide_rate

        num, den = self.groups["num_m"], self.groups["den_m"]
        successes, trials = result.value(num), result.value(den)
        op, a, b = self._target()
        return decide_rate(self.text, int(successes or 0), int(trials or 0), op, a, b,
                           float(self.groups["conf"]) / 100.0, units=f"{den}",
                           replications=result.replications)

    def _check_mean(self, result: SimulationResult) -> str | None:
        from opspec.statistics.claims import decide_mean

        op, a, b = self._target()
        return decide_mean(self.text, result.samples(self.groups["metric"]), op, a, b,
                           float(self.groups["conf"]) / 100.0)

    def caveat(self, result: SimulationResult) -> str | None:
        """What a reader must know of this expectation's pass on ``result``: a mean over
        replications that were all alike (:func:`~opspec.statistics.claims.alike_caveat`);
        None for any other."""
        if self.property is not None or self.form != "mean":
            return None
        from opspec.statistics.claims import alike_caveat

        return alike_caveat(self.text, result.samples(self.groups["metric"]),
                            float(self.groups["conf"]) / 100.0)

    def _check_quantile(self, result: SimulationResult) -> str | None:
        from opspec.statistics.claims import decide_quantile

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
    for form, pattern in _STATISTICAL:
        match = pattern.fullmatch(cleaned)
        if match is not None:
            return _checked(text, form, match, where)
    metric = _METRIC.fullmatch(cleaned)
    if looks_like_property(cleaned):
        try:
            prop, gap = read_property(cleaned, what="expectation", location=_loc(where))
        except ConfigurationError:
            if metric is None:      # a metric named like a keyword ('count == 3') is one
                raise
        else:
            groups = {"gap": gap} if gap is not None else {}
            return Expectation(cleaned, _PROPERTY_FORMS[type(prop)], groups, prop)
    if metric is not None:
        return _checked(text, "metric", metric, where)
    raise ConfigurationError(f"cannot read the expectation {text!r}", location=_loc(where),
                             hint=_HINT)


def _checked(text: str, form: str, match: re.Match[str], where: str) -> Expectation:
    cleaned = " ".join(text.split())
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
    if "lo" in groups and float(groups["lo"]) > float(groups["hi"]):
        raise ConfigurationError(f"{text!r}: the interval is empty", location=_loc(where))
    return Expectation(cleaned, form, groups)


# ---------------------------------------------------------------- formatting
def _loc(where: str) -> SourceLocation:
    path, _, key = where.partition(": ")
    return SourceLocation(path, key=key or None)


def _duration(text: str) -> float:
    from opspec.clock import parse_duration

    return parse_duration(text, error=ConfigurationError)


def _fmt(value: float | None) -> str:
    return "undefined (no samples)" if value is None else f"{value:g}"


def _metric_line(values: dict[str, object]) -> str:
    return ", ".join(f"{k}={_fmt(v) if isinstance(v, (int, float)) or v is None else v}"
                     for k, v in values.items() if k != "kind")


def _in_rep(result: SimulationResult, rep: int) -> str:
    return f" (replication {rep})" if result.replications > 1 else ""


def format_events(events: Sequence[TraceEvent]) -> list[str]:
    """One short line per event (:func:`opspec.engine.trace_text.listing_line`)."""
    from opspec.engine.trace_text import listing_line

    return [listing_line(e) for e in events]


def _with_slice(lines: list[str], result: SimulationResult, events: Sequence[TraceEvent],
                title: str = "") -> str:
    if events:
        title = title or f"trace ({len(events)} relevant event(s))"
        lines = [*lines, f"  {title}:", *format_events(events)]
    return "\n".join(lines)


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
    names it has. A mean line that holds on replications all alike warns
    (:class:`~opspec.testing.assertions.AllAlikeWarning`, as ``assert_mean``)."""
    __tracebackhide__ = True     # pytest: the failure is the test's line, not ours
    require_result(result, "expect", "names")
    failures = []
    for line in lines:
        expectation = parse_expectation(line, where="expect()")
        expectation.check_names(result.names, "expect()")
        message = expectation.check(result)
        if message is not None:
            failures.append(message)
            continue
        caveat = expectation.caveat(result)
        if caveat is not None:
            import warnings

            from opspec.testing.assertions import AllAlikeWarning

            warnings.warn(caveat, AllAlikeWarning, stacklevel=2)
    if failures:
        failures.append(f"(seed {result.seed}, {result.replications} replication(s))")
        raise AssertionError("\n\n".join(failures))
