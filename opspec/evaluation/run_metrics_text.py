"""One run's metrics as text, one line each: the ``metrics`` block of ``opspec run`` (and what
the walkthrough's summary should print, word for word: :mod:`opspec.tui.summary`).

Counts as they are, durations as mean, median, p95 and n. A ratio of two counts reads as
``opspec evaluate``'s table reads it (:mod:`.tables`, hence here and not in the commands: the
walkthrough, a layer below them, can use it too): the counts it divides follow its value,
``(13 of 12)``, as in that table's pooled column; and a ratio the spec declares a proportion
(``Proportion="true"``: ``taken_rate``, doses taken of doses due) is in percent, by the table's
own formatter (:func:`.tables.fmt`), ``100.00 % (12 of 12)`` — unless this run's counts make
the declaration false, which its line then says. Other ratios (of durations, of other
ratios) are their bare value. ``opspec run --json`` does not use this (its metrics are shaped
as ``opspec evaluate --json``'s).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from opspec.clock import figure
from opspec.model import MetricDefinition, MetricKind

__all__ = ["metric_lines"]


def metric_lines(metrics: Mapping[str, Mapping[str, Any]], medians: Mapping[str, float],
                 definitions: Iterable[MetricDefinition] = ()) -> list[str]:
    """The spec's metrics, one line each (none without metrics): ``metrics`` as a run gives
    them (:meth:`opspec.engine.metrics.MetricsListener.values`), ``medians`` of the
    durations, ``definitions`` the spec's (a ratio's numerator and denominator; without them
    every ratio is its bare value)."""
    if not metrics:
        return []
    ratios = {d.name: d for d in definitions if d.kind is MetricKind.RATIO}
    width = max(len(name) for name in metrics)
    lines = []
    for name, value in metrics.items():
        kind = value.get("kind")
        if kind == "count":
            text = f"{value.get('total', 0)}"
        elif kind == "duration":
            n = value.get("n", 0)
            text = (f"n {n}" if not n else
                    f"mean {figure(value.get('mean'), ' s')}, median "
                    f"{figure(medians.get(name), ' s')}, p95 {figure(value.get('p95'), ' s')}, "
                    f"n {n}")
        else:
            text = _ratio(ratios.get(name), value, _counts(ratios.get(name), metrics))
        lines.append(f"  {name:<{width}}  {text}")
    return lines


def _counts(definition: MetricDefinition | None, metrics: Mapping[str, Mapping[str, Any]]
            ) -> tuple[int, int] | None:
    """The totals a ratio divides when both are counts (None otherwise)."""
    if definition is None:
        return None
    numerator = metrics.get(definition.numerator or "")
    denominator = metrics.get(definition.denominator or "")
    if (numerator is None or denominator is None or numerator.get("kind") != "count"
            or denominator.get("kind") != "count"):
        return None
    return int(numerator.get("total", 0)), int(denominator.get("total", 0))


def _ratio(definition: MetricDefinition | None, value: Mapping[str, Any],
           counts: tuple[int, int] | None) -> str:
    if definition is None or counts is None:   # of durations, of other ratios: the value
        return figure(value.get("value"))
    part, whole = counts
    # "k of 0", not "no doses_due": every ratio of counts ends in the same "(k of n)", as
    # evaluate's pooled column, so the 0 that leaves no value stands where the eye looks for
    # the denominator, and the line stays true when the numerator is not 0
    if whole == 0:
        return f"{figure(None)} ({part} of 0)"
    from opspec.evaluation.tables import fmt

    # in percent when the spec declares it a proportion (Proportion="true"), as evaluate
    # gives it an interval of a proportion; never from its name or these numbers:
    # alarms_per_dose is 4 of 4 in some runs, and is no proportion
    if not definition.proportion:
        return f"{figure(value.get('value'))} ({part} of {whole})"
    if part > whole:
        # the declaration is false in this run: said where the number is (evaluate refuses
        # the proportion's interval for it, docs/evaluation.md)
        return (f"{figure(value.get('value'))} ({part} of {whole}: more "
                f"{definition.numerator} than {definition.denominator}, though the spec "
                "declares it a proportion)")
    return f"{fmt(value.get('value'), percent=True)} ({part} of {whole})"
