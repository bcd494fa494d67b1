"""Model -> standard XPDL 2.1 XML.

:func:`write_xpdl` writes every model element back as XPDL 2.1
(``http://www.wfmc.org/2008/XPDL2.1``), children in the order the official schema
(``bpmnxpdl_31.xsd``) requires, so that the output of a schema-valid input validates again.

- Extended attributes are written verbatim (``Value``, text and raw child XML).
- SISARL-XPDL directives (:mod:`opspec.model.sisarl`) are written as ``ExtendedAttribute``
  elements named ``opspec:…`` (``docs/sisarl-xpdl.md``), except where a verbatim extended
  attribute of the same name is already there (the reader may keep those), so nothing is
  written twice.
- Conditions, assignments and parameters are written from their original text when the model
  has it, else printed from the expression tree (:func:`expression_text`).

Known losses (the model does not keep them, or XPDL 2.1 has no place for them): graphics,
application types other than Script/Xslt/Form, ``business-rule`` tasks (written as
``TaskService``), the ``interrupting`` flag of boundary events, source lines.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable, Iterator, Sequence
from typing import TypeVar

from lxml import etree

from opspec.model import (
    Activity,
    ActivitySet,
    ActualParameter,
    Application,
    ArrayType,
    Assignment,
    BasicType,
    BlockActivity,
    Condition,
    ConditionKind,
    DataField,
    DataType,
    DeclaredType,
    EnumerationType,
    Event,
    EventPosition,
    ExtendedAttribute,
    ExternalReferenceType,
    FormalParameter,
    GatewayType,
    Lane,
    ListType,
    Literal,
    NoImplementation,
    Package,
    Participant,
    Pool,
    RecordType,
    Reference,
    Route,
    SchemaType,
    SubFlow,
    Task,
    TaskKind,
    Transition,
    Trigger,
    TriggerKind,
    TypeDeclaration,
    UnionType,
    WorkflowProcess,
)
from opspec.xpdl.sisarl_write import (
    activity_directive_attributes,
    builtin_attribute,
    distribution_text,
    duration_text,
    expression_text,
    literal_text,
    merged_attributes,
    package_directive_attributes,
    process_directive_attributes,
    trigger_text,
)

__all__ = [
    "XPDL21",
    "distribution_text",
    "duration_text",
    "expression_text",
    "trigger_text",
    "write_xpdl",
]

T = TypeVar("T")

XPDL21 = "http://www.wfmc.org/2008/XPDL2.1"
XPDL10 = "http://www.wfmc.org/2002/XPDL1.0"
OPSPEC = "urn:opspec:sisarl:1"
_NSMAP = {None: XPDL21, "opspec": OPSPEC}


def _q(local: str) -> str:
    return f"{{{XPDL21}}}{local}"


def _sub(parent: etree._Element, local: str, text: str | None = None, **attrs: str | None) -> etree._Element:
    element = etree.SubElement(parent, _q(local))
    for key, value in attrs.items():
        if value is not None:
            element.set(key, value)
    if text is not None:
        element.text = text
    return element


def _each(parent: etree._Element, wrapper: str,
          items: Sequence[T]) -> Iterator[tuple[etree._Element, T]]:
    """Each of ``items`` with the ``wrapper`` element written for them (XPDL's
    ``<DataFields>``, ``<Transitions>``…); no wrapper at all when there are none."""
    if not items:
        return
    container = _sub(parent, wrapper)
    for item in items:
        yield container, item


def _bool(value: bool) -> str:
    return "true" if value else "false"


# --------------------------------------------------------------------------- extended attributes


_FRAGMENT_PARSER = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False)


def _append_raw_xml(element: etree._Element, raw_xml: str) -> None:
    """Put the verbatim child XML of an extended attribute back under ``element``."""
    wrapper = f'<w xmlns:opspec="{OPSPEC}">{raw_xml}</w>'
    try:
        parsed = etree.fromstring(wrapper.encode("utf-8"), _FRAGMENT_PARSER)
    except etree.XMLSyntaxError:
        # Not well-formed on its own (it always was in the source): keep it as text.
        element.text = (element.text or "") + raw_xml
        return
    if parsed.text and parsed.text.strip():
        element.text = (element.text or "") + parsed.text
    for child in list(parsed):
        element.append(child)


def _write_extended(parent: etree._Element, attributes: Iterable[ExtendedAttribute]) -> None:
    attributes = list(attributes)
    for container, attribute in _each(parent, "ExtendedAttributes", attributes):
        element = _sub(container, "ExtendedAttribute", Name=attribute.name, Value=attribute.value)
        if attribute.text is not None:
            element.text = attribute.text
        if attribute.raw_xml:
            _append_raw_xml(element, attribute.raw_xml)


# --------------------------------------------------------------------------- data


def _write_data_type(parent: etree._Element, data_type: DataType) -> None:
    if isinstance(data_type, BasicType):
        basic = _sub(parent, "BasicType", Type=data_type.kind.value)
        for local, value in (("Length", data_type.length), ("Precision", data_type.precision),
                             ("Scale", data_type.scale)):
            if value is not None:
                _sub(basic, local, str(value))
    elif isinstance(data_type, DeclaredType):
        _sub(parent, "DeclaredType", Id=data_type.ref)
    elif isinstance(data_type, SchemaType):
        schema = _sub(parent, "SchemaType")
        if data_type.raw_xml:
            _append_raw_xml(schema, data_type.raw_xml)
    elif isinstance(data_type, ExternalReferenceType):
        _sub(parent, "ExternalReference", location=data_type.location, xref=data_type.xref,
             namespace=data_type.namespace)
    elif isinstance(data_type, (RecordType, UnionType)):
        record = _sub(parent, "RecordType" if isinstance(data_type, RecordType) else "UnionType")
        for index, member in enumerate(data_type.members, start=1):
            # XPDL 2.1 Members have no Name (the reader numbers them member1, member2…);
            # a real name is kept as the Name attribute some editors write.
            element = _sub(record, "Member")
            if member.name != f"member{index}":
                element.set("Name", member.name)
            _write_data_type(element, member.type)
    elif isinstance(data_type, EnumerationType):
        enumeration = _sub(parent, "EnumerationType")
        for enum_value in data_type.values:
            _sub(enumeration, "EnumerationValue", Name=enum_value)
    elif isinstance(data_type, ArrayType):
        array = _sub(parent, "ArrayType", LowerIndex=str(data_type.lower or 0),
                     UpperIndex=str(data_type.upper if data_type.upper is not None else 0))
        _write_data_type(array, data_type.element)
    elif isinstance(data_type, ListType):
        _write_data_type(_sub(parent, "ListType"), data_type.element)
    else:
        raise TypeError(f"cannot write data type {data_type!r}")


def _write_data_fields(parent: etree._Element, fields: tuple[DataField, ...]) -> None:
    for container, field in _each(parent, "DataFields", fields):
        element = _sub(container, "DataField", Id=field.id, Name=field.name,
                       ReadOnly=_bool(True) if field.read_only else None,
                       IsArray=_bool(True) if field.is_array else None,
                       Correlation=_bool(True) if field.correlation else None)
        _write_data_type(_sub(element, "DataType"), field.type)
        if field.initial_value is not None:
            _sub(element, "InitialValue", field.initial_value)
        elif field.initial is not None:
            _sub(element, "InitialValue", literal_text(field.initial))
        if field.description is not None:
            _sub(element, "Description", field.description)
        _write_extended(element, field.extended_attributes)


def _write_formal_parameters(parent: etree._Element, parameters: tuple[FormalParameter, ...]) -> None:
    for container, parameter in _each(parent, "FormalParameters", parameters):
        element = _sub(container, "FormalParameter", Id=parameter.id, Mode=parameter.mode.value,
                       Name=parameter.name,
                       Required=_bool(True) if parameter.required else None,
                       IsArray=_bool(True) if parameter.is_array else None)
        _write_data_type(_sub(element, "DataType"), parameter.type)
        if parameter.description is not None:
            _sub(element, "Description", parameter.description)


def _as_written(value: ActualParameter | Assignment) -> str | None:
    """An expression's text as the spec wrote it, else as opspec prints the parsed one."""
    if not value.text and value.expression is not None:
        return expression_text(value.expression)
    return value.text


