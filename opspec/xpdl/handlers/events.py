"""Handlers for BPMN events in XPDL 2.x: start, intermediate (incl. boundary) and end events
with their triggers and results (XPDL 2.0 ``Rule`` arrives normalised as ``Conditional``)."""

from __future__ import annotations

from typing import Any

from lxml import etree

from opspec.errors import SpecError
from opspec.model.activities import ActivityBody, Event, EventPosition, Trigger, TriggerKind
from opspec.model.expressions import Expression, Literal
from opspec.xpdl.handlers.common import (
    BuildContext,
    attr,
    child,
    parse_bool,
    text_of,
)
from opspec.xpdl.handlers.registry import Registry

__all__ = ["EVENTS", "parse_condition_element"]

EVENTS: Registry[ActivityBody] = Registry("event")

_KINDS: dict[str, TriggerKind] = {
    "none": TriggerKind.NONE,
    "message": TriggerKind.MESSAGE,
    "timer": TriggerKind.TIMER,
    "conditional": TriggerKind.RULE,
    "rule": TriggerKind.RULE,
    "signal": TriggerKind.SIGNAL,
    "link": TriggerKind.LINK,
    "error": TriggerKind.ERROR,
    "escalation": TriggerKind.ESCALATION,
    "compensation": TriggerKind.COMPENSATION,
    "cancel": TriggerKind.CANCEL,
    "terminate": TriggerKind.TERMINATE,
    "multiple": TriggerKind.MULTIPLE,
    "parallelmultiple": TriggerKind.PARALLEL_MULTIPLE,
}


def parse_condition_element(
    element: etree._Element | None, text: str | None, ctx: BuildContext, what: str
) -> Expression | None:
    """Parse condition ``text`` found at ``element``; a syntax error is a ``bad-condition``
    error diagnostic (never an exception)."""
    from opspec.xpdl.conditions import parse_condition

    if text is None or not text.strip():
        return None
    location = ctx.loc(element)
    try:
        return parse_condition(text, location=location)
    except (SpecError, ValueError, RecursionError) as error:
        detail = getattr(error, "message", str(error))
        ctx.error(element, "bad-condition", f"{what} {text.strip()!r} cannot be understood: {detail}",
                  "write it as an expression over data fields, e.g. status == \"ok\" && n < 3")
        return None


def _expression_text(element: etree._Element | None) -> str | None:
    """Text of ``element``'s Expression child, else its own text (both forms occur)."""
    if element is None:
        return None
    expression = child(element, "Expression")
    if expression is not None:
        return "".join(expression.itertext()).strip() or None
    return text_of(element)


def _catching(element: etree._Element | None) -> bool:
    if element is None:
        return True
    return (attr(element, "CatchThrow") or "CATCH").upper() != "THROW"


def _kind(raw: str | None, element: etree._Element, ctx: BuildContext, what: str) -> TriggerKind:
    if raw is None:
        return TriggerKind.NONE
    kind = _KINDS.get(raw.replace("-", "").replace("_", "").lower())
    if kind is None:
        allowed = ", ".join(sorted({k.value for k in _KINDS.values()}))
        ctx.warning(element, "unknown-trigger", f"unknown {what} {raw!r}; treated as None",
                    f"use one of {allowed}")
        return TriggerKind.NONE
    return kind


