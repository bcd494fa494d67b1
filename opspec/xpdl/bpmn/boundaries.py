"""Boundary events of BPMN activities, read as the engine's existing constructs:

* an interrupting boundary **timer** with a ``timeDuration`` is a synchronous ``Deadline`` of
  the activity it is attached to, a non-interrupting one an asynchronous deadline; its
  exception path leads to the boundary event, which passes the token on at once (timers with
  a ``timeDate`` or ``timeCycle`` stay boundary events the engine arms itself);
* a boundary **error** event catches the activity's failures (a device fault) as an
  ``EXCEPTION`` path named by the error's ``errorCode`` (no ``errorRef``: every failure,
  ``DEFAULTEXCEPTION``);
* **message, signal, conditional and escalation** boundary events are boundary events of
  the model (interrupting or not, as ``cancelActivity`` says);
* compensation and cancel boundary events, and those without a definition, are said at their
  line and kept as events that never fire.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TypeAlias

from lxml import etree

from opspec.model.activities import Activity, Deadline, Event, EventPosition, Execution, Trigger
from opspec.model.process import Condition, ConditionKind, Transition
from opspec.xpdl.bpmn.common import Defs, expression_text, first, local
from opspec.xpdl.bpmn.events import definitions_of, named_ref, read_timer, trigger_of

__all__ = ["Boundaries", "Plain", "read_boundaries"]

#: Builds a boundary event's node: (event element, its body, the host activity's id).
Plain: TypeAlias = Callable[[etree._Element, Event, str], Activity]

_TIMER_KINDS = ("timeDuration", "timeDate", "timeCycle")


@dataclass(slots=True)
class Boundaries:
    """What the boundary events of one level add to their hosts."""

    deadlines: dict[str, list[Deadline]] = field(default_factory=dict)
    activities: list[Activity] = field(default_factory=list)
    transitions: list[Transition] = field(default_factory=list)
    skipped: set[str] = field(default_factory=set)



def read_boundaries(events: list[etree._Element], hosts: set[str], defs: Defs,
                    level_of: Callable[[etree._Element], str], plain: Plain) -> Boundaries:
    """What the boundary ``events`` of one level (attached to the activities ``hosts``) add:
    deadlines of their hosts, exception paths, and boundary events of the model. ``level_of``
    names the level of an element in a diagnostic, ``plain`` builds the event's node."""
    out = Boundaries()
    for event in events:
        event_id = event.get("id") or ""
        host = (event.get("attachedToRef") or "").strip()
        interrupting = (event.get("cancelActivity") or "true").strip().lower() != "false"
        if host not in hosts:
            where = defs.by_id.get(host)
            defs.ctx.error(event, "unknown-reference",
                           f"boundary event {event_id!r}: attachedToRef {host!r} is no "
                           f"activity of {level_of(event)}"
                           + (f" (it is a bpmn:{local(where)}{defs.line(where)})"
                              if where is not None else ""),
                           "attach it to an activity next to it (it is left out)")
            out.skipped.add(event_id)
            continue
        found = definitions_of(event, defs)
        kind = local(found[0]) if found else None
        passing = Event(position=EventPosition.INTERMEDIATE, trigger=Trigger())
        if kind == "timerEventDefinition" and not any(
                expression_text(first(found[0], k)) for k in _TIMER_KINDS):
            # no time at all: an intermediate timer fires at once (said), but a boundary
            # timer that fired at once would cut its activity off before it began
            empty = [k for k in _TIMER_KINDS if first(found[0], k) is not None]
            defs.ctx.error(found[0], "bad-timer",
                           f"boundary timer {event_id!r} has "
                           + (f"an empty {empty[0]}" if empty
                              else "no timeDuration, timeDate or timeCycle")
                           + ", so when it interrupts its activity is not said",
                           "give it a time, e.g. <bpmn:timeDuration>PT2H</bpmn:timeDuration>")
            out.skipped.add(event_id)     # its flows are left out with it, said once here
            continue
        if kind == "timerEventDefinition":
            timer = read_timer(found[0], defs)
            if timer is None or timer.kind == "duration":
                out.deadlines.setdefault(host, []).append(Deadline(
                    duration_text=timer.text if timer else "",
                    duration=timer.duration if timer else None,
                    execution=Execution.SYNCHR if interrupting else Execution.ASYNCHR,
                    exception_name=event_id, location=defs.loc(found[0])))
                _exception_path(out, event, host, passing, event_id, defs, plain)
                continue
        if kind == "errorEventDefinition":
            code = named_ref(found[0], "errorRef", defs.errors, defs, "error")[1]
            if not interrupting:
                defs.ctx.warning(event, "non-interrupting-error",
                                 f"boundary error event {event_id!r} is non-interrupting, "
                                 "which BPMN does not allow; a failure ends the activity",
                                 "remove cancelActivity=\"false\"")
            _exception_path(out, event, host, passing, code, defs, plain)
            continue
        if kind in ("compensateEventDefinition", "cancelEventDefinition") or kind is None:
            what = ("it has no event definition" if kind is None
                    else f"opspec does not run {kind.removesuffix('EventDefinition')} events")
            defs.ctx.warning(event, "unsupported-element",
                             f"boundary event {event_id!r}: {what}; it never fires, so its "
                             "outgoing flows never carry a token",
                             "docs/bpmn.md lists the boundary events opspec runs")
            # kept as a boundary event that never fires: the nodes its flows lead to keep
            # their incoming flows, so none of them starts when the process does
            out.activities.append(plain(event, Event(
                position=EventPosition.INTERMEDIATE,
                trigger=Trigger(catching=True, attached_to=host,
                                interrupting=interrupting)), host))
            continue
        trigger = trigger_of(event, defs, catching=True, attached_to=host,
                             interrupting=interrupting)[0]
        out.activities.append(plain(event, Event(position=EventPosition.INTERMEDIATE,
                                                 trigger=trigger), host))
    return out


def _exception_path(out: Boundaries, event: etree._Element, host: str, body: Event,
                    exception: str | None, defs: Defs, plain: Plain) -> None:
    """The boundary event as a node reached by an exception path from ``host``."""
    event_id = event.get("id") or ""
    kind = ConditionKind.EXCEPTION if exception else ConditionKind.DEFAULTEXCEPTION
    out.transitions.append(Transition(
        id=f"{event_id}.exception", source=host, target=event_id,
        condition=Condition(kind=kind, text=exception, exception_name=exception),
        location=defs.loc(event)))
    out.activities.append(plain(event, body, host))
