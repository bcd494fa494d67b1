"""A trace event as a line of text for people: the one place that writes one.

Two layouts of the same words: :func:`timeline_line` (``opspec run``'s timeline: time, lane,
process#instance, what happened) and :func:`listing_line` (the events a failed spec test or a
violated monitor lists: time, instance, process, kind, activity). :func:`what_happened` is the
phrase both use for an event (``press_report completed (chose report)``, ``trigger trg_2
raised by sound_alarm``, ``deadline of wait_report expired``). A trace written for programs is
JSON Lines (:mod:`opspec.engine.trace_sinks`), not this.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from opspec.clock import clock_time
from opspec.engine.lane_labels import PLAIN

if TYPE_CHECKING:
    from opspec.engine.lane_labels import LaneLabels
    from opspec.engine.trace import TraceEvent

__all__ = ["listing_line", "timeline_line", "what_happened"]

#: the data keys a line shows (the first one the event has)
_DETAILS = ("reason", "message", "latency", "exception")


def what_happened(event: TraceEvent) -> str:
    """What ``event`` says, in words, with its first telling detail."""
    data = event.data or {}
    kind = event.kind
    what: str
    if kind == "trigger.raised":
        what = f"trigger {data.get('name', '?')} raised" + (
            f" by {event.activity}" if event.activity else "")
    elif kind.startswith("activity."):
        verb = kind.split(".", 1)[1]
        what = f"{event.activity} {verb}"
        if data.get("choice"):
            what += f" (chose {data['choice']})"
    elif kind.startswith("process."):
        what = f"{event.process} {kind.split('.', 1)[1]}"
    elif kind == "deadline.expired":
        what = f"deadline of {event.activity or event.process} expired"
    elif kind == "exception.raised":
        what = f"exception {data.get('exception', '?')} at {event.activity}"
    elif kind == "mode.changed":
        what = f"mode {data.get('from')} -> {data.get('to')}" + (
            f" by {event.activity}" if event.activity else "")
    else:
        what = kind + (f" {event.activity}" if event.activity else "")
    details = _DETAILS[:3] if kind == "exception.raised" else _DETAILS
    for key in details:
        if key in data:
            value = data[key]
            if isinstance(value, float):
                value = f"{value:g}"
            what += f"  [{key}: {value}]"
            break
    return what


def timeline_line(event: TraceEvent, lanes: LaneLabels = PLAIN) -> str:
    """One readable line: time, lane, process#instance, what happened, key details. ``lanes``
    (:func:`opspec.engine.lane_labels.lane_labels` of the spec) names the lanes as the spec
    does and sizes the columns so that they line up with and without lanes."""
    return (f"{clock_time(event.time):>16}  {lanes.label(event):<{lanes.width}} "
            f"{lanes.where(event)} {what_happened(event)}")


def listing_line(event: TraceEvent) -> str:
    """One short line of a listing: time, instance, process, kind, activity, key data (the
    kinds as the trace names them: a spec test's reader matches them to its predicates)."""
    data = event.data or {}
    what = event.activity or ""
    if event.kind == "trigger.raised":
        what = f"{data.get('name', '?')}" + (f" (by {event.activity})" if event.activity
                                             else "")
    detail = ""
    for key in ("exception", "reason", "message", "choice"):
        if key in data:
            detail = f"  ({key}: {data[key]})"
            break
    inst = f"#{event.instance}" if event.instance is not None else ""
    return (f"    {clock_time(event.time):<15}  {inst:>4} {event.process or '':<18} "
            f"{event.kind:<20} {what}{detail}").rstrip()
