"""The Activity handler: body, performers, modes, priority, deadlines, loop, restrictions,
lane, assignments and SISARL directives of one activity."""

from __future__ import annotations

import dataclasses

from lxml import etree

from opspec.clock import DURATION_HINT, parse_duration
from opspec.errors import Severity, SpecError
from opspec.model.activities import (
    Activity,
    ActivityBody,
    Deadline,
    Execution,
    GatewayType,
    Join,
    Loop,
    LoopKind,
    MIFlow,
    Mode,
    NoImplementation,
    Route,
    Split,
)
from opspec.model.data import Assignment
from opspec.model.expressions import Expression
from opspec.xpdl.conditions import ConditionSyntaxError
from opspec.xpdl.handlers.bodies import BODIES, gateway_type
from opspec.xpdl.handlers.common import (
    BuildContext,
    attr,
    base_fields,
    child,
    children,
    children_by_tag,
    grandchildren,
    parse_int,
    quantity,
    text_of,
)
from opspec.xpdl.handlers.events import parse_condition_element
from opspec.xpdl.handlers.resources import performers_of
from opspec.xpdl.namespaces import qname
from opspec.xpdl.sisarl import activity_directives

__all__ = ["build_activity", "build_assignment", "build_assignments", "read_expression"]


def _mode(element: etree._Element, name: str, ctx: BuildContext) -> Mode:
    raw = attr(element, name)
    if raw is None:
        return Mode.AUTOMATIC
    for mode in Mode:
        if raw.lower() == mode.value.lower():
            return mode
    ctx.warning(element, "bad-mode", f"unknown {name} {raw!r}; Automatic assumed",
                "use Automatic or Manual")
    return Mode.AUTOMATIC


def _expression_text(element: etree._Element | None) -> str | None:
    if element is None:
        return None
    expression = child(element, "Expression")
    source = expression if expression is not None else element
    return "".join(source.itertext()).strip() or None


def _deadlines(element: etree._Element, ctx: BuildContext) -> tuple[Deadline, ...]:
    found = children(element, "Deadline")
    if not found:
        return ()
    from opspec.xpdl.durations import parse_duration_expression

    out: list[Deadline] = []
    for deadline in found:
        duration_element = child(deadline, "DeadlineDuration")
        text = _expression_text(duration_element) or ""
        duration = None
        if text:
            try:
                duration = parse_duration_expression(text)
            except (SpecError, ValueError, RecursionError) as error:
                refusal = _misspelt_duration(text, error)
                # the engine cannot run either kind; a misspelt duration is refused here, at
                # once (validate then leaves the engine's checks out, so this is the one
                # message); a script in another language (JaWE's JavaScript) the engine
                # refuses, naming the package's script language
                if refusal is not None:
                    ctx.error(duration_element, "bad-deadline", f"Deadline: {refusal}",
                              _DEADLINE_HINT)
        else:
            ctx.warning(deadline, "bad-deadline", "Deadline has no duration; it never expires",
                        "add <DeadlineDuration>PT5M</DeadlineDuration>")
        raw = (attr(deadline, "Execution") or "ASYNCHR").upper()
        execution = Execution.SYNCHR if raw == "SYNCHR" else Execution.ASYNCHR
        out.append(Deadline(duration_text=text, duration=duration, execution=execution,
                            exception_name=text_of(child(deadline, "ExceptionName")),
                            location=ctx.loc(deadline)))
    return tuple(out)


_DEADLINE_HINT = (f"{DURATION_HINT}, or an expression over data fields giving seconds "
                  "(timeout * 60)")


def _misspelt_duration(text: str, error: Exception) -> str | None:
    """The duration grammar's refusal of a DeadlineDuration meant as a duration (``10
    minuts``, ``-5``), or ``None`` for an expression opspec cannot read (``timeout *``,
    JavaScript). XPDL's DeadlineDuration is an Expression, so ``timeout * 60`` is a deadline,
    and so is ``timeout`` alone. (:func:`~opspec.xpdl.durations.parse_duration_expression`
    refuses text meant as a duration with the duration grammar's own message.)"""
    if isinstance(error, ConditionSyntaxError):
        return None
    if isinstance(error, SpecError):
        return error.message           # the duration grammar's (misspelt, negative, too large)
    try:
        parse_duration(text)
    except SpecError as refusal:
        return refusal.message
    return None


