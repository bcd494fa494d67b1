"""Declared metrics computed incrementally from the trace, as a trace listener.

- COUNT: the number of events matching ``select``: ``{"kind": "count", "total": N}``.
- DURATION: per process instance, seconds from the ``first`` (or ``last``) event matching
  ``start`` to the next event matching ``end`` of the same instance; one sample per pair:
  ``{"kind": "duration", "n", "mean", "p95", "min", "max"}`` (``None`` values when n = 0).
- RATIO: numerator metric / denominator metric (their totals or means):
  ``{"kind": "ratio", "value": x}`` (``None`` when the denominator is 0).

The output shape is shared with ``opspec evaluate --json``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Any, Final

from opspec.engine.trace import TraceEvent, TraceListener
from opspec.model import EventSelector, MetricDefinition, MetricKind
from opspec.statistics.percentiles import linear

if TYPE_CHECKING:
    from opspec.engine.compiled import CompiledPackage

__all__ = ["MetricsListener", "flag_key", "listener_tables", "metrics_only", "own_metrics",
           "percentile", "summarise_durations"]

# What a selector is to its metric (Final: mypyc inlines them).
COUNT: Final = 0
START: Final = 1
END: Final = 2


def percentile(values: list[float], q: float) -> float:
    """Linear-interpolation percentile (numpy's default), ``q`` in 0..100."""
    return linear(sorted(values), q / 100.0)


def summarise_durations(samples: list[float]) -> dict[str, Any]:
    if not samples:
        return {"kind": "duration", "n": 0, "mean": None, "p95": None, "min": None,
                "max": None}
    return {"kind": "duration", "n": len(samples), "mean": sum(samples) / len(samples),
            "p95": percentile(samples, 95.0), "min": min(samples), "max": max(samples)}


class MetricsListener:
    """Computes ``definitions`` from the events it receives.

    ``selects`` tells the simulation which events it needs, so events nobody needs are
    never built.
    """

    def __init__(self, definitions: Iterable[MetricDefinition]) -> None:
        self.definitions = tuple(definitions)
        self.counts: dict[str, int] = {}
        self.samples: dict[str, list[float]] = {}
        self.opened: dict[str, dict[int, float]] = {}
        # When ``keep_times`` is set (evaluation runs), the simulated time of every counted
        # event and of the end of every duration sample is kept too, for outcomes over days
        # and time of day; plain runs don't pay for it.
        self.keep_times = False
        self.count_times: dict[str, list[float]] = {}
        self.sample_times: dict[str, list[float]] = {}
        # kind -> (metric name, role, process, activity, keep the last start): plain values,
        # not the model's selector objects, because ``raw`` runs for every matching event.
        self._by_kind: dict[str, list[tuple[str, int, str | None, str | None, bool]]] = {}
        # kind -> process -> activity -> the (metric name, role, keep the last start) of
        # the selectors it matches, in their order: found once per distinct event
        # (:meth:`chosen`), so ``raw`` does not test every selector of the kind at every
        # event; nested, so that an event looks its entry up without a key tuple made and
        # hashed for it
        self.matching: dict[str, dict[str | None, dict[
            str | None, tuple[tuple[str, int, bool], ...]]]] = {}
        selects: set[tuple[str, str | None, str | None]] = set()
        for metric in self.definitions:
            if metric.kind is MetricKind.COUNT and metric.select is not None:
                self.counts[metric.name] = 0
                self._add(metric, metric.select, COUNT, selects)
            elif metric.kind is MetricKind.DURATION and metric.start and metric.end:
                self.samples[metric.name] = []
                self.opened[metric.name] = {}
                self._add(metric, metric.start, START, selects)
                self._add(metric, metric.end, END, selects)
        self.selects = frozenset(selects)

    def _add(self, metric: MetricDefinition, selector: EventSelector, role: int,
             selects: set[tuple[str, str | None, str | None]]) -> None:
        self._by_kind.setdefault(selector.event, []).append(
            (metric.name, role, selector.process, selector.activity, selector.which == "last"))
        selects.add((selector.event, selector.process, selector.activity))

    def __call__(self, event: TraceEvent) -> None:
        self.raw(event.time, event.kind, event.process, event.instance, event.activity,
                 event.data)

    def raw(self, time: float, kind: str, process: str | None, instance: int | None,
            activity: str | None, data: Mapping[str, Any] | None = None) -> None:
        """The same as calling with a TraceEvent, without building one (the engine uses
        this when no other listener needs the event object). ``RunState.emit`` takes these
        steps in line for a run's own metrics (a plain MetricsListener, its one raw
        listener): a change here is a change there."""
        try:
            chosen = self.matching[kind][process][activity]
        except KeyError:
            chosen = self.chosen(kind, process, activity)
        for name, role, last in chosen:
            if role == COUNT:
                self.counts[name] += 1
                if self.keep_times:
                    self.count_times.setdefault(name, []).append(time)
                continue
            which = instance or 0
            pending = self.opened[name]
            if role == START:
                if last or which not in pending:
                    pending[which] = time
            elif which in pending:
                started = pending[which]
                del pending[which]
                self.samples[name].append(time - started)
                if self.keep_times:
                    self.sample_times.setdefault(name, []).append(time)

    def chosen(self, kind: str, process: str | None, activity: str | None
               ) -> tuple[tuple[str, int, bool], ...]:
        """:meth:`match`, kept in ``matching`` (an event's first time)."""
        found = self.match(kind, process, activity)
        self.matching.setdefault(kind, {}).setdefault(process, {})[activity] = found
        return found

    def match(self, kind: str, process: str | None, activity: str | None
               ) -> tuple[tuple[str, int, bool], ...]:
        """The selectors of ``kind`` an event of ``process`` / ``activity`` matches."""
        return tuple((name, role, last)
                     for name, role, want_process, want_activity, last
                     in self._by_kind.get(kind, ())
                     if (want_process is None or want_process == process)
                     and (want_activity is None or want_activity == activity))

    def values(self) -> dict[str, dict[str, Any]]:
        """Every declared metric in the shared output shape."""
        out: dict[str, dict[str, Any]] = {}
        for metric in self.definitions:
            if metric.kind is MetricKind.COUNT:
                out[metric.name] = {"kind": "count", "total": self.counts.get(metric.name, 0)}
            elif metric.kind is MetricKind.DURATION:
                out[metric.name] = summarise_durations(self.samples.get(metric.name, []))
        for metric in self.definitions:
            if metric.kind is MetricKind.RATIO:
                num = _scalar(out.get(metric.numerator or ""))
                den = _scalar(out.get(metric.denominator or ""))
                value = num / den if num is not None and den else None
                out[metric.name] = {"kind": "ratio", "value": value}
        return out


def _scalar(value: dict[str, Any] | None) -> float | None:
    if value is None:
        return None
    if value["kind"] == "count":
        return float(value["total"])
    result = value["mean"] if value["kind"] == "duration" else value.get("value")
    return None if result is None else float(result)


# Who hears which trace events of a run: the tables RunState makes once per run from its
# listeners (here, compiled beside the metrics listener they single out; none of this runs
# per event).

_FLAG_KEYS: dict[tuple[bool, frozenset[Any]], object] = {}


def flag_key(wants_all: bool, wanted: frozenset[Any]) -> object:
    """One object per distinct listener selection: runs that select the same events share
    the bits cached on a compiled package's activities (households run one after another
    on one package)."""
    key = (wants_all, wanted)
    found = _FLAG_KEYS.get(key)
    if found is None:
        if len(_FLAG_KEYS) > 1000:           # a long-lived process with many selections
            _FLAG_KEYS.clear()
        found = _FLAG_KEYS[key] = object()
    return found


def metrics_only(raw: list[Callable[..., None]]) -> list[MetricsListener] | None:
    """The raw listeners when they are all metrics listeners' (a run's own, as a rule): the
    compiled engine then calls them as native methods, not through Python's protocol."""
    metrics = [getattr(listener, "__self__", None) for listener in raw]
    chosen = [m for m in metrics if isinstance(m, MetricsListener)]
    if len(chosen) != len(raw) or any(m.raw != r for m, r in zip(chosen, raw)):
        return None
    return chosen


def own_metrics(raw_metrics: list[MetricsListener] | None) -> MetricsListener | None:
    """The one raw listener when it is a run's own metrics (a plain MetricsListener, whose
    steps ``RunState.emit`` takes in line), else None."""
    if raw_metrics is not None and len(raw_metrics) == 1:
        only = raw_metrics[0]
        if type(only) is MetricsListener:
            return only
    return None


_Selector = tuple[str, str | None, str | None]      # (kind, process, activity)


def listener_tables(listeners: list[TraceListener], compiled: CompiledPackage) -> tuple[
        list[TraceListener], list[Callable[..., None]], bool,
        frozenset[_Selector], frozenset[_Selector],
        list[tuple[TraceListener, frozenset[_Selector] | None]]]:
    """Who hears what: the full listeners (a ``raw`` method gets the fields without a
    TraceEvent object), whether any wants everything, and the (kind, process, activity)
    selectors the others asked for, expanded over the compiled package."""
    full_listeners = [lst for lst in listeners if getattr(lst, "raw", None) is None]
    raw = [lst.raw for lst in listeners  # type: ignore[attr-defined]
           if getattr(lst, "raw", None) is not None]
    wants_all = False
    selectors: set[_Selector] = set()
    for listener in listeners:
        wanted = getattr(listener, "selects", None)
        if wanted is None:
            wants_all = True
            break
        selectors.update(wanted)
    chosen = frozenset(selectors)
    expanded = (frozenset() if wants_all or not selectors
                else compiled.expand_selectors(chosen))
    # each full listener only receives what it selects (None: everything)
    full = [(lst, None if getattr(lst, "selects", None) is None
             else compiled.expand_selectors(frozenset(lst.selects)))  # type: ignore[attr-defined]
            for lst in full_listeners]
    return full_listeners, raw, wants_all, chosen, expanded, full
