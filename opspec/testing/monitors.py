"""Monitors in tests: safety properties checked during every simulated run.

::

    from opspec.testing.monitors import assert_no_violations, min_gap

    result = simulate(spec, users=200, user_model="older-adults",
                      monitors=[min_gap("dispense", hours=3.75), "max_count dispense 4 per 24h"])
    assert_no_violations(result)             # AssertionError with each violation's events
    print(result.monitor_report())           # violations per user-day, exact 95 % interval

A spec declares its own monitors as a package ``ExtendedAttribute``; :func:`simulate` checks
them in every run as well::

    <ExtendedAttribute Name="opspec:Monitor" Value="min_gap dispense 4h"/>

A monitor is a property of the one property language (:mod:`opspec.properties.language`, usable
by any layer), built with the one Python vocabulary (:mod:`opspec.properties.vocabulary`:
``min_gap``, ``never``, ``within``, ``count``..., re-exported here and by
:mod:`opspec.testing`): the same object is a trace predicate (``check(result,
min_gap("dispense", hours=4))``) and its text a scenario ``then`` line, judged on stored traces
by the same evaluator. This module adds the report (``never_happens`` and
``bounded_response`` remain as deprecated spellings of ``never`` and ``within``).
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from opspec.errors import ConfigurationError, OpspecError
from opspec.properties.language import MonitorResult, Names, Property, Violation, clock
from opspec.properties.monitors import Monitor, declared_monitors, parse_monitor
from opspec.properties.vocabulary import (
    Predicate,
    max_count_per,
    min_gap,
    monitor,
    never,
    never_while,
    within,
)
from opspec.statistics import poisson_interval
from opspec.statistics.claims import confidence_text

__all__ = [
    "Monitor",
    "MonitorReport",
    "MonitorRow",
    "Violation",
    "assert_no_violations",
    "bounded_response",
    "max_count_per",
    "min_gap",
    "monitor",
    "monitor_report",
    "monitors_for",
    "never_happens",
    "never_while",
]


def never_happens(subject: str) -> Predicate:
    """Deprecated spelling of :func:`~opspec.properties.vocabulary.never` (the same property,
    ``never A``)."""
    warnings.warn("never_happens() is deprecated: use never()", DeprecationWarning,
                  stacklevel=2)
    return never(subject)


def bounded_response(trigger: str, response: str, seconds: float) -> Predicate:
    """Deprecated spelling of :func:`~opspec.properties.vocabulary.within` (the same property,
    ``bounded_response A B D``)."""
    warnings.warn("bounded_response() is deprecated: use within()", DeprecationWarning,
                  stacklevel=2)
    return within(trigger, response, seconds)


def monitors_for(compiled: Any, names: Names,
                 extra: Iterable[Predicate | Property | str] | None) -> list[Monitor]:
    """The spec's declared monitors plus ``extra`` (the vocabulary's objects, properties or
    their text), bound to its names (:class:`ConfigurationError` listing the names when one
    is unknown)."""
    out = declared_monitors(compiled)
    for item in extra or ():
        m = (parse_monitor(item) if isinstance(item, str)
             else item.monitor() if isinstance(item, Predicate) else item)
        if not isinstance(m, Property):
            raise ConfigurationError(f"{item!r} is not a monitor",
                                     hint="pass monitor objects (min_gap(...), ...) or their "
                                          "text form ('min_gap dispense 4h')")
        try:
            out.append(m.bind(names))
        except ConfigurationError as error:
            raise ConfigurationError(f"monitor {m.text!r}: {error.message}",
                                     location=error.location, hint=error.hint) from None
    return out


# ---------------------------------------------------------------- the report
@dataclass(frozen=True, slots=True)
class MonitorRow:
    """One monitor over every replication: violations, the users affected and the hazard
    (violations per user-day) with its exact Poisson interval."""

    monitor: str
    violations: int
    replications_affected: int
    replications: int
    user_days: float
    hazard: float
    hazard_lo: float
    hazard_hi: float
    first: tuple[Violation, ...]

    def __str__(self) -> str:
        return (f"{self.monitor}: {self.violations} violation(s) in "
                f"{self.replications_affected}/{self.replications} replication(s); "
                f"{self.hazard:.4g} per user-day [{self.hazard_lo:.4g}, {self.hazard_hi:.4g}]")


@dataclass(frozen=True, slots=True)
class MonitorReport:
    """Every monitor of a result (``result.monitor_report()``); ``ok`` when none fired."""

    rows: tuple[MonitorRow, ...]
    confidence: float

    @property
    def ok(self) -> bool:
        return all(row.violations == 0 for row in self.rows)

    def row(self, monitor: str) -> MonitorRow:
        """The row of ``monitor``: its text as the result has it, or the same property
        spelt otherwise (``min_gap dispense 3h45m`` for ``min_gap dispense 3.75h``)."""
        for r in self.rows:
            if r.monitor == monitor:
                return r
        wanted = _canonical(monitor)
        for r in self.rows:
            if wanted is not None and _canonical(r.monitor) == wanted:
                return r
        raise ConfigurationError(f"no monitor {monitor!r} in this result",
                                 hint="its monitors are: "
                                      + (", ".join(r.monitor for r in self.rows) or "(none)"))

    def __str__(self) -> str:
        if not self.rows:
            return "no monitors"
        head = f"monitors (hazard: violations per user-day, exact {confidence_text(self.confidence)} interval)"
        return "\n".join([head, *(f"  {row}" for row in self.rows)])

    def describe(self, limit: int = 3) -> str:
        """The report plus the first ``limit`` violations of each monitor, with events."""
        from opspec.testing.expectations import format_events

        lines = [str(self)]
        for row in self.rows:
            for v in row.first[:limit]:
                where = f" (replication {v.replication})" if row.replications > 1 else ""
                lines.append(f"  {row.monitor}: {clock(v.time)}{where}: {v.message}")
                lines.extend(format_events(v.events))
            if row.violations > limit:
                lines.append(f"  ... {row.violations - min(limit, len(row.first))} more "
                             f"violation(s) of {row.monitor}")
        return "\n".join(lines)


def _canonical(text: str) -> str | None:
    """The property ``text`` reads as, in one spelling (None when it reads as none)."""
    try:
        return parse_monitor(text).describe()
    except OpspecError:
        return None


def monitor_report(result: Any, confidence: float = 0.95) -> MonitorReport:
    """The monitor report of a :class:`~opspec.testing.simulation.SimulationResult`."""
    outcomes: Sequence[MonitorResult] = result.monitor_results
    replications = result.replications
    days = (result.horizon or 0.0) / 86_400.0
    exposure = max(replications * days, 1e-12)
    order: dict[str, list[MonitorResult]] = {}
    for outcome in outcomes:
        order.setdefault(outcome.monitor, []).append(outcome)
    rows = []
    for name, parts in order.items():
        total = sum(p.count for p in parts)
        rate, lo, hi = poisson_interval(total, exposure, confidence)
        first = tuple(v for p in parts for v in p.violations)[:20]
        rows.append(MonitorRow(name, total, sum(1 for p in parts if p.count), replications,
                               replications * days, rate, lo, hi, first))
    return MonitorReport(tuple(rows), confidence)


def assert_no_violations(result: Any, *monitors: str, limit: int = 3) -> None:
    """``AssertionError`` when a monitor (any, or those named by their text) fired in any
    replication, showing the report and the first violations with their events."""
    __tracebackhide__ = True
    from opspec.testing.simulation import require_result

    require_result(result, "assert_no_violations", "monitor_results")
    report = monitor_report(result)
    rows = report.rows if not monitors else tuple(report.row(m) for m in monitors)
    if not rows:
        raise ConfigurationError("this result has no monitors",
                                 hint="pass simulate(..., monitors=[...]) or declare "
                                      "opspec:Monitor in the spec")
    bad = MonitorReport(tuple(r for r in rows if r.violations), report.confidence)
    if bad.rows:
        raise AssertionError("monitor violations:\n" + bad.describe(limit)
                             + f"\n(seed {result.seed}, {result.replications} replication(s))")
