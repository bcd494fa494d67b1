"""Who hears which trace events of a run: the tables :class:`~opspec.engine.runstate.RunState`
makes once per run from its listeners (moved out of ``runstate``, which keeps the run's
time-critical steps; none of this runs per event)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from opspec.engine.compiled import CompiledPackage
from opspec.engine.metrics import MetricsListener
from opspec.engine.trace import TraceListener

__all__ = ["flag_key", "listener_tables", "metrics_only", "own_metrics"]

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