def _write_actual_parameters(parent: etree._Element, parameters: tuple[ActualParameter, ...]) -> None:
    for container, parameter in _each(parent, "ActualParameters", parameters):
        _sub(container, "ActualParameter", _as_written(parameter))


def _write_assignments(parent: etree._Element, assignments: tuple[Assignment, ...]) -> None:
    for container, assignment in _each(parent, "Assignments", assignments):
        element = _sub(container, "Assignment", AssignTime=assignment.assign_time)
        _sub(element, "Target", assignment.target)
        _sub(element, "Expression", _as_written(assignment))


# --------------------------------------------------------------------------- resources


def _write_participants(parent: etree._Element, participants: tuple[Participant, ...]) -> None:
    for container, participant in _each(parent, "Participants", participants):
        element = _sub(container, "Participant", Id=participant.id, Name=participant.name)
        _sub(element, "ParticipantType", Type=participant.type.value)
        if participant.description is not None:
            _sub(element, "Description", participant.description)
        _write_extended(element, participant.extended_attributes)


_APPLICATION_TYPES = {"Script", "Xslt", "Form"}  # the XPDL 2.1 types with no required content


def _write_applications(parent: etree._Element, applications: tuple[Application, ...]) -> None:
    for container, application in _each(parent, "Applications", applications):
        element = _sub(container, "Application", Id=application.id, Name=application.name)
        if application.description is not None:
            _sub(element, "Description", application.description)
        if application.kind in _APPLICATION_TYPES:
            _sub(_sub(element, "Type"), application.kind)
        _write_formal_parameters(element, application.formal_parameters)
        if not application.formal_parameters:
            _sub(element, "FormalParameters")
        _write_extended(element, application.extended_attributes)


