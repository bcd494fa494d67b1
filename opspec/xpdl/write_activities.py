"""Writing one activity as XPDL 2.1: its body (a route with its gateway type, a task and
its implementation, a subflow, a reference, a block activity, or an event, written by
:mod:`opspec.xpdl.write_events`), then its performers, priority, deadlines, join and split,
extended attributes with the SISARL directives (:mod:`opspec.xpdl.sisarl_write`), loop,
assignments and lane.
"""

from __future__ import annotations

from lxml import etree

from opspec.model import (
    Activity,
    BlockActivity,
    Event,
    GatewayType,
    NoImplementation,
    Reference,
    Route,
    SubFlow,
    Task,
    TaskKind,
)
from opspec.xpdl.sisarl_write import (
    activity_directive_attributes,
    builtin_attribute,
    expression_text,
    merged_attributes,
)
from opspec.xpdl.write_data import write_actual_parameters, write_assignments
from opspec.xpdl.write_elements import XPDL10, nmtoken, sub, write_extended
from opspec.xpdl.write_events import write_event

__all__ = [
    "write_activity",
]

_GATEWAY = {GatewayType.XOR: "Exclusive", GatewayType.EVENT: "Exclusive",
            GatewayType.AND: "Parallel", GatewayType.OR: "Inclusive",
            GatewayType.COMPLEX: "Complex"}


_TASK_ELEMENTS = {
    TaskKind.MANUAL: "TaskManual", TaskKind.USER: "TaskUser", TaskKind.SCRIPT: "TaskScript",
    TaskKind.SERVICE: "TaskService", TaskKind.SEND: "TaskSend",
    TaskKind.RECEIVE: "TaskReceive", TaskKind.REFERENCE: "TaskReference",
    TaskKind.BUSINESS_RULE: "TaskService",   # XPDL 2.2 only; closest 2.1 form
}
_IMPLEMENTATIONS = {"WebService", "Other", "Unspecified"}


def _write_task(parent: etree._Element, task: Task, script_language: str | None) -> None:
    implementation = sub(parent, "Implementation")
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
        element = sub(sub(implementation, "Task"), "TaskApplication")
        if task.applications:
            application = task.applications[0]
            element.set("Id", application.application)
            if application.package_ref is not None:
                element.set("PackageRef", application.package_ref)
            write_actual_parameters(element, application.actual_parameters)
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
    element = sub(sub(implementation, "Task"), local, **attrs)
    if local == "TaskScript":
        # Inside a task, Script is an ExpressionType: its language is ScriptType (the
        # package-level Script element is the one with a Type attribute).
        sub(element, "Script", task.script or "", ScriptType=script_language)
    elif local in ("TaskSend", "TaskReceive") and task.message is not None:
        sub(element, "Message", Id=nmtoken(task.message), Name=task.message)
    elif local in ("TaskUser", "TaskService") and task.message is not None:
        sub(element, "MessageIn", Id=nmtoken(task.message), Name=task.message)


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
        sub(parent, "Route", **attrs)
    elif isinstance(body, NoImplementation):
        sub(sub(parent, "Implementation"), "No")
    elif isinstance(body, Task):
        _write_task(parent, body, script_language)
    elif isinstance(body, SubFlow):
        element = sub(sub(parent, "Implementation"), "SubFlow", Id=body.process,
                      Execution=body.execution.value, PackageRef=body.package_ref)
        write_actual_parameters(element, body.actual_parameters)
    elif isinstance(body, Reference):
        sub(sub(parent, "Implementation"), "Reference", ActivityId=body.activity)
    elif isinstance(body, BlockActivity):
        sub(parent, "BlockActivity", ActivitySetId=body.activity_set,
            StartActivityId=body.start_activity)
    elif isinstance(body, Event):
        write_event(parent, body)
    else:
        raise TypeError(f"cannot write activity body {body!r}")


def write_activity(parent: etree._Element, activity: Activity, script_language: str | None) -> None:
    element = sub(parent, "Activity", Id=activity.id, Name=activity.name)
    if activity.start_mode.value != "Automatic":
        element.set("StartMode", activity.start_mode.value)
    if activity.finish_mode.value != "Automatic":
        element.set("FinishMode", activity.finish_mode.value)
    if activity.start_quantity != 1:
        element.set("StartQuantity", str(activity.start_quantity))
    if activity.completion_quantity != 1:
        element.set("CompletionQuantity", str(activity.completion_quantity))
    if activity.marked_start:
        element.set("StartActivity", "true")
    if activity.description is not None:
        sub(element, "Description", activity.description)
    _write_body(element, activity, script_language)
    if activity.performers:
        performers = sub(element, "Performers")
        for performer in activity.performers:
            sub(performers, "Performer", performer)
    if activity.priority is not None:
        sub(element, "Priority", str(activity.priority))
    for deadline in activity.deadlines:
        deadline_element = sub(element, "Deadline", Execution=deadline.execution.value)
        sub(deadline_element, "DeadlineDuration", deadline.duration_text)
        if deadline.exception_name is not None:
            sub(deadline_element, "ExceptionName", deadline.exception_name)
    if activity.join is not None or activity.split is not None:
        restriction = sub(sub(element, "TransitionRestrictions"), "TransitionRestriction")
        if activity.join is not None:
            join = sub(restriction, "Join", Type=_GATEWAY[activity.join.type])
            if activity.join.type is GatewayType.EVENT:
                join.set("ExclusiveType", "Event")
        if activity.split is not None:
            split = sub(restriction, "Split", Type=_GATEWAY[activity.split.type])
            if activity.split.type is GatewayType.EVENT:
                split.set("ExclusiveType", "Event")
            if activity.split.transition_refs:
                refs = sub(split, "TransitionRefs")
                for ref in activity.split.transition_refs:
                    sub(refs, "TransitionRef", Id=ref)
    generated = activity_directive_attributes(activity.directives)
    if activity.coordination is not None:
        generated.append(builtin_attribute(activity.coordination))
    write_extended(element, merged_attributes(activity.extended_attributes, generated))
    if activity.loop is not None:
        loop = activity.loop
        condition = loop.condition_text
        if condition is None and loop.condition is not None:
            condition = expression_text(loop.condition)
        if loop.kind.value == "standard":
            loop_element = sub(element, "Loop", LoopType="Standard")
            sub(loop_element, "LoopStandard", LoopCondition=condition,
                LoopMaximum=None if loop.maximum is None else str(loop.maximum),
                TestTime="Before" if loop.test_before else "After")
        else:
            loop_element = sub(element, "Loop", LoopType="MultiInstance")
            flow_condition = loop.flow_condition_text
            if flow_condition is None and loop.flow_condition is not None:
                flow_condition = expression_text(loop.flow_condition)
            sub(loop_element, "LoopMultiInstance", MI_Condition=condition,
                MI_Ordering="Parallel" if loop.parallel else "Sequential",
                MI_FlowCondition=loop.flow.value, ComplexMI_FlowCondition=flow_condition)
    write_assignments(element, activity.assignments)
    if activity.lane is not None:
        sub(sub(element, "NodeGraphicsInfos"), "NodeGraphicsInfo", LaneId=activity.lane)
