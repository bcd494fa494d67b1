"""What each BPMN flow node *is* in the model: a table from element name to a builder, as
SpiffWorkflow's parser keys its node parsers by tag.

=======================  ===============================================================
BPMN                     model body
=======================  ===============================================================
task                     ``NoImplementation`` (a ``Task`` when it names an application)
userTask, manualTask     ``Task(USER / MANUAL)``: waits for its performer (the user lane)
serviceTask, sendTask,   ``Task(SERVICE / SEND / BUSINESS_RULE)``: runs by itself, or is
businessRuleTask         offered to a device bound to its application or performer
scriptTask               ``Task(SCRIPT)``; the script, when it is assignments, runs as them
receiveTask              a catching message event: waits for its message
callActivity             ``SubFlow`` of ``calledElement``
exclusive/parallel/      ``Route(XOR / AND / OR / EVENT / COMPLEX)``
inclusive/eventBased/
complexGateway
start/end/intermediate   ``Event`` with the trigger of its definition
events
=======================  ===============================================================

Sub-processes and boundary events need the process around them: :mod:`.process` builds them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from lxml import etree

from opspec.model.activities import (
    ActivityBody,
    Event,
    EventPosition,
    GatewayType,
    NoImplementation,
    Route,
    SubFlow,
    Task,
    TaskKind,
    Trigger,
    TriggerKind,
)
from opspec.model.data import Assignment
from opspec.xpdl.bpmn.common import Defs, first, label, text_of
from opspec.xpdl.bpmn.events import trigger_of
from opspec.xpdl.bpmn.extensions import actual_parameters, execution, task_applications

__all__ = ["GATEWAYS", "NODES", "Built", "build_node"]

GATEWAYS: dict[str, GatewayType] = {
    "exclusiveGateway": GatewayType.XOR,
    "parallelGateway": GatewayType.AND,
    "inclusiveGateway": GatewayType.OR,
    "eventBasedGateway": GatewayType.EVENT,
    "complexGateway": GatewayType.COMPLEX,
}

_TASKS: dict[str, TaskKind | None] = {
    "task": None,
    "userTask": TaskKind.USER,
    "manualTask": TaskKind.MANUAL,
    "serviceTask": TaskKind.SERVICE,
    "sendTask": TaskKind.SEND,
    "businessRuleTask": TaskKind.BUSINESS_RULE,
    "scriptTask": TaskKind.SCRIPT,
}

# End events: definition kind -> the XPDL Result the engine reads.
_RESULTS: dict[TriggerKind, str] = {
    TriggerKind.NONE: "None", TriggerKind.MESSAGE: "Message", TriggerKind.SIGNAL: "Signal",
    TriggerKind.TERMINATE: "Terminate", TriggerKind.ERROR: "Error",
    TriggerKind.ESCALATION: "Escalation", TriggerKind.COMPENSATION: "Compensation",
    TriggerKind.CANCEL: "Cancel", TriggerKind.LINK: "Link",
}


@dataclass(slots=True)
class Built:
    """A flow node's body and what else its element says: ``gateway`` for gateways,
    ``assignments`` a script task's script read as assignments, ``sends`` a message a send
    task raises when it completes."""

    body: ActivityBody
    gateway: GatewayType | None = None
    assignments: tuple[Assignment, ...] = ()
    sends: str | None = None
    manual: bool = False
    notes: list[str] = field(default_factory=list)


def _task(kind: TaskKind | None) -> Callable[[etree._Element, Defs], Built]:
    def build(element: etree._Element, defs: Defs) -> Built:
        applications = task_applications(element, defs)
        implementation = (element.get("implementation") or "").strip() or None
        if kind is None:
            body: ActivityBody = (Task(kind=TaskKind.APPLICATION, applications=applications)
                                  if applications else NoImplementation())
            return Built(body)
        if kind is TaskKind.SCRIPT:
            return _script(element, defs, applications)
        sends = None
        if kind is TaskKind.SEND:
            from opspec.xpdl.bpmn.events import named_ref

            given, sends = named_ref(element, "messageRef", defs.messages, defs, "message")
            if not given:
                flows = defs.sends.get(element.get("id") or "", [])
                sends = flows[0][0] if flows else None
        body = Task(kind=kind, applications=applications, implementation=implementation,
                    message=sends)
        return Built(body, sends=sends,
                     manual=kind in (TaskKind.USER, TaskKind.MANUAL))

    return build


def _script(element: etree._Element, defs: Defs, applications: tuple[object, ...]) -> Built:
    """A script task: its script runs as assignments when it is written in the subset of
    :mod:`.scripts` (assignments, one per line or per ``;``, Python tuple assignments);
    anything else is a ``bad-script`` error at the statement's line."""
    from opspec.xpdl.bpmn.scripts import read_script

    script_element = first(element, "script")
    text = text_of(script_element)
    body = Task(kind=TaskKind.SCRIPT, script=text,
                applications=applications)  # type: ignore[arg-type]
    if text is None or script_element is None:
        return Built(body)
    statements, _ok = read_script(script_element, defs, label(element))
    return Built(body, assignments=statements)


