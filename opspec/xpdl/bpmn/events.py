"""BPMN event definitions as model triggers: message, timer (timeDate, timeCycle,
timeDuration), signal, conditional, error, escalation, link, terminate, compensation,
cancel. The same :class:`~opspec.model.activities.Trigger` values XPDL 2.x events give."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from lxml import etree

from opspec.errors import SpecError
from opspec.model.activities import Trigger, TriggerKind
from opspec.model.expressions import Expression, Literal
from opspec.xpdl.bpmn.common import Defs, bpmn_children, expression_text, first, local
from opspec.xpdl.bpmn.cron import cron_cycle

__all__ = ["KINDS", "Timer", "definitions_of", "named_ref", "read_timer", "trigger_of"]

#: Event definition element -> trigger kind.
KINDS: dict[str, TriggerKind] = {
    "messageEventDefinition": TriggerKind.MESSAGE,
    "timerEventDefinition": TriggerKind.TIMER,
    "signalEventDefinition": TriggerKind.SIGNAL,
    "conditionalEventDefinition": TriggerKind.RULE,
    "errorEventDefinition": TriggerKind.ERROR,
    "escalationEventDefinition": TriggerKind.ESCALATION,
    "terminateEventDefinition": TriggerKind.TERMINATE,
    "linkEventDefinition": TriggerKind.LINK,
    "compensateEventDefinition": TriggerKind.COMPENSATION,
    "cancelEventDefinition": TriggerKind.CANCEL,
}

_TIMER_HINT = ("write timeDuration as an ISO 8601 duration (PT5M), timeDate as "
               "2026-01-01T08:00:00 and timeCycle as R3/PT10M or R/2026-01-01T08:00:00/P1D "
               "(a cron expression is read when it fires every day at evenly spaced times)")


def definitions_of(event: etree._Element, defs: Defs) -> list[etree._Element]:
    """The event's definitions in document order (``eventDefinitionRef`` resolved)."""
    out: list[etree._Element] = []
    for sub in bpmn_children(event):
        name = local(sub)
        if name in KINDS:
            out.append(sub)
        elif name == "eventDefinitionRef":
            ref = (sub.text or "").strip()
            target = defs.by_id.get(ref)
            if target is not None and local(target) in KINDS:
                out.append(target)
            else:
                defs.ctx.error(sub, "unknown-reference", f"eventDefinitionRef {ref!r} names no "
                               "event definition of this file", "fix the reference")
    return out


@dataclass(frozen=True, slots=True)
class Timer:
    """What a timerEventDefinition says: ``kind`` is ``duration``, ``date`` or ``cycle``,
    ``text`` as written (JUEL wrapper and quotes removed), ``fields`` the
    :class:`Trigger` fields the XPDL reader gives the same timer (empty when unreadable)."""

    kind: str
    text: str
    fields: dict[str, Any]
    duration: Expression | None = None


def read_timer(definition: etree._Element, defs: Defs) -> Timer | None:
    """The timer of a ``timerEventDefinition``. An unreadable value is a ``bad-timer`` error
    (the engine could not run it either: validate and run agree, as for XPDL's); a timer with
    no time is a ``bad-timer`` warning saying what the engine does with it: fire at once."""
    from opspec.xpdl.durations import (
        parse_duration_expression,
        parse_time_cycle,
        parse_time_date,
    )

    ctx = defs.ctx
    for kind in ("timeDuration", "timeDate", "timeCycle"):
        element = first(definition, kind)
        if element is None:
            continue
        text = expression_text(element, unquote=True)
        if text is None:
            ctx.warning(element, "bad-timer", f"{kind} is empty: opspec fires the timer at "
                        "once", _TIMER_HINT)
            return None
        where = defs.loc(element)
        try:
            if kind == "timeCycle":
                cycle = parse_time_cycle(text, location=where)
                iso = cron_cycle(text, where) if cycle is None else None
                if iso is not None:     # a cron expression that is a fixed period
                    cycle = parse_time_cycle(iso, location=where)
                    defs.info(element, "cron-timer", f"the cron timeCycle {text!r} is read "
                              f"as {iso}: from {iso.split('/')[1][1:]} of day 1 of the run, "
                              "then every period, as the cron fires each day")
                if cycle is None:
                    raise SpecError(f"cannot read timeCycle {text!r}", location=where)
                repeat, period, start = cycle
                fields: dict[str, Any] = {"time_cycle": text, "duration": Literal(period),
                                          "repeat": repeat}
                if start is not None:
                    fields["date"], fields["calendar"] = start
                return Timer("cycle", text, fields)
            if kind == "timeDate":
                moment = parse_time_date(text, location=where)
                if moment is None:
                    # an expression (a data field holding an ISO date): the engine fires at
                    # the date its value holds when the timer is armed
                    expression = parse_duration_expression(text, location=where)
                    return Timer("date", text, {"time_date": text, "duration": expression},
                                 expression)
                return Timer("date", text, {"time_date": text, "date": moment[0],
                                            "calendar": moment[1]})
            duration = parse_duration_expression(text, location=where)
        except (SpecError, ValueError, RecursionError) as error:
            message = getattr(error, "message", str(error))
            ctx.error(element, "bad-timer", f"{message}, so the timer cannot run",
                      _TIMER_HINT)
            return None
        return Timer("duration", text, {"duration": duration}, duration)
    ctx.warning(definition, "bad-timer", "the timer has no timeDuration, timeDate or "
                "timeCycle: opspec fires it at once", _TIMER_HINT)
    return None


