"""Writing an event activity as XPDL 2.1: a start, intermediate (its boundary target) or end
event, its trigger or result named as XPDL 2.1 allows at that position (``None`` where it has
no such trigger; escalations have none), and the trigger's detail: the message, the timer's
date or cycle, the condition, the signal, link or error.
"""

from __future__ import annotations

from lxml import etree

from opspec.model import Event, EventPosition, Literal, Trigger, TriggerKind
from opspec.xpdl.sisarl_write import duration_text, expression_text
from opspec.xpdl.write_elements import nmtoken, sub, xpdl_tag

__all__ = [
    "write_event",
]

_TRIGGER_NAMES = {
    TriggerKind.NONE: "None", TriggerKind.MESSAGE: "Message", TriggerKind.TIMER: "Timer",
    TriggerKind.RULE: "Conditional", TriggerKind.SIGNAL: "Signal", TriggerKind.LINK: "Link",
    TriggerKind.ERROR: "Error", TriggerKind.COMPENSATION: "Compensation",
    TriggerKind.CANCEL: "Cancel", TriggerKind.TERMINATE: "Terminate",
    TriggerKind.MULTIPLE: "Multiple", TriggerKind.PARALLEL_MULTIPLE: "Multiple",
    TriggerKind.ESCALATION: "None",   # XPDL 2.1 has no escalation events
}
_START_TRIGGERS = {"None", "Message", "Timer", "Conditional", "Signal", "Multiple"}
_INTERMEDIATE_TRIGGERS = {"None", "Message", "Timer", "Error", "Cancel", "Conditional", "Link",
                          "Signal", "Compensation", "Multiple"}
_END_RESULTS = {"None", "Message", "Error", "Cancel", "Compensation", "Signal", "Terminate",
                "Multiple"}


def _write_trigger_detail(parent: etree._Element, trigger: Trigger, name: str) -> None:
    """The trigger's child element (message, timer, condition…), when it has one."""
    kind = trigger.kind
    catch_throw = "CATCH" if trigger.catching else "THROW"
    if kind is TriggerKind.MESSAGE:
        element = sub(parent, "TriggerResultMessage", CatchThrow=catch_throw)
        if trigger.name is not None:
            sub(element, "Message", Id=nmtoken(trigger.name), Name=trigger.name)
    elif kind is TriggerKind.TIMER and name == "Timer":
        element = sub(parent, "TriggerTimer")
        if trigger.time_date is not None:
            sub(element, "TimeDate", trigger.time_date)
        else:
            cycle = trigger.time_cycle
            if cycle is None and isinstance(trigger.duration, Literal) and isinstance(
                trigger.duration.value, (int, float)) and not isinstance(
                    trigger.duration.value, bool):
                cycle = duration_text(float(trigger.duration.value))
            sub(element, "TimeCycle", cycle or "")
    elif kind is TriggerKind.RULE and name == "Conditional":
        element = sub(parent, "TriggerConditional", ConditionName=trigger.name)
        if trigger.condition is not None:
            sub(element, "Expression", expression_text(trigger.condition))
    elif kind is TriggerKind.SIGNAL and name == "Signal":
        element = sub(parent, "TriggerResultSignal", Name=trigger.name, CatchThrow=catch_throw)
        sub(element, "Properties")
    elif kind is TriggerKind.LINK and name == "Link":
        sub(parent, "TriggerResultLink", Name=nmtoken(trigger.name) if trigger.name else None,
            CatchThrow=catch_throw)
    elif kind is TriggerKind.ERROR and name == "Error":
        sub(parent, "ResultError", ErrorCode=trigger.name)
    elif kind is TriggerKind.COMPENSATION and name == "Compensation":
        sub(parent, "TriggerResultCompensation")
    elif (kind is TriggerKind.CANCEL and name == "Cancel"
          and parent.tag == xpdl_tag("IntermediateEvent")):
        sub(parent, "TriggerResultCancel")


def write_event(parent: etree._Element, event: Event) -> None:
    container = sub(parent, "Event")
    trigger = event.trigger
    name = _TRIGGER_NAMES[trigger.kind]
    if event.position is EventPosition.START:
        name = name if name in _START_TRIGGERS else "None"
        element = sub(container, "StartEvent", Trigger=name)
    elif event.position is EventPosition.INTERMEDIATE:
        name = name if name in _INTERMEDIATE_TRIGGERS else "None"
        element = sub(container, "IntermediateEvent", Trigger=name,
                      Target=trigger.attached_to)
    else:
        result = event.result if event.result in _END_RESULTS else None
        name = result or (name if name in _END_RESULTS else "None")
        element = sub(container, "EndEvent", Result=name)
    _write_trigger_detail(element, trigger, name)