def _flatten_lanes(lanes: tuple[Lane, ...]) -> list[Lane]:
    out: list[Lane] = []
    for lane in lanes:
        out.append(lane)
        out.extend(_flatten_lanes(lane.lanes))
    return out


def _write_pools(parent: etree._Element, pools: tuple[Pool, ...]) -> None:
    for container, pool in _each(parent, "Pools", pools):
        element = _sub(container, "Pool", Id=pool.id, Name=pool.name, Process=pool.process,
                       Participant=pool.participant, BoundaryVisible=_bool(pool.boundary_visible))
        if pool.lanes:
            lanes = _sub(element, "Lanes")
            # XPDL 2.1 lanes are flat; nesting is stated by NestedLane references.
            for lane in _flatten_lanes(pool.lanes):
                lane_element = _sub(lanes, "Lane", Id=lane.id, Name=lane.name,
                                    ParentPool=lane.parent_pool)
                if lane.performers:
                    performers = _sub(lane_element, "Performers")
                    for performer in lane.performers:
                        _sub(performers, "Performer", performer)
                for nested in lane.lanes:
                    _sub(lane_element, "NestedLane", LaneId=nested.id)


# --------------------------------------------------------------------------- activities


_GATEWAY = {GatewayType.XOR: "Exclusive", GatewayType.EVENT: "Exclusive",
            GatewayType.AND: "Parallel", GatewayType.OR: "Inclusive",
            GatewayType.COMPLEX: "Complex"}

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
_NMTOKEN_BAD = re.compile(r"[^\w.:-]")


def _nmtoken(text: str) -> str:
    return _NMTOKEN_BAD.sub("_", text) or "_"


def _write_trigger_detail(parent: etree._Element, trigger: Trigger, name: str) -> None:
    """The trigger's child element (message, timer, condition…), when it has one."""
    kind = trigger.kind
    catch_throw = "CATCH" if trigger.catching else "THROW"
    if kind is TriggerKind.MESSAGE:
        element = _sub(parent, "TriggerResultMessage", CatchThrow=catch_throw)
        if trigger.name is not None:
            _sub(element, "Message", Id=_nmtoken(trigger.name), Name=trigger.name)
    elif kind is TriggerKind.TIMER and name == "Timer":
        element = _sub(parent, "TriggerTimer")
        if trigger.time_date is not None:
            _sub(element, "TimeDate", trigger.time_date)
        else:
            cycle = trigger.time_cycle
            if cycle is None and isinstance(trigger.duration, Literal) and isinstance(
                trigger.duration.value, (int, float)) and not isinstance(
                    trigger.duration.value, bool):
                cycle = duration_text(float(trigger.duration.value))
            _sub(element, "TimeCycle", cycle or "")
    elif kind is TriggerKind.RULE and name == "Conditional":
        element = _sub(parent, "TriggerConditional", ConditionName=trigger.name)
        if trigger.condition is not None:
            _sub(element, "Expression", expression_text(trigger.condition))
    elif kind is TriggerKind.SIGNAL and name == "Signal":
        element = _sub(parent, "TriggerResultSignal", Name=trigger.name, CatchThrow=catch_throw)
        _sub(element, "Properties")
    elif kind is TriggerKind.LINK and name == "Link":
        _sub(parent, "TriggerResultLink", Name=_nmtoken(trigger.name) if trigger.name else None,
             CatchThrow=catch_throw)
    elif kind is TriggerKind.ERROR and name == "Error":
        _sub(parent, "ResultError", ErrorCode=trigger.name)
    elif kind is TriggerKind.COMPENSATION and name == "Compensation":
        _sub(parent, "TriggerResultCompensation")
    elif kind is TriggerKind.CANCEL and name == "Cancel" and parent.tag == _q("IntermediateEvent"):
        _sub(parent, "TriggerResultCancel")


