"""Handlers for what an activity *is*: Implementation (No, Task…, SubFlow, Reference), Route,
BlockActivity, and (via :mod:`.events`) events."""

from __future__ import annotations

from lxml import etree

from opspec.model.activities import (
    ActivityBody,
    BlockActivity,
    Execution,
    GatewayType,
    NoImplementation,
    Reference,
    Route,
    SubFlow,
    Task,
    TaskApplication,
    TaskKind,
)
from opspec.xpdl.handlers.common import (
    BuildContext,
    attr,
    child,
    children,
    enum_attr,
    required_attr,
    text_of,
)
from opspec.xpdl.handlers.data import build_actual_parameters
from opspec.xpdl.handlers.events import EVENTS
from opspec.xpdl.handlers.registry import Registry

__all__ = ["BODIES", "IMPLEMENTATIONS", "TASKS", "gateway_type"]

BODIES: Registry[ActivityBody] = Registry("activity kind")
IMPLEMENTATIONS: Registry[ActivityBody] = Registry("implementation")
TASKS: Registry[ActivityBody] = Registry("task")

_GATEWAYS: dict[str, GatewayType] = {
    "exclusive": GatewayType.XOR,
    "xor": GatewayType.XOR,
    "parallel": GatewayType.AND,
    "and": GatewayType.AND,
    "inclusive": GatewayType.OR,
    "or": GatewayType.OR,
    "complex": GatewayType.COMPLEX,
    "eventbasedxor": GatewayType.EVENT,
    "eventbasedexclusive": GatewayType.EVENT,
    "eventbased": GatewayType.EVENT,
    "xoreventbased": GatewayType.EVENT,
    "exclusiveeventbased": GatewayType.EVENT,
    "paralleleventbased": GatewayType.EVENT,
}


def gateway_type(element: etree._Element, attribute: str, ctx: BuildContext) -> GatewayType | None:
    """The gateway type written in ``attribute`` (``None`` when absent). ``ExclusiveType="Event"``
    (XPDL 2.1) turns an exclusive gateway into an event-based one."""
    raw = attr(element, attribute)
    if raw is None:
        return None
    gateway = _GATEWAYS.get(raw.replace("-", "").replace("_", "").lower())
    if gateway is None:
        ctx.warning(element, "unknown-gateway", f"unknown {attribute} {raw!r}; Exclusive assumed",
                    "use Exclusive, Parallel, Inclusive, Complex or EventBasedXOR")
        return GatewayType.XOR
    if gateway is GatewayType.XOR and (attr(element, "ExclusiveType") or "").lower() == "event":
        return GatewayType.EVENT
    return gateway


@BODIES.register("Route")
def _route(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    # Without GatewayType (XPDL 1.0, Bizagi) the activity builder derives it from the
    # restrictions; XOR is the default of both.
    return Route(gateway=gateway_type(element, "GatewayType", ctx) or GatewayType.XOR)


@BODIES.register("BlockActivity")
def _block(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    set_id = required_attr(element, "ActivitySetId", ctx, "missing-activity-set",
                           "BlockActivity names no ActivitySetId",
                           "set ActivitySetId to the Id of an ActivitySet of this process")
    return BlockActivity(activity_set=set_id, start_activity=attr(element, "StartActivityId"))


@BODIES.register("Event")
def _event(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    body = EVENTS.build_first(element, ctx)
    if body is None:
        ctx.warning(element, "empty-event", "Event has no StartEvent, IntermediateEvent or EndEvent",
                    "put one of them inside <Event>")
        return NoImplementation()
    return body


@BODIES.register("Implementation")
def _implementation(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    body = IMPLEMENTATIONS.build_first(element, ctx)
    return body if body is not None else NoImplementation()


@IMPLEMENTATIONS.register("No")
def _no(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    return NoImplementation()


@IMPLEMENTATIONS.register("SubFlow")
def _subflow(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    process = required_attr(element, "Id", ctx, "missing-subflow-target",
                            "SubFlow names no process (its Id is missing)",
                            "set Id to the Id of the WorkflowProcess to call")
    execution = enum_attr(element, "Execution", Execution.SYNCHR, ctx, "bad-execution",
                          "SubFlow Execution", "use SYNCHR or ASYNCHR")
    return SubFlow(process=process, execution=execution,
                   actual_parameters=build_actual_parameters(element, ctx),
                   package_ref=attr(element, "PackageRef"))


@IMPLEMENTATIONS.register("Reference")
def _reference(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    return Reference(activity=attr(element, "ActivityId") or "")


@IMPLEMENTATIONS.register("Task")
def _task(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    applications = children(element, "TaskApplication")
    if len(applications) > 1:  # several XPDL 1.0 Tools, normalised into one Task
        return Task(kind=TaskKind.APPLICATION,
                    applications=tuple(_application(a, ctx) for a in applications))
    body = TASKS.build_first(element, ctx)
    return body if body is not None else Task(kind=TaskKind.MANUAL)


def _application(element: etree._Element, ctx: BuildContext) -> TaskApplication:
    application = required_attr(element, "Id", ctx, "missing-application",
                                "TaskApplication names no application",
                                "set Id to the Id of an Application")
    return TaskApplication(application=application, package_ref=attr(element, "PackageRef"),
                           actual_parameters=build_actual_parameters(element, ctx))


@TASKS.register("TaskApplication")
def _task_application(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    return Task(kind=TaskKind.APPLICATION, applications=(_application(element, ctx),))


def _message_name(element: etree._Element) -> str | None:
    for tag in ("Message", "MessageIn", "MessageOut"):
        message = child(element, tag)
        if message is not None:
            return attr(message, "Name") or attr(message, "Id")
    return attr(element, "MessageName")


def _simple(kind: TaskKind) -> None:
    def build(element: etree._Element, ctx: BuildContext) -> ActivityBody:
        return Task(kind=kind, message=_message_name(element),
                    implementation=attr(element, "Implementation"))

    TASKS.register(f"Task{_SUFFIX[kind]}")(build)


_SUFFIX = {
    TaskKind.MANUAL: "Manual",
    TaskKind.USER: "User",
    TaskKind.SERVICE: "Service",
    TaskKind.SEND: "Send",
    TaskKind.RECEIVE: "Receive",
    TaskKind.REFERENCE: "Reference",
    TaskKind.BUSINESS_RULE: "BusinessRule",
}
for _kind in _SUFFIX:
    _simple(_kind)


@TASKS.register("TaskScript")
def _task_script(element: etree._Element, ctx: BuildContext) -> ActivityBody:
    script = child(element, "Script")
    text = None
    if script is not None:
        text = "".join(script.itertext()).strip() or None
    return Task(kind=TaskKind.SCRIPT, script=text if text is not None else text_of(element))