def _call(element: etree._Element, defs: Defs) -> Built:
    called = (element.get("calledElement") or "").strip()
    called = defs.call_aliases.get(called, called)     # tns:proc of an imported file
    if not called:
        defs.ctx.error(element, "missing-subflow-target",
                       f"{label(element)} has no calledElement, so it calls nothing",
                       "set calledElement to the id of the process to call")
    actuals = actual_parameters(element, defs)
    if not actuals and defs.process_io.get(called):
        # BPMN engines copy a called process's inputs and outputs by name (the called
        # process's ioSpecification): the caller's data field of the same id
        from opspec.model.data import ActualParameter
        from opspec.model.expressions import Name

        location = defs.loc(element)
        actuals = tuple(ActualParameter(text=name, expression=Name((name,)), location=location)
                        for name, _mode in defs.process_io[called])
    return Built(SubFlow(process=called, execution=execution(element, defs),
                         actual_parameters=actuals))


def _receive(element: etree._Element, defs: Defs) -> Built:
    from opspec.xpdl.bpmn.events import named_ref

    given, name = named_ref(element, "messageRef", defs.messages, defs, "message")
    if not given:
        flows = defs.receives.get(element.get("id") or "", [])
        name = flows[0][0] if flows else None
    trigger = Trigger(kind=TriggerKind.MESSAGE, name=name, catching=True)
    return Built(Event(position=EventPosition.INTERMEDIATE, trigger=trigger))


def _gateway(kind: GatewayType) -> Callable[[etree._Element, Defs], Built]:
    def build(element: etree._Element, defs: Defs) -> Built:
        return Built(Route(gateway=kind), gateway=kind)

    return build


def _start(element: etree._Element, defs: Defs) -> Built:
    trigger, definition, _timer = trigger_of(element, defs, catching=True)
    if trigger.kind in (TriggerKind.ERROR, TriggerKind.ESCALATION, TriggerKind.COMPENSATION):
        defs.ctx.warning(definition, "unsupported-event",
                         f"{label(element)} starts on {trigger.kind.value}, which only an event "
                         "sub-process can catch; opspec waits for a message of that name",
                         "start it with a message, signal, timer or none start event")
    return Built(Event(position=EventPosition.START, trigger=trigger))


def _end(element: etree._Element, defs: Defs) -> Built:
    trigger, definition, _timer = trigger_of(element, defs, catching=False)
    # error and escalation end events run as BPMN defines them (the engine hands them to the
    # nearest enclosing boundary event for them); the others end their path and say so
    if trigger.kind in (TriggerKind.CANCEL, TriggerKind.COMPENSATION):
        defs.ctx.warning(definition, "unsupported-event",
                         f"{label(element)} throws {trigger.kind.value}: opspec ends the path "
                         "there but does not hand the "
                         f"{trigger.kind.value} to a boundary event of an enclosing "
                         "sub-process or call activity",
                         "model the outcome with a message, a data field and a gateway, or "
                         "an exception path (docs/bpmn.md)")
    return Built(Event(position=EventPosition.END, trigger=trigger,
                       result=_RESULTS.get(trigger.kind, "None")))


def _intermediate(catching: bool) -> Callable[[etree._Element, Defs], Built]:
    def build(element: etree._Element, defs: Defs) -> Built:
        trigger, definition, _timer = trigger_of(element, defs, catching=catching)
        if catching and trigger.kind is TriggerKind.NONE:
            defs.ctx.warning(element, "empty-event",
                             f"{label(element)} catches nothing (no event definition); it "
                             "passes the token on at once", "give it a message, timer, signal "
                             "or conditional event definition")
        if not catching and trigger.kind in (TriggerKind.COMPENSATION, TriggerKind.ERROR):
            defs.ctx.warning(definition, "unsupported-event",
                             f"{label(element)} throws {trigger.kind.value}, which opspec raises "
                             "as a message of that name (a boundary event waiting for it "
                             "catches it)", "see docs/bpmn.md")
        return Built(Event(position=EventPosition.INTERMEDIATE, trigger=trigger))

    return build


NODES: dict[str, Callable[[etree._Element, Defs], Built]] = {
    **{name: _task(kind) for name, kind in _TASKS.items()},
    "receiveTask": _receive,
    "callActivity": _call,
    **{name: _gateway(kind) for name, kind in GATEWAYS.items()},
    "startEvent": _start,
    "endEvent": _end,
    "intermediateCatchEvent": _intermediate(True),
    "intermediateThrowEvent": _intermediate(False),
}


def build_node(name: str, element: etree._Element, defs: Defs) -> Built:
    return NODES[name](element, defs)
