"""The semantics gate's tests about where a process level starts.

**A flow node no triggered instance starts**: a node without an incoming sequence flow
(transition) at the top level of a process that has a start event with a trigger (timer,
message, signal, conditional, link, error, escalation). BPMN 2.0 §10.4.2 instantiates "All
Flow Objects that do not have an incoming Sequence Flow" with every instance. The engine does
not: an instance that a triggered start event starts runs only that start event's path
(:mod:`opspec.engine.compiling.graphs`, ``start_events``); the node runs only in an instance
started without a trigger (beside a none start event, called from another process, from the
API). Reported at the node's line (``bpmn-unstarted-node``, ``xpdl-unstarted-activity`` in
the registry); ``opspec check`` plays the same instances
(:mod:`opspec.model.instance_starts`). A process-level ``opspec:StartTrigger`` or
``opspec:Arrival`` makes every instance start at every start node: then nothing is reported.

**A start event with a trigger inside a sub-process** (an embedded sub-process, an XPDL
activity set; not an event sub-process): BPMN 2.0 §10.4.2 allows only None there, and the
engine starts it with the sub-process, its trigger ignored (``bpmn-sub-process-start-trigger``,
``xpdl-activity-set-start-trigger``).

Read on the file as written, before the reader rewrites it.
"""

from __future__ import annotations

from lxml import etree

__all__ = ["BPMN_TRIGGERS", "XPDL_TRIGGERS", "triggered_start_in_sub_level",
           "unstarted_by_triggered_starts"]

#: Event definitions that make a BPMN start event a triggered one (the engine arms it).
BPMN_TRIGGERS = frozenset({
    "messageEventDefinition", "timerEventDefinition", "signalEventDefinition",
    "conditionalEventDefinition", "linkEventDefinition", "errorEventDefinition",
    "escalationEventDefinition"})
#: XPDL StartEvent Trigger values (lower case, no separators) the engine arms.
XPDL_TRIGGERS = frozenset({"message", "timer", "conditional", "rule", "signal", "link",
                           "error", "escalation"})
_START_DIRECTIVES = frozenset({"StartTrigger", "Arrival"})


def _local(element: etree._Element) -> str:
    return str(element.tag).rsplit("}", 1)[-1]


def _elements(parent: etree._Element, *names: str) -> list[etree._Element]:
    return [c for c in parent if isinstance(c.tag, str) and _local(c) in names]


def _start_directive(process: etree._Element) -> bool:
    """A process-level opspec:StartTrigger or opspec:Arrival (attribute, ExtendedAttribute or
    extension element): the engine then starts every instance at all its start nodes."""
    if any(str(name).rsplit("}", 1)[-1] in _START_DIRECTIVES and str(name).startswith("{")
           for name in process.keys()):  # noqa: SIM118 - iterating an element gives children
        return True
    for holder in _elements(process, "ExtendedAttributes", "extensionElements"):
        for item in holder:
            if not isinstance(item.tag, str):
                continue
            name = item.get("Name") if _local(item) == "ExtendedAttribute" else _local(item)
            if (name or "").removeprefix("opspec:") in _START_DIRECTIVES:
                return True
    return False


def _bpmn_level(process: etree._Element) -> tuple[bool, set[str]]:
    """Whether the process has a triggered start event, and the ids of its flow nodes that
    are targets of a sequence flow."""
    triggered = any(
        any(isinstance(c.tag, str) and _local(c) in BPMN_TRIGGERS for c in start)
        for start in _elements(process, "startEvent"))
    targets = {(flow.get("targetRef") or "").strip()
               for flow in _elements(process, "sequenceFlow")}
    return triggered and not _start_directive(process), targets


def _xpdl_trigger(activity: etree._Element) -> str | None:
    for event in _elements(activity, "Event"):
        for start in _elements(event, "StartEvent"):
            raw = (start.get("Trigger") or "None").replace("-", "").replace("_", "").lower()
            return raw
    return None


def _xpdl_level(process: etree._Element) -> tuple[bool, set[str]]:
    triggered = any(_xpdl_trigger(activity) in XPDL_TRIGGERS
                    for activities in _elements(process, "Activities")
                    for activity in _elements(activities, "Activity"))
    targets = {(transition.get("To") or "").strip()
               for transitions in _elements(process, "Transitions")
               for transition in _elements(transitions, "Transition")}
    return triggered and not _start_directive(process), targets


def unstarted_by_triggered_starts(element: etree._Element,
                                  levels: dict[etree._Element, tuple[bool, set[str]]]) -> bool:
    """Whether ``element`` (a BPMN flow node, or an XPDL Activity) has no incoming sequence
    flow at the top level of a process with a triggered start event, and is none of the
    nodes BPMN 2.0 §10.4.2 excepts: start events, boundary events, event sub-processes and
    compensation activities. ``levels`` caches each process's analysis."""
    parent = element.getparent()
    if parent is None:
        return False
    if _local(element) == "Activity":              # XPDL: WorkflowProcess/Activities/Activity
        process = parent.getparent()
        if _local(parent) != "Activities" or process is None or _local(process) not in (
                "WorkflowProcess", "ProcessDefinition"):
            return False
        if _xpdl_trigger(element) is not None or (
                element.get("IsForCompensation") or "").strip().lower() == "true":
            return False
        if any((event.get("Target") or "").strip()
               for holder in _elements(element, "Event")
               for event in _elements(holder, "IntermediateEvent")):
            return False                             # a boundary event: its host starts it
        analyse = _xpdl_level
        ident = element.get("Id") or ""
    else:
        process = parent
        if _local(process) != "process":
            return False
        if ((element.get("triggeredByEvent") or "").strip().lower() == "true"
                or (element.get("isForCompensation") or "").strip().lower() == "true"):
            return False
        analyse = _bpmn_level
        ident = element.get("id") or ""
    level = levels.get(process)
    if level is None:
        level = levels[process] = analyse(process)
    triggered, targets = level
    return triggered and ident.strip() not in targets


def triggered_start_in_sub_level(element: etree._Element) -> bool:
    """Whether ``element`` (a BPMN startEvent, or an XPDL StartEvent) has a trigger the engine
    would arm at a top level, but starts an embedded sub-process (not an event sub-process)
    or an XPDL activity set, where it starts with its level and the trigger is ignored."""
    parent = element.getparent()
    if parent is None:
        return False
    if _local(element) == "startEvent":
        return (_local(parent) in ("subProcess", "adHocSubProcess", "transaction")
                and (parent.get("triggeredByEvent") or "").strip().lower() != "true"
                and any(isinstance(c.tag, str) and _local(c) in BPMN_TRIGGERS
                        for c in element))
    activity = parent.getparent()                   # Activity/Event/StartEvent
    activities = activity.getparent() if activity is not None else None
    owner = activities.getparent() if activities is not None else None
    return (owner is not None and _local(owner) == "ActivitySet"
            and _xpdl_trigger(activity) in XPDL_TRIGGERS)