def _write_event(parent: etree._Element, event: Event) -> None:
    container = _sub(parent, "Event")
    trigger = event.trigger
    name = _TRIGGER_NAMES[trigger.kind]
    if event.position is EventPosition.START:
        name = name if name in _START_TRIGGERS else "None"
        element = _sub(container, "StartEvent", Trigger=name)
    elif event.position is EventPosition.INTERMEDIATE:
        name = name if name in _INTERMEDIATE_TRIGGERS else "None"
        element = _sub(container, "IntermediateEvent", Trigger=name,
                       Target=trigger.attached_to)
    else:
        result = event.result if event.result in _END_RESULTS else None
        name = result or (name if name in _END_RESULTS else "None")
        element = _sub(container, "EndEvent", Result=name)
    _write_trigger_detail(element, trigger, name)


_TASK_ELEMENTS = {
    TaskKind.MANUAL: "TaskManual", TaskKind.USER: "TaskUser", TaskKind.SCRIPT: "TaskScript",
    TaskKind.SERVICE: "TaskService", TaskKind.SEND: "TaskSend",
    TaskKind.RECEIVE: "TaskReceive", TaskKind.REFERENCE: "TaskReference",
    TaskKind.BUSINESS_RULE: "TaskService",   # XPDL 2.2 only; closest 2.1 form
}
_IMPLEMENTATIONS = {"WebService", "Other", "Unspecified"}


def _write_task(parent: etree._Element, task: Task, script_language: str | None) -> None:
    implementation = _sub(parent, "Implementation")
    if task.kind is TaskKind.APPLICATION:
        if len(task.applications) > 1:
            # XPDL 2.1 tasks call one application; several are only expressible as the
            # (deprecated, still schema-valid) XPDL 1.0 Tool list.
            for application in task.applications:
                tool = etree.SubElement(implementation, f"{{{XPDL10}}}Tool",
                                        Id=application.application, Type="APPLICATION")
                if application.actual_parameters:
                    params = etree.SubElement(tool, f"{{{XPDL10}}}ActualParameters")
                    for parameter in application.actual_parameters:
                        etree.SubElement(params, f"{{{XPDL10}}}ActualParameter").text = (
                            parameter.text)
            return
        element = _sub(_sub(implementation, "Task"), "TaskApplication")
        if task.applications:
            application = task.applications[0]
            element.set("Id", application.application)
            if application.package_ref is not None:
                element.set("PackageRef", application.package_ref)
            _write_actual_parameters(element, application.actual_parameters)
        else:
            element.set("Id", task.implementation or "_")
        return
    local = _TASK_ELEMENTS[task.kind]
    attrs: dict[str, str | None] = {}
    if local in ("TaskUser", "TaskService", "TaskSend", "TaskReceive") and (
        task.implementation in _IMPLEMENTATIONS
    ):
        attrs["Implementation"] = task.implementation
    if local == "TaskReceive":
        attrs["Instantiate"] = "false"
    if local == "TaskReference":
        attrs["TaskRef"] = task.implementation or task.message or "_"
    element = _sub(_sub(implementation, "Task"), local, **attrs)
    if local == "TaskScript":
        # Inside a task, Script is an ExpressionType: its language is ScriptType (the
        # package-level Script element is the one with a Type attribute).
        _sub(element, "Script", task.script or "", ScriptType=script_language)
    elif local in ("TaskSend", "TaskReceive") and task.message is not None:
        _sub(element, "Message", Id=_nmtoken(task.message), Name=task.message)
    elif local in ("TaskUser", "TaskService") and task.message is not None:
        _sub(element, "MessageIn", Id=_nmtoken(task.message), Name=task.message)