def _loop(element: etree._Element, ctx: BuildContext) -> Loop | None:
    loop = child(element, "Loop")
    if loop is None:
        return None
    kind_text = (attr(loop, "LoopType") or "").lower()
    if kind_text == "standard" or (not kind_text and child(loop, "LoopStandard") is not None):
        detail = child(loop, "LoopStandard")
        if detail is None:
            return Loop(kind=LoopKind.STANDARD)
        text = attr(detail, "LoopCondition") or _expression_text(child(detail, "LoopCondition"))
        return Loop(kind=LoopKind.STANDARD, condition_text=text,
                    condition=parse_condition_element(detail, text, ctx, "loop condition"),
                    maximum=parse_int(attr(detail, "LoopMaximum")),
                    test_before=(attr(detail, "TestTime") or "After").lower() == "before")
    if kind_text == "multiinstance" or (not kind_text and child(loop, "LoopMultiInstance") is not None):
        detail = child(loop, "LoopMultiInstance")
        if detail is None:
            ctx.error(loop, "bad-multi-instance", "a MultiInstance Loop has no LoopMultiInstance "
                      "element, so the number of instances is unknown",
                      'add <LoopMultiInstance MI_Condition="N" MI_Ordering="Parallel"/>')
            return Loop(kind=LoopKind.MULTI_INSTANCE)
        text = attr(detail, "MI_Condition") or _expression_text(child(detail, "MI_Condition"))
        ordering = (attr(detail, "MI_Ordering") or "Sequential").lower()
        if ordering not in ("sequential", "parallel"):
            ctx.error(detail, "bad-multi-instance", f"MI_Ordering {ordering!r} is neither "
                      "Sequential nor Parallel", "write Sequential or Parallel")
        flow_text = attr(detail, "MI_FlowCondition") or "All"
        flow = {f.value.lower(): f for f in MIFlow}.get(flow_text.lower())
        if flow is None:
            ctx.error(detail, "bad-multi-instance", f"MI_FlowCondition {flow_text!r} is not "
                      "None, One, All or Complex", "write one of None, One, All, Complex")
            flow = MIFlow.ALL
        complex_text = (attr(detail, "ComplexMI_FlowCondition")
                        or _expression_text(child(detail, "ComplexMI_FlowCondition")))
        if flow is MIFlow.COMPLEX and not (complex_text or "").strip():
            ctx.error(detail, "bad-multi-instance", "MI_FlowCondition is Complex but there is no "
                      "ComplexMI_FlowCondition", "give the condition (over data fields and "
                      "nrOfInstances, nrOfCompletedInstances, nrOfActiveInstances)")
        return Loop(kind=LoopKind.MULTI_INSTANCE, condition_text=text,
                    condition=read_expression(detail, text, ctx, "multi-instance count"),
                    parallel=ordering == "parallel", flow=flow,
                    flow_condition_text=complex_text,
                    flow_condition=(read_expression(detail, complex_text, ctx,
                                                    "ComplexMI_FlowCondition")
                                    if flow is MIFlow.COMPLEX else None))
    return None  # LoopType="None"


def read_expression(element: etree._Element | None, text: str | None, ctx: BuildContext,
                    what: str, *, severity: Severity = Severity.WARNING,
                    hint: str = "write an expression over data fields") -> Expression | None:
    """``text`` as an expression over data fields, located at ``element``'s line; ``None``
    without text, or when it cannot be read (then a ``bad-expression`` diagnostic of
    ``severity`` says why). The XPDL and BPMN readers' loop, multi-instance and gateway
    expressions all come through here."""
    from opspec.xpdl.conditions import parse_expression

    if text is None:
        return None
    try:
        return parse_expression(text, location=ctx.loc(element))
    except (SpecError, ValueError, RecursionError) as error:
        ctx.report(element, severity, "bad-expression", f"{what} {text!r} cannot be "
                   f"understood: {getattr(error, 'message', error)}", hint)
        return None


def build_assignments(element: etree._Element, ctx: BuildContext) -> tuple[Assignment, ...]:
    """``element/Assignments/Assignment`` (XPDL 2.1): Target := Expression at AssignTime."""
    found = grandchildren(element, "Assignments", "Assignment")
    out: list[Assignment] = []
    for assignment in found:
        target = _expression_text(child(assignment, "Target"))
        text = _expression_text(child(assignment, "Expression")) or ""
        if target is None:
            ctx.warning(assignment, "bad-assignment", "Assignment has no Target; it is ignored",
                        "add <Target>data_field</Target>")
            continue
        out.append(build_assignment(assignment, ctx, target, text,
                                    attr(assignment, "AssignTime") or "End"))
    return tuple(out)


def build_assignment(element: etree._Element, ctx: BuildContext, target: str, text: str,
                     assign_time: str) -> Assignment:
    """``target := text`` (an XPDL Assignment or a BPMN ``opspec:Assignment``); text that is
    no expression is a ``bad-assignment`` warning and kept as text only."""
    from opspec.xpdl.conditions import parse_expression

    expression = None
    if text:
        try:
            expression = parse_expression(text, location=ctx.loc(element))
        except (SpecError, ValueError, RecursionError) as error:
            ctx.warning(element, "bad-assignment", f"assignment to {target!r} of {text!r} "
                        f"cannot be understood: {getattr(error, 'message', error)}",
                        "write an expression over data fields")
    return Assignment(target=target, text=text, expression=expression, assign_time=assign_time,
                      location=ctx.loc(element))