def named_ref(definition: etree._Element, attribute: str, table: dict[str, str], defs: Defs,
           what: str) -> tuple[bool, str | None]:
    """``(given, name)`` of the element ``attribute`` refers to; an unknown reference is an
    ``unknown-reference`` error."""
    ref = (definition.get(attribute) or "").strip()
    if not ref:
        return False, None
    if ":" in ref and ref not in table:
        ref = ref.split(":", 1)[1]          # a prefixed QName reference (tns:Message_1)
    if ref not in table:
        defs.ctx.error(definition, "unknown-reference",
                       f"{attribute} {ref!r} names no bpmn:{what} of this file",
                       f"declare <bpmn:{what} id=\"{ref}\"> or fix the reference")
        return True, None
    return True, table[ref]


def _flow_message(event: etree._Element, defs: Defs, catching: bool
                  ) -> tuple[str | None, bool]:
    """The message a message flow to (or from) ``event`` carries, and whether the flow names
    it with a ``messageRef`` (else the flow's name or id stands for it)."""
    flows = (defs.receives if catching else defs.sends).get(event.get("id") or "", [])
    if not flows:
        return None, False
    return flows[0][0], bool(flows[0][1].get("messageRef"))


def trigger_of(event: etree._Element, defs: Defs, *, catching: bool,
               attached_to: str | None = None, interrupting: bool = True
               ) -> tuple[Trigger, etree._Element | None, Timer | None]:
    """The trigger of a BPMN event, the definition it came from and, for timers, the timer."""
    found = definitions_of(event, defs)
    common: dict[str, Any] = {"catching": catching, "attached_to": attached_to,
                              "interrupting": interrupting}
    if not found:
        return Trigger(kind=TriggerKind.NONE, **common), None, None
    definition = found[0]
    if len(found) > 1:
        defs.ctx.warning(event, "multiple-event-definitions",
                         f"event {event.get('id')!r} has {len(found)} event definitions; opspec "
                         f"uses only the first ({local(definition)})",
                         "split it into one event per definition (an event-based gateway "
                         "waits for the first of several)")
    kind = KINDS[local(definition)]
    name: str | None = None
    timer: Timer | None = None
    if kind is TriggerKind.MESSAGE:
        given, name = named_ref(definition, "messageRef", defs.messages, defs, "message")
        flow, explicit = _flow_message(event, defs, catching)
        if not given:
            name = flow
        elif name is not None and explicit and flow != name:
            defs.ctx.warning(event, "message-mismatch",
                             f"event {event.get('id')!r} names message {name!r}, but its message "
                             f"flow carries {flow!r}; opspec uses {name!r}",
                             "make the message flow's messageRef and the event's agree")
    elif kind is TriggerKind.SIGNAL:
        name = named_ref(definition, "signalRef", defs.signals, defs, "signal")[1]
    elif kind is TriggerKind.ERROR:
        name = named_ref(definition, "errorRef", defs.errors, defs, "error")[1]
    elif kind is TriggerKind.ESCALATION:
        name = named_ref(definition, "escalationRef", defs.escalations, defs, "escalation")[1]
    elif kind is TriggerKind.LINK:
        name = (definition.get("name") or event.get("name") or "").strip() or None
    elif kind is TriggerKind.RULE:
        condition = first(definition, "condition")
        text = expression_text(condition)
        from opspec.xpdl.bpmn.scripts import bpmn_condition

        common["condition"] = bpmn_condition(
            condition if condition is not None else definition, text, defs,
            "event condition")
        if text is None:
            defs.ctx.error(definition, "bad-condition", "the conditional event has no "
                           "condition", "add <bpmn:condition>expression</bpmn:condition>")
    elif kind is TriggerKind.TIMER:
        timer = read_timer(definition, defs)
        if timer is not None:
            common.update(timer.fields)
    return Trigger(kind=kind, name=name, **common), definition, timer