def _write_body(parent: etree._Element, activity: Activity, script_language: str | None) -> None:
    body = activity.body
    if isinstance(body, Route):
        attrs = {"GatewayType": _GATEWAY[body.gateway]}
        if body.gateway is GatewayType.EVENT:
            attrs["ExclusiveType"] = "Event"
        join = activity.join
        if join is not None and join.type is GatewayType.COMPLEX:
            text = join.condition_text
            if text is None and join.condition is not None:
                text = expression_text(join.condition)
            if text is not None:
                attrs["IncomingCondition"] = text
        _sub(parent, "Route", **attrs)
    elif isinstance(body, NoImplementation):
        _sub(_sub(parent, "Implementation"), "No")
    elif isinstance(body, Task):
        _write_task(parent, body, script_language)
    elif isinstance(body, SubFlow):
        element = _sub(_sub(parent, "Implementation"), "SubFlow", Id=body.process,
                       Execution=body.execution.value, PackageRef=body.package_ref)
        _write_actual_parameters(element, body.actual_parameters)
    elif isinstance(body, Reference):
        _sub(_sub(parent, "Implementation"), "Reference", ActivityId=body.activity)
    elif isinstance(body, BlockActivity):
        _sub(parent, "BlockActivity", ActivitySetId=body.activity_set,
             StartActivityId=body.start_activity)
    elif isinstance(body, Event):
        _write_event(parent, body)
    else:
        raise TypeError(f"cannot write activity body {body!r}")


def _write_activity(parent: etree._Element, activity: Activity, script_language: str | None) -> None:
    element = _sub(parent, "Activity", Id=activity.id, Name=activity.name)
    if activity.start_mode.value != "Automatic":
        element.set("StartMode", activity.start_mode.value)
    if activity.finish_mode.value != "Automatic":
        element.set("FinishMode", activity.finish_mode.value)
    if activity.start_quantity != 1:
        element.set("StartQuantity", str(activity.start_quantity))
    if activity.completion_quantity != 1:
        element.set("CompletionQuantity", str(activity.completion_quantity))
    if activity.description is not None:
        _sub(element, "Description", activity.description)
    _write_body(element, activity, script_language)
    if activity.performers:
        performers = _sub(element, "Performers")
        for performer in activity.performers:
            _sub(performers, "Performer", performer)
    if activity.priority is not None:
        _sub(element, "Priority", str(activity.priority))
    for deadline in activity.deadlines:
        deadline_element = _sub(element, "Deadline", Execution=deadline.execution.value)
        _sub(deadline_element, "DeadlineDuration", deadline.duration_text)
        if deadline.exception_name is not None:
            _sub(deadline_element, "ExceptionName", deadline.exception_name)
    if activity.join is not None or activity.split is not None:
        restriction = _sub(_sub(element, "TransitionRestrictions"), "TransitionRestriction")
        if activity.join is not None:
            join = _sub(restriction, "Join", Type=_GATEWAY[activity.join.type])
            if activity.join.type is GatewayType.EVENT:
                join.set("ExclusiveType", "Event")
        if activity.split is not None:
            split = _sub(restriction, "Split", Type=_GATEWAY[activity.split.type])
            if activity.split.type is GatewayType.EVENT:
                split.set("ExclusiveType", "Event")
            if activity.split.transition_refs:
                refs = _sub(split, "TransitionRefs")
                for ref in activity.split.transition_refs:
                    _sub(refs, "TransitionRef", Id=ref)
    generated = activity_directive_attributes(activity.directives)
    if activity.coordination is not None:
        generated.append(builtin_attribute(activity.coordination))
    _write_extended(element, merged_attributes(activity.extended_attributes, generated))
    if activity.loop is not None:
        loop = activity.loop
        condition = loop.condition_text
        if condition is None and loop.condition is not None:
            condition = expression_text(loop.condition)
        if loop.kind.value == "standard":
            loop_element = _sub(element, "Loop", LoopType="Standard")
            _sub(loop_element, "LoopStandard", LoopCondition=condition,
                 LoopMaximum=None if loop.maximum is None else str(loop.maximum),
                 TestTime="Before" if loop.test_before else "After")
        else:
            loop_element = _sub(element, "Loop", LoopType="MultiInstance")
            flow_condition = loop.flow_condition_text
            if flow_condition is None and loop.flow_condition is not None:
                flow_condition = expression_text(loop.flow_condition)
            _sub(loop_element, "LoopMultiInstance", MI_Condition=condition,
                 MI_Ordering="Parallel" if loop.parallel else "Sequential",
                 MI_FlowCondition=loop.flow.value, ComplexMI_FlowCondition=flow_condition)
    _write_assignments(element, activity.assignments)
    if activity.lane is not None:
        _sub(_sub(element, "NodeGraphicsInfos"), "NodeGraphicsInfo", LaneId=activity.lane)


