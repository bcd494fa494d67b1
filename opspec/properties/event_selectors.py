"""Selecting events by their kind and fields, as predicates: the completions or starts of an
activity, the raises of a trigger, the starts of a process's instances, any event of a kind
with given data (``activity_completed("dispense")``, ``event("activity.omitted",
reason="busy")``). Each gives a :class:`~opspec.properties.simple_predicates.Match`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from opspec.engine.trace import EventKind, TraceEvent
from opspec.properties import language
from opspec.properties.simple_predicates import Match
from opspec.properties.term_arguments import text

__all__ = ["activity_completed", "activity_started", "event", "process_started", "trigger_raised"]


def _selector(kind: str, what: str, name: str, process: str | None,
              test: Callable[[TraceEvent], bool]) -> Match:
    # a number would be taken and never match: say so (activity_completed(3))
    text(f"{what}_{kind.split('.')[1]}()", name, f"the {what} is named by text")
    if process is not None:
        text(f"{what}_{kind.split('.')[1]}()", process, "process= is named by text")
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
    text("event()", kind, "the kind is text ('activity.omitted')")
    for field, value in (("activity", activity), ("process", process)):
        if value is not None:
            text("event()", value, f"{field}= is named by text")
    def test(e: TraceEvent) -> bool:
        return (e.kind == kind and (activity is None or e.activity == activity)
                and (process is None or e.process == process)
                and all(e.data.get(k) == v for k, v in data.items()))

    parts = [kind, *(x for x in (activity, process and f"in {process}") if x),
             *(f"{k}={v!r}" for k, v in data.items())]
    subject = language.Subject(activity, "activity") if activity else None
    return Match(test, " ".join(parts), subject, process)