def _timer(element: etree._Element, ctx: BuildContext) -> dict[str, Any]:
    """TimeDate (a point in time: :func:`~opspec.xpdl.durations.parse_time_date`), TimeCycle
    as an ISO 8601 repeating interval (``R3/PT7S``) or a plain duration; a TimeDate that is no
    date is read as a duration expression (a delay), as before."""
    from opspec.xpdl.durations import (
        parse_duration_expression,
        parse_time_cycle,
        parse_time_date,
    )

    timer = child(element, "TriggerTimer")
    if timer is None:
        return {}
    date = _expression_text(child(timer, "TimeDate")) or attr(timer, "TimeDate")
    cycle = _expression_text(child(timer, "TimeCycle")) or attr(timer, "TimeCycle")
    duration: Expression | None = None
    text = cycle or date
    try:
        if cycle:
            repeating = parse_time_cycle(cycle, location=ctx.loc(timer))
            if repeating is not None:
                repeat, period, start = repeating
                found: dict[str, Any] = {"time_date": date, "time_cycle": cycle,
                                         "duration": Literal(period), "repeat": repeat}
                if start is not None:
                    found["date"], found["calendar"] = start
                return found
        elif date:
            moment = parse_time_date(date, location=ctx.loc(timer))
            if moment is not None:
                return {"time_date": date, "time_cycle": None, "date": moment[0],
                        "calendar": moment[1]}
    except SpecError as error:
        ctx.error(timer, "bad-timer", error.message, error.hint)
        return {"time_date": date, "time_cycle": cycle}
    if text:
        try:
            duration = parse_duration_expression(text)
        except (SpecError, ValueError, RecursionError) as error:
            # an error, as the engine refuses to run it (validate and run agree); the duration
            # grammar's reason ("the number is too large") said, not an expression's parse
            from opspec.xpdl.conditions import ConditionSyntaxError

            why = (f" ({error.message})" if isinstance(error, SpecError)
                   and not isinstance(error, ConditionSyntaxError) else "")
            ctx.error(timer, "bad-timer", f"timer {text!r} is not a duration, date or cycle "
                      f"opspec understands{why}, so the spec cannot run",
                      "write an ISO 8601 duration (PT5M), a number of seconds, 5min, an "
                      "expression over data fields, a date (2026-01-01T08:00:00) or a cycle "
                      "(R3/PT10M)")
    else:
        # vendor exports draw timers they never configure: they run, and fire at once
        ctx.warning(timer, "bad-timer", "the timer has no TimeDate or TimeCycle: opspec fires "
                    "it at once", "give it a TimeCycle (PT5M, R3/PT10M) or a TimeDate "
                    "(2026-01-01T08:00:00)")
    return {"time_date": date, "time_cycle": cycle, "duration": duration}


def _details(element: etree._Element, kind: TriggerKind, ctx: BuildContext) -> dict[str, Any]:
    """Name / timer / condition / direction of a trigger from its detail child."""
    if kind is TriggerKind.MESSAGE:
        detail = child(element, "TriggerResultMessage")
        message = child(detail, "Message") if detail is not None else None
        name = None
        if message is not None:
            name = attr(message, "Name") or attr(message, "Id")
        return {"name": name, "catching": _catching(detail)}
    if kind is TriggerKind.TIMER:
        return _timer(element, ctx)
    if kind is TriggerKind.RULE:
        detail = child(element, "TriggerConditional")
        text = _expression_text(detail)
        return {
            "name": attr(detail, "ConditionName") if detail is not None else None,
            "condition": parse_condition_element(detail, text, ctx, "event condition"),
        }
    if kind is TriggerKind.SIGNAL:
        detail = child(element, "TriggerResultSignal")
        return {"name": attr(detail, "Name") if detail is not None else None,
                "catching": _catching(detail)}
    if kind is TriggerKind.LINK:
        detail = child(element, "TriggerResultLink")
        name = (attr(detail, "Name") or attr(detail, "LinkId")) if detail is not None else None
        return {"name": name, "catching": _catching(detail)}
    if kind is TriggerKind.ERROR:
        detail = child(element, "ResultError")
        return {"name": attr(detail, "ErrorCode") if detail is not None else None}
    if kind is TriggerKind.ESCALATION:
        detail = child(element, "TriggerEscalation")
        name = (attr(detail, "EscalationCode") or attr(detail, "Name")) if detail is not None else None
        return {"name": name}
    if kind is TriggerKind.COMPENSATION:
        detail = child(element, "TriggerResultCompensation")
        return {"name": attr(detail, "ActivityId") if detail is not None else None}
    return {}


def _interrupting(element: etree._Element) -> bool:
    for name in ("Interrupting", "IsInterrupting"):
        value = parse_bool(attr(element, name))
        if value is not None:
            return value
    return True


@EVENTS.register("StartEvent")
def _start(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    kind = _kind(attr(element, "Trigger"), element, ctx, "start trigger")
    details = _details(element, kind, ctx)
    details["catching"] = True
    trigger = Trigger(kind=kind, interrupting=_interrupting(element), **details)
    return Event(position=EventPosition.START, trigger=trigger)


@EVENTS.register("IntermediateEvent")
def _intermediate(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    kind = _kind(attr(element, "Trigger"), element, ctx, "intermediate trigger")
    details = _details(element, kind, ctx)
    trigger = Trigger(kind=kind, attached_to=attr(element, "Target"),
                      interrupting=_interrupting(element), **details)
    return Event(position=EventPosition.INTERMEDIATE, trigger=trigger)


@EVENTS.register("EndEvent")
def _end(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    result = attr(element, "Result")
    kind = _kind(result, element, ctx, "end result")
    details = _details(element, kind, ctx)
    details["catching"] = False
    trigger = Trigger(kind=kind, **details)
    return Event(position=EventPosition.END, trigger=trigger, result=result or "None")