def _condition_text(condition: Condition) -> str | None:
    if condition.text is not None:
        return condition.text
    if condition.expression is not None:
        return expression_text(condition.expression)
    return condition.exception_name


def _write_transitions(parent: etree._Element, transitions: tuple[Transition, ...]) -> None:
    for container, transition in _each(parent, "Transitions", transitions):
        element = _sub(container, "Transition", Id=transition.id, From=transition.source,
                       To=transition.target, Name=transition.name)
        if transition.quantity != 1:
            element.set("Quantity", str(transition.quantity))
        condition = transition.condition
        if condition.kind is not ConditionKind.NONE or condition.text:
            condition_element = _sub(element, "Condition")
            if condition.kind is not ConditionKind.NONE:
                condition_element.set("Type", condition.kind.value)
            text = _condition_text(condition)
            if condition.kind in (ConditionKind.CONDITION, ConditionKind.NONE):
                if text is not None:
                    expression = _sub(condition_element, "Expression", text)
                    if condition.kind is ConditionKind.NONE:    # a label, not an expression
                        expression.set("ScriptGrammar", "Text")
            elif text is not None:
                condition_element.text = text
        if transition.description is not None:
            _sub(element, "Description", transition.description)
        _write_extended(element, transition.extended_attributes)
        _write_assignments(element, transition.assignments)


def _write_activities(parent: etree._Element, activities: tuple[Activity, ...],
                      script_language: str | None) -> None:
    for container, activity in _each(parent, "Activities", activities):
        _write_activity(container, activity, script_language)


def _write_activity_sets(parent: etree._Element, sets: tuple[ActivitySet, ...],
                         script_language: str | None) -> None:
    for container, activity_set in _each(parent, "ActivitySets", sets):
        completion = activity_set.completion_condition_text
        if completion is None and activity_set.completion_condition is not None:
            completion = expression_text(activity_set.completion_condition)
        element = _sub(container, "ActivitySet", Id=activity_set.id, Name=activity_set.name,
                       AdHoc=_bool(True) if activity_set.ad_hoc else None,
                       AdHocOrdering="Sequential" if activity_set.ad_hoc_sequential else None,
                       AdHocCompletionCondition=completion)
        _write_activities(element, activity_set.activities, script_language)
        _write_transitions(element, activity_set.transitions)


def _write_process(parent: etree._Element, process: WorkflowProcess, package: Package) -> None:
    element = _sub(parent, "WorkflowProcess", Id=process.id, Name=process.name,
                   AccessLevel=process.access_level)
    header = process.header
    header_element = _sub(element, "ProcessHeader", DurationUnit=header.duration_unit)
    priority = header.priority if header.priority is not None else (
        None if process.priority is None else str(process.priority))
    description = header.description if header.description is not None else process.description
    for local, value in (("Created", header.created), ("Description", description),
                         ("Priority", priority), ("Limit", header.limit),
                         ("ValidFrom", header.valid_from), ("ValidTo", header.valid_to)):
        if value is not None:
            _sub(header_element, local, value)
    if header.waiting_time or header.working_time or header.duration:
        estimation = _sub(header_element, "TimeEstimation")
        for local, value in (("WaitingTime", header.waiting_time),
                             ("WorkingTime", header.working_time),
                             ("Duration", header.duration)):
            if value is not None:
                _sub(estimation, local, value)
    _write_formal_parameters(element, process.formal_parameters)
    _write_participants(element, process.participants)
    _write_applications(element, process.applications)
    _write_data_fields(element, process.data_fields)
    _write_activity_sets(element, process.activity_sets, package.script_language)
    _write_activities(element, process.activities, package.script_language)
    _write_transitions(element, process.transitions)
    _write_extended(element, merged_attributes(process.extended_attributes,
                                     process_directive_attributes(process.directives)))
    _write_assignments(element, process.assignments)


