"""Handlers for workflow processes, their headers, activity sets and transitions."""

from __future__ import annotations

from typing import Any

from lxml import etree

from opspec.model.process import (
    ActivitySet,
    Condition,
    ConditionKind,
    ProcessHeader,
    Transition,
    WorkflowProcess,
)
from opspec.xpdl.handlers.activities import build_activity, build_assignments
from opspec.xpdl.handlers.common import (
    BuildContext,
    attr,
    base_fields,
    child,
    child_text,
    children,
    grandchildren,
    local_name,
    parse_bool,
    parse_int,
    quantity,
)
from opspec.xpdl.handlers.data import build_data_field, build_formal_parameter
from opspec.xpdl.handlers.events import parse_condition_element
from opspec.xpdl.handlers.resources import build_application, build_participant
from opspec.xpdl.sisarl import process_directives
from opspec.xpdl.sisarl_values import parse_probability

__all__ = ["build_condition", "build_process", "build_transition"]


# A transition without Condition (shared: the model is immutable).
_NO_CONDITION = Condition()


def build_condition(element: etree._Element | None, ctx: BuildContext) -> Condition:
    """A transition ``Condition`` (its text is in ``Expression`` after normalising)."""
    if element is None:
        return _NO_CONDITION
    expression = child(element, "Expression")
    source = expression if expression is not None else element
    text = "".join(source.itertext()).strip() or None
    raw = (attr(element, "Type") or "").upper()
    if raw and raw not in ConditionKind.__members__:
        ctx.warning(element, "unknown-condition-type", f"unknown Condition Type {raw!r}",
                    "use CONDITION, OTHERWISE, EXCEPTION or DEFAULTEXCEPTION")
        raw = ""
    if not raw:
        raw = "CONDITION" if text else "NONE"
    kind = ConditionKind[raw]
    if kind is ConditionKind.CONDITION:
        if text is None:
            return Condition()  # CONDITION with nothing written: unconditional
        grammar = attr(expression, "ScriptGrammar") if expression is not None else None
        if grammar is not None and grammar.strip().lower() == "text":
            # TIBCO's free-text conditions: a label for people, not an expression
            ctx.warning(element, "text-condition",
                        f"condition {text!r} is written with ScriptGrammar=\"Text\": a label, "
                        "not an expression: at an XOR split whose branches are all labelled, the "
                        "performer of the deciding activity picks the branch (with nobody bound "
                        "to it, the branch is drawn at random from the run's seed)",
                        "write the condition as an expression over data fields (and drop "
                        "ScriptGrammar=\"Text\") for opspec to decide the branch")
            return Condition(text=text)
        parsed = parse_condition_element(expression if expression is not None else element,
                                         text, ctx, "transition condition")
        return Condition(kind=kind, text=text, expression=parsed)
    if kind is ConditionKind.EXCEPTION:
        return Condition(kind=kind, text=text, exception_name=text)
    return Condition(kind=kind, text=text)


def build_transition(element: etree._Element, ctx: BuildContext) -> Transition:
    fields = base_fields(element, ctx, kind="Transition")
    source, target = attr(element, "From"), attr(element, "To")
    for name, value in (("From", source), ("To", target)):
        if value is None:
            ctx.error(element, "missing-transition-end", f"Transition {fields['id']!r} has no {name}",
                      f"set {name} to the Id of an activity")
    tokens = quantity(element, "Quantity", ctx)
    if not len(element):        # no Condition, no Assignments (most transitions)
        return Transition(source=source or "", target=target or "", condition=_NO_CONDITION,
                          quantity=tokens, **fields)
    return Transition(source=source or "", target=target or "",
                      condition=build_condition(child(element, "Condition"), ctx),
                      assignments=build_assignments(element, ctx), quantity=tokens,
                      probability=_probability(element, fields, ctx), **fields)


def _probability(element: etree._Element, fields: dict[str, Any], ctx: BuildContext
                 ) -> float | None:
    """The branch probability an ``opspec:Probability`` extended attribute gives (what
    opspec writes for a BPMN gateway the diagram left undecided: docs/bpmn.md)."""
    for extended in fields.get("extended_attributes", ()):
        if extended.name in ("opspec:Probability", "Probability"):
            raw = extended.value if extended.value is not None else (extended.text or "")
            value = parse_probability(raw)
            if value is None:
                ctx.error(element, "bad-probability",
                          f"opspec:Probability {raw!r} of transition {fields['id']!r} is not a "
                          "number between 0 and 1", "write a probability such as 0.25")
            return value
    return None


