"""Writing a workflow process as XPDL 2.1: its header (with the time estimation), formal
parameters, participants, applications, data fields, activity sets (ad hoc, with their
completion condition), activities, transitions with their conditions, extended attributes with
the process's SISARL directives, and assignments.
"""

from __future__ import annotations

from lxml import etree

from opspec.model import (
    Activity,
    ActivitySet,
    Condition,
    ConditionKind,
    Package,
    Transition,
    WorkflowProcess,
)
from opspec.xpdl.sisarl_write import (
    expression_text,
    merged_attributes,
    process_directive_attributes,
)
from opspec.xpdl.write_activities import write_activity
from opspec.xpdl.write_data import write_assignments, write_data_fields, write_formal_parameters
from opspec.xpdl.write_elements import each, sub, write_extended, xml_bool
from opspec.xpdl.write_resources import write_applications, write_participants

__all__ = [
    "write_process",
]


def _condition_text(condition: Condition) -> str | None:
    if condition.text is not None:
        return condition.text
    if condition.expression is not None:
        return expression_text(condition.expression)
    return condition.exception_name


def _write_transitions(parent: etree._Element, transitions: tuple[Transition, ...]) -> None:
    for container, transition in each(parent, "Transitions", transitions):
        element = sub(container, "Transition", Id=transition.id, From=transition.source,
                      To=transition.target, Name=transition.name)
        if transition.quantity != 1:
            element.set("Quantity", str(transition.quantity))
        condition = transition.condition
        if condition.kind is not ConditionKind.NONE or condition.text:
            condition_element = sub(element, "Condition")
            if condition.kind is not ConditionKind.NONE:
                condition_element.set("Type", condition.kind.value)
            text = _condition_text(condition)
            if condition.kind in (ConditionKind.CONDITION, ConditionKind.NONE):
                if text is not None:
                    expression = sub(condition_element, "Expression", text)
                    if condition.kind is ConditionKind.NONE:    # a label, not an expression
                        expression.set("ScriptGrammar", "Text")
            elif text is not None:
                condition_element.text = text
        if transition.description is not None:
            sub(element, "Description", transition.description)
        write_extended(element, transition.extended_attributes)
        write_assignments(element, transition.assignments)


def _write_activities(parent: etree._Element, activities: tuple[Activity, ...],
                      script_language: str | None) -> None:
    for container, activity in each(parent, "Activities", activities):
        write_activity(container, activity, script_language)


def _write_activity_sets(parent: etree._Element, sets: tuple[ActivitySet, ...],
                         script_language: str | None) -> None:
    for container, activity_set in each(parent, "ActivitySets", sets):
        completion = activity_set.completion_condition_text
        if completion is None and activity_set.completion_condition is not None:
            completion = expression_text(activity_set.completion_condition)
        element = sub(container, "ActivitySet", Id=activity_set.id, Name=activity_set.name,
                      AdHoc=xml_bool(True) if activity_set.ad_hoc else None,
                      AdHocOrdering="Sequential" if activity_set.ad_hoc_sequential else None,
                      AdHocCompletionCondition=completion)
        _write_activities(element, activity_set.activities, script_language)
        _write_transitions(element, activity_set.transitions)


def write_process(parent: etree._Element, process: WorkflowProcess, package: Package) -> None:
    element = sub(parent, "WorkflowProcess", Id=process.id, Name=process.name,
                  AccessLevel=process.access_level)
    header = process.header
    header_element = sub(element, "ProcessHeader", DurationUnit=header.duration_unit)
    priority = header.priority if header.priority is not None else (
        None if process.priority is None else str(process.priority))
    description = header.description if header.description is not None else process.description
    for local, value in (("Created", header.created), ("Description", description),
                         ("Priority", priority), ("Limit", header.limit),
                         ("ValidFrom", header.valid_from), ("ValidTo", header.valid_to)):
        if value is not None:
            sub(header_element, local, value)
    if header.waiting_time or header.working_time or header.duration:
        estimation = sub(header_element, "TimeEstimation")
        for local, value in (("WaitingTime", header.waiting_time),
                             ("WorkingTime", header.working_time),
                             ("Duration", header.duration)):
            if value is not None:
                sub(estimation, local, value)
    write_formal_parameters(element, process.formal_parameters)
    write_participants(element, process.participants)
    write_applications(element, process.applications)
    write_data_fields(element, process.data_fields)
    _write_activity_sets(element, process.activity_sets, package.script_language)
    _write_activities(element, process.activities, package.script_language)
    _write_transitions(element, process.transitions)
    write_extended(element, merged_attributes(process.extended_attributes,
                                              process_directive_attributes(process.directives)))
    write_assignments(element, process.assignments)