def _restrictions(element: etree._Element, ctx: BuildContext) -> tuple[Join | None, Split | None]:
    join: Join | None = None
    split: Split | None = None
    for restriction in grandchildren(element, "TransitionRestrictions", "TransitionRestriction"):
        join_element = child(restriction, "Join")
        if join_element is not None and join is None:
            join = Join(type=gateway_type(join_element, "Type", ctx) or GatewayType.XOR)
        split_element = child(restriction, "Split")
        if split_element is not None and split is None:
            refs = tuple(ref_id for ref in grandchildren(split_element, "TransitionRefs", "TransitionRef")
                         if (ref_id := attr(ref, "Id")) is not None)
            split = Split(type=gateway_type(split_element, "Type", ctx) or GatewayType.XOR,
                          transition_refs=refs)
    return join, split


def _lane(element: etree._Element) -> str | None:
    for info in grandchildren(element, "NodeGraphicsInfos", "NodeGraphicsInfo"):
        lane = attr(info, "LaneId")
        if lane is not None:
            return lane
    return None


def _body(element: etree._Element, ctx: BuildContext) -> tuple[ActivityBody, etree._Element | None]:
    sub = BODIES.first(element)
    if sub is not None:
        return BODIES.build(sub, ctx), sub
    return NoImplementation(), None


# Route's only field is its gateway: a new Route is what dataclasses.replace gives, quicker.
_ROUTE_IS_GATEWAY_ONLY = tuple(f.name for f in dataclasses.fields(Route)) == ("gateway",)


def build_activity(element: etree._Element, ctx: BuildContext) -> Activity:
    if not len(element):
        return _bare_activity(element, ctx)
    fields = base_fields(element, ctx, kind="Activity")
    tags = children_by_tag(element)       # None outside indexed_children: look for everything

    def has(local: str) -> bool:
        return tags is None or qname(local) in tags

    body, body_element = _body(element, ctx)
    join, split = _restrictions(element, ctx) if has("TransitionRestrictions") else (None, None)
    if isinstance(body, Route) and body_element is not None and attr(body_element, "GatewayType") is None:
        # XPDL 1.0 and Bizagi routes say what they do only through their restrictions.
        derived = (split.type if split else None) or (join.type if join else None) or GatewayType.XOR
        body = (Route(gateway=derived) if _ROUTE_IS_GATEWAY_ONLY and type(body) is Route
                else dataclasses.replace(body, gateway=derived))
    if join is not None and join.type is GatewayType.COMPLEX:
        # XPDL 2.1 writes a complex gateway's activation rule on the Route: IncomingCondition
        text = attr(body_element, "IncomingCondition") if body_element is not None else None
        join = dataclasses.replace(join, condition_text=text, condition=read_expression(
            body_element, text, ctx, "IncomingCondition"))
    priority_text = text_of(child(element, "Priority")) if has("Priority") else None
    priority = parse_int(priority_text)
    if priority_text is not None and priority is None:
        ctx.warning(child(element, "Priority"), "bad-priority",
                    f"Priority {priority_text!r} of activity {fields['id']!r} is not an integer; ignored",
                    "write an integer")
    directives, coordination = activity_directives(element, ctx)
    return Activity(
        body=body,
        performers=performers_of(element) if has("Performers") else (),
        start_mode=_mode(element, "StartMode", ctx),
        finish_mode=_mode(element, "FinishMode", ctx),
        priority=priority,
        deadlines=_deadlines(element, ctx) if has("Deadline") else (),
        loop=_loop(element, ctx) if has("Loop") else None,
        join=join,
        split=split,
        lane=_lane(element) if has("NodeGraphicsInfos") else None,
        directives=directives,
        coordination=coordination,
        assignments=build_assignments(element, ctx) if has("Assignments") else (),
        start_quantity=quantity(element, "StartQuantity", ctx),
        completion_quantity=quantity(element, "CompletionQuantity", ctx),
        marked_start=_marked_start(element),
        **fields,
    )


def _marked_start(element: etree._Element) -> bool:
    """XPDL 2.x ``StartActivity="true"``: "Designates the first activity to be executed when
    the process is instantiated. Used when there is no other way to determine this"
    (:meth:`opspec.model.graph.FlowGraph.starts`)."""
    return (attr(element, "StartActivity") or "").strip().lower() == "true"


def _bare_activity(element: etree._Element, ctx: BuildContext) -> Activity:
    """An Activity element without children (common in big generated files): what
    :func:`build_activity` gives, without asking for each kind of child in turn."""
    fields = base_fields(element, ctx, kind="Activity")
    directives, coordination = activity_directives(element, ctx)   # its opspec: attributes
    return Activity(
        body=NoImplementation(),
        start_mode=_mode(element, "StartMode", ctx),
        finish_mode=_mode(element, "FinishMode", ctx),
        directives=directives,
        coordination=coordination,
        start_quantity=quantity(element, "StartQuantity", ctx),
        completion_quantity=quantity(element, "CompletionQuantity", ctx),
        marked_start=_marked_start(element),
        **fields,
    )