def _transition_elements(element: etree._Element, ctx: BuildContext) -> list[etree._Element]:
    """``Transitions/Transition``, plus Transitions found in a misnamed wrapper (one exporter
    writes ``<Transactions>``): tolerated with a warning so no flow is silently lost."""
    found = grandchildren(element, "Transitions", "Transition")
    for wrapper in element:
        if not isinstance(wrapper.tag, str) or local_name(wrapper) in ("Transitions", "Activities"):
            continue
        stray = children(wrapper, "Transition")
        if stray:
            ctx.warning(wrapper, "misplaced-element",
                        f"Transition elements inside <{local_name(wrapper)}>; read as if inside "
                        "<Transitions>", "rename the wrapper element to Transitions")
            found.extend(stray)
    return found


def _activities(element: etree._Element, ctx: BuildContext) -> dict[str, object]:
    return {
        "activities": ctx.each(grandchildren(element, "Activities", "Activity"), build_activity),
        "transitions": ctx.each(_transition_elements(element, ctx), build_transition),
    }


def _activity_set(element: etree._Element, ctx: BuildContext) -> ActivitySet:
    fields = base_fields(element, ctx, kind="ActivitySet")
    ad_hoc = parse_bool(attr(element, "AdHoc")) or False
    ordering = (attr(element, "AdHocOrdering") or "Parallel").lower()
    if ad_hoc and ordering not in ("parallel", "sequential"):
        ctx.error(element, "bad-ad-hoc", f"AdHocOrdering {ordering!r} is neither Parallel nor "
                  "Sequential", "write Parallel or Sequential")
    completion = attr(element, "AdHocCompletionCondition") if ad_hoc else None
    return ActivitySet(ad_hoc=ad_hoc, ad_hoc_sequential=ad_hoc and ordering == "sequential",
                       completion_condition_text=completion,
                       completion_condition=parse_condition_element(
                           element, completion, ctx, "AdHocCompletionCondition"),
                       **_activities(element, ctx), **fields)  # type: ignore[arg-type]


def _header(element: etree._Element | None) -> ProcessHeader:
    if element is None:
        return ProcessHeader()
    estimation = child(element, "TimeEstimation")
    source = estimation if estimation is not None else element
    return ProcessHeader(
        created=child_text(element, "Created"),
        description=child_text(element, "Description"),
        priority=child_text(element, "Priority"),
        limit=child_text(element, "Limit"),
        valid_from=child_text(element, "ValidFrom"),
        valid_to=child_text(element, "ValidTo"),
        duration=child_text(source, "Duration"),
        duration_unit=attr(element, "DurationUnit"),
        waiting_time=child_text(source, "WaitingTime"),
        working_time=child_text(source, "WorkingTime"),
    )


def build_process(element: etree._Element, ctx: BuildContext) -> WorkflowProcess:
    fields = base_fields(element, ctx, kind="WorkflowProcess")
    header = _header(child(element, "ProcessHeader"))
    priority = parse_int(header.priority)
    if header.priority is not None and priority is None:
        ctx.warning(child(element, "ProcessHeader"), "bad-priority",
                    f"process priority {header.priority!r} is not an integer; ignored",
                    "write an integer")
    return WorkflowProcess(
        header=header,
        access_level=attr(element, "AccessLevel"),
        data_fields=ctx.each(grandchildren(element, "DataFields", "DataField"), build_data_field),
        formal_parameters=ctx.each(grandchildren(element, "FormalParameters", "FormalParameter"),
                                   build_formal_parameter),
        participants=ctx.each(grandchildren(element, "Participants", "Participant"),
                              build_participant),
        applications=ctx.each(grandchildren(element, "Applications", "Application"),
                              build_application),
        activity_sets=ctx.each(grandchildren(element, "ActivitySets", "ActivitySet"), _activity_set),
        directives=process_directives(element, ctx),
        priority=priority,
        assignments=build_assignments(element, ctx),
        **_activities(element, ctx),  # type: ignore[arg-type]
        **fields,
    )