# --------------------------------------------------------------------------- package


def build_tree(package: Package) -> etree._Element:
    """The ``Package`` element of ``package`` (for callers that post-process the tree)."""
    root = etree.Element(_q("Package"), nsmap=_NSMAP)
    root.set("Id", package.id)
    if package.name is not None:
        root.set("Name", package.name)
    header = package.header
    header_element = _sub(root, "PackageHeader")
    _sub(header_element, "XPDLVersion", "2.1")
    _sub(header_element, "Vendor", header.vendor or "opspec")
    _sub(header_element, "Created", header.created or "")
    description = header.description if header.description is not None else package.description
    for local, value in (("ModificationDate", header.modified), ("Description", description),
                         ("Documentation", header.documentation),
                         ("PriorityUnit", header.priority_unit),
                         ("CostUnit", header.cost_unit)):
        if value is not None:
            _sub(header_element, local, value)
    if package.conformance_class is not None:
        _sub(root, "ConformanceClass", GraphConformance=package.conformance_class)
    if package.script_language is not None:
        _sub(root, "Script", Type=package.script_language)
    if package.external_packages:
        container = _sub(root, "ExternalPackages")
        for external in package.external_packages:
            element = _sub(container, "ExternalPackage", href=external.href, Id=external.id,
                           Name=external.name)
            _write_extended(element, external.extended_attributes)
    if package.type_declarations:
        container = _sub(root, "TypeDeclarations")
        for declaration in package.type_declarations:
            _write_type_declaration(container, declaration)
    _write_participants(root, package.participants)
    _write_applications(root, package.applications)
    _write_data_fields(root, package.data_fields)
    _write_pools(root, package.pools)
    if package.processes:
        container = _sub(root, "WorkflowProcesses")
        for process in package.processes:
            _write_process(container, process, package)
    _write_extended(root, merged_attributes(package.extended_attributes,
                                  package_directive_attributes(package)))
    return root


def _write_type_declaration(parent: etree._Element, declaration: TypeDeclaration) -> None:
    element = _sub(parent, "TypeDeclaration", Id=declaration.id, Name=declaration.name)
    _write_data_type(element, declaration.type)
    if declaration.description is not None:
        _sub(element, "Description", declaration.description)
    _write_extended(element, declaration.extended_attributes)


def write_xpdl(package: Package) -> bytes:
    """``package`` as a standard XPDL 2.1 document (UTF-8, with an XML declaration)."""
    root = build_tree(_abstract_tasks_automatic(package))
    etree.cleanup_namespaces(root, keep_ns_prefixes=["opspec"])
    data: bytes = etree.tostring(root, xml_declaration=True, encoding="UTF-8",
                                 pretty_print=True)
    return data



def _abstract_tasks_automatic(package: Package) -> Package:
    """A package read from BPMN, its abstract tasks (no implementation) automatic in writing.

    BPMN 2.0 §10.2.3: a Task "not further specified" runs by itself, while XPDL 2.1 §7.6.5.1
    reads an activity without an implementation performed by a person (a lane's ROLE
    participant) as manual work; so the XPDL written says opspec:AutoRun="true" for each such
    activity, and runs as the BPMN file did."""
    if not package.source_format.upper().startswith("BPMN"):
        return package
    # the same package, read as XPDL reads it: which activities would turn into manual work
    as_xpdl = dataclasses.replace(package, header=dataclasses.replace(
        package.header, source_format=None))

    def automatic(activities: tuple[Activity, ...], process: WorkflowProcess
                  ) -> tuple[Activity, ...]:
        return tuple(
            dataclasses.replace(a, directives=dataclasses.replace(a.directives, auto_run=True))
            if isinstance(a.body, NoImplementation) and a.directives.auto_run is None
            and not a.is_manual and as_xpdl.is_manual_work(a, process) else a
            for a in activities)

    processes = tuple(dataclasses.replace(
        process, activities=automatic(process.activities, process),
        activity_sets=tuple(dataclasses.replace(s, activities=automatic(s.activities, process))
                            for s in process.activity_sets))
        for process in package.processes)
    return dataclasses.replace(package, processes=processes)
