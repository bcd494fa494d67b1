"""Event sub-processes with a timer or message start event, read as the boundary events they
behave like.

BPMN 2.0 §10.2.5 (Event Sub-Process): "Each time the Start Event is triggered while the parent
Process is active, then the Event Sub-Process will start"; an interrupting one cancels the
parent's other work first, a non-interrupting one runs beside it (§13.5.4). That is what a
boundary event attached to the parent's contents does (§13.5.3): so the contents of the parent
level (its flow nodes, sequence flows and boundary events) are moved into one embedded
sub-process, ``<parent>__body``, and each event sub-process becomes an ordinary embedded
sub-process that a boundary event on that body starts (the start event's trigger, interrupting
as its ``isInterrupting`` says), its start event a none start event. The names a trace shows
stay the file's: the start event and everything in the event sub-process keep their ids; the
body and the boundary event (``<event sub-process>__trigger``) are the only new ones.

Only what this reading runs as the standard says is rewritten: a level whose own start events
are all none start events (a triggered start event inside the body would start with it), and
event sub-processes with exactly one start event, a timer or a message one. Anything else stays
as written, and the reader refuses it at its line (:mod:`opspec.xpdl.constructs`, ``not-run``).
"""

from __future__ import annotations

import copy
from collections.abc import Iterator

from lxml import etree

from opspec.xpdl.bpmn.common import BPMN, local, namespace

__all__ = ["RUNNABLE_TRIGGERS", "hoist_event_sub_processes", "is_event_sub_process",
           "runnable_event_sub_process"]

#: The start event definitions of the event sub-processes opspec runs.
RUNNABLE_TRIGGERS = frozenset({"timerEventDefinition", "messageEventDefinition"})
_SUBS = frozenset({"subProcess", "transaction", "adHocSubProcess"})
_DEFINITIONS = frozenset({
    "messageEventDefinition", "timerEventDefinition", "signalEventDefinition",
    "conditionalEventDefinition", "errorEventDefinition", "escalationEventDefinition",
    "compensateEventDefinition", "cancelEventDefinition", "eventDefinitionRef",
    "terminateEventDefinition", "linkEventDefinition"})
# what moves into the body: the level's flow (its data, lanes and documentation stay)
_FLOW = frozenset({
    "task", "userTask", "manualTask", "serviceTask", "sendTask", "receiveTask", "scriptTask",
    "businessRuleTask", "callActivity", "subProcess", "transaction", "adHocSubProcess",
    "startEvent", "endEvent", "intermediateCatchEvent", "intermediateThrowEvent",
    "boundaryEvent", "exclusiveGateway", "parallelGateway", "inclusiveGateway",
    "complexGateway", "eventBasedGateway", "sequenceFlow"})


def _bpmn(element: etree._Element) -> bool:
    return isinstance(element.tag, str) and namespace(element) == BPMN


def _children(element: etree._Element, *names: str) -> Iterator[etree._Element]:
    for child in element:
        if _bpmn(child) and local(child) in names:
            yield child


def _definitions(event: etree._Element) -> list[etree._Element]:
    return [child for child in event if _bpmn(child) and local(child) in _DEFINITIONS]


def is_event_sub_process(element: etree._Element) -> bool:
    return (_bpmn(element) and local(element) in _SUBS
            and (element.get("triggeredByEvent") or "").strip().lower() == "true")


def runnable_event_sub_process(element: etree._Element) -> bool:
    """Whether ``element`` is an event sub-process this module rewrites (see the module
    docstring): one start event, with one timer or message definition, in a level whose own
    start events are none start events."""
    if not is_event_sub_process(element) or local(element) != "subProcess":
        return False
    starts = list(_children(element, "startEvent"))
    if len(starts) != 1:
        return False
    found = _definitions(starts[0])
    if len(found) != 1 or local(found[0]) not in RUNNABLE_TRIGGERS:
        return False
    parent = element.getparent()
    return parent is not None and not any(
        _definitions(start) for start in _children(parent, "startEvent"))


def hoist_event_sub_processes(container: etree._Element) -> None:
    """Rewrite ``container``'s runnable event sub-processes in place (see the module
    docstring); one that is not runnable leaves the level as written."""
    events = [child for child in container if is_event_sub_process(child)]
    if not events or not all(runnable_event_sub_process(e) for e in events):
        return
    owner = container.get("id") or "process"
    line = events[0].sourceline
    body = etree.Element(f"{{{BPMN}}}subProcess", id=f"{owner}__body", name=f"{owner} (body)")
    moved = [child for child in container if _bpmn(child) and local(child) in _FLOW
             and not is_event_sub_process(child)]
    if not moved:
        return
    moved[0].addprevious(body)
    body.sourceline = moved[0].sourceline
    for child in moved:
        body.append(child)
    for event in events:
        start = next(_children(event, "startEvent"))
        definition = _definitions(start)[0]
        interrupting = (start.get("isInterrupting") or "true").strip().lower() != "false"
        trigger = etree.SubElement(
            container, f"{{{BPMN}}}boundaryEvent", id=f"{event.get('id')}__trigger",
            attachedToRef=body.get("id") or "",
            cancelActivity="true" if interrupting else "false")
        trigger.append(copy.deepcopy(definition))
        start.remove(definition)
        start.attrib.pop("isInterrupting", None)
        event.attrib.pop("triggeredByEvent", None)
        flow = etree.SubElement(container, f"{{{BPMN}}}sequenceFlow",
                                id=f"{event.get('id')}__start", sourceRef=trigger.get("id") or "",
                                targetRef=event.get("id") or "")
        trigger.sourceline = flow.sourceline = start.sourceline or line
