"""The walkthrough's timeline panel: the trace's events, newest first, filtered by lane.

``l`` cycles the filters of :func:`lane_filters`: all lanes, the device's, the user's (and,
with ``--large``, the timeline hidden). A spec without a user lane has nothing to tell apart:
its timeline shows every event, and ``l`` only hides it with ``--large``. Each line names the
lane in the spec's own words (:mod:`opspec.engine.lane_labels`); the person's or the model's
actions are the user lane's, device faults and notes the device's.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from rich.text import Text

from opspec.engine.lane_labels import LaneLabels
from opspec.tui.session_clock import time_of_day_shown

__all__ = ["HIDDEN", "lane_filters", "timeline_text"]

LANES = ("all", "device", "user")
HIDDEN = "hidden"
_KINDS = frozenset({
    "activity.completed", "activity.omitted", "activity.withdrawn", "activity.offered",
    "trigger.raised", "deadline.expired", "process.started", "process.completed", "fault",
    "mode.changed", "walkthrough.action"})


def lane_filters(*, user_lane: bool, large: bool) -> tuple[str, ...]:
    """What ``l`` cycles through: the lanes (only "all" without a user lane: the device's
    would be the same events, the user's none), then "hidden" with ``large``."""
    return (*(LANES if user_lane else LANES[:1]), *((HIDDEN,) if large else ()))


def timeline_text(events: Sequence[Any], lanes: LaneLabels, shown: str, rows: int, *,
                  filters: Sequence[str], dim: str = "dim") -> Text:
    """The newest ``rows`` events of ``events`` in lane ``shown`` (one of ``filters``), under
    a line saying which lanes are shown and what ``l`` does."""
    if shown == HIDDEN:
        return Text()
    text = Text(no_wrap=True, overflow="ellipsis")
    does = ("(l: change)" if len([f for f in filters if f != HIDDEN]) > 1
            else "(no user lane; l: hide)" if HIDDEN in filters
            else "(this spec has no user lane)")
    text.append(f"showing: {shown} {does}\n", style=dim)
    count = 0
    for event in reversed(events):
        if event.kind not in _KINDS:
            continue
        # the person's (or the model's) actions belong to the user lane, faults and
        # device notes to the device; the rest to the lane the spec puts them in, by
        # its name (a BPMN lane "Resident" whose work is manual is the user lane)
        if event.kind == "walkthrough.action":
            users, label = True, "user"
        elif event.kind in ("fault", "device.note"):
            users, label = False, "device"
        else:
            users, label = lanes.is_user(event), lanes.label(event)
        if shown != "all" and users != (shown == "user"):
            continue
        text.append(f"{time_of_day_shown(event.time)}  {label:<{lanes.width}} "
                    f"{_what(event)}\n")
        count += 1
        if count >= rows:
            break
    return text


def _what(event: Any) -> str:
    data = event.data or {}
    if event.kind == "trigger.raised":
        return f"trigger {data.get('name', '?')} raised"
    if event.kind == "fault":
        return (f"FAULT {data.get('device') or ''} {data.get('participant') or ''}: "
                f"{data.get('fault', '')}")
    if event.kind == "walkthrough.action":
        return f"{'you' if data.get('by') == 'person' else 'model'}: {data.get('action')}"
    return f"{event.activity or event.process or ''} {event.kind.split('.')[-1]}"
