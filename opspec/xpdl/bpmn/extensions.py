"""The ``opspec:`` extension elements of a BPMN file (namespace ``urn:opspec:sisarl:1``).

BPMN has no place for what a simulation needs beyond the diagram (a workflow's period, an
activity's duration distribution, metrics, data fields with initial values), so it travels
where BPMN 2.0 puts vendor data: child elements of ``bpmn:extensionElements``. Every modeller
keeps them (bpmn.io, Camunda Modeler and Signavio write them back unchanged).

* **Directives** are the SISARL directives of docs/sisarl-xpdl.md, one element each, named
  like the directive, the value in ``Value`` or the text: ``<opspec:Period Value="PT1S"/>``,
  ``<opspec:Raises>message:trg_1</opspec:Raises>``; structured ones hold their children as in
  XPDL (``<opspec:BuiltIn><opspec:Arbiter …/></opspec:BuiltIn>``, ``<opspec:Metrics>…``).
  The attribute shorthand ``opspec:Period="PT1S"`` on the BPMN element works too. They are
  parsed by :mod:`opspec.xpdl.sisarl`, so values, errors and warnings are XPDL's.
* **Structure** XPDL has and BPMN lacks: ``opspec:DataField``, ``opspec:FormalParameter``,
  ``opspec:Application``, ``opspec:TaskApplication``, ``opspec:ActualParameter``,
  ``opspec:Assignment`` and ``opspec:Execution`` (a call activity's ``ASYNCHR``).
"""

from __future__ import annotations

from lxml import etree

from opspec.model.activities import Execution, TaskApplication
from opspec.model.common import ExtendedAttribute
from opspec.model.data import (
    ActualParameter,
    Assignment,
    BasicKind,
    BasicType,
    DataField,
    FormalParameter,
    ParameterMode,
)
from opspec.model.resources import Application
from opspec.xpdl.bpmn.common import Defs, first, is_opspec, local
from opspec.xpdl.handlers.activities import build_assignment
from opspec.xpdl.handlers.common import raw_xml
from opspec.xpdl.handlers.data import actual_parameter, typed_value
from opspec.xpdl.sisarl import REPEATABLE, Directive, collect

__all__ = [
    "STRUCTURE",
    "actual_parameters",
    "application",
    "assignments",
    "data_field",
    "directives",
    "execution",
    "formal_parameter",
    "opspec_elements",
    "task_applications",
]

#: The structural opspec elements (not directives) and where each may stand.
STRUCTURE = ("DataField", "FormalParameter", "Application", "TaskApplication",
             "ActualParameter", "Assignment", "Execution")


def opspec_elements(element: etree._Element) -> list[etree._Element]:
    """The ``opspec:`` children of ``element``'s ``bpmn:extensionElements``."""
    extensions = first(element, "extensionElements")
    if extensions is None:
        return []
    return [sub for sub in extensions if isinstance(sub.tag, str) and is_opspec(sub)]


def opspec_named(element: etree._Element, name: str) -> list[etree._Element]:
    return [sub for sub in opspec_elements(element) if local(sub) == name]


def _value(element: etree._Element) -> str:
    value = element.get("Value")
    if value is not None:
        return str(value)
    if not len(element):
        return "".join(element.itertext()).strip()
    return (element.text or "").strip()


def directives(element: etree._Element, defs: Defs, known: tuple[str, ...], what: str,
               structure: tuple[str, ...] = ()
               ) -> tuple[dict[str, Directive], tuple[ExtendedAttribute, ...]]:
    """The directives of ``element`` (attribute shorthand and extension elements) and the
    extension elements as :class:`ExtendedAttribute` values (kept verbatim, as XPDL keeps
    its ExtendedAttributes). ``structure`` names the structural elements allowed here;
    others are ``unknown-directive`` warnings saying they are ignored."""
    ctx = defs.ctx
    found = collect(element, ctx, known, what)
    kept: list[ExtendedAttribute] = []
    for sub in opspec_elements(element):
        name = local(sub)
        if name in structure:
            continue
        where = ctx.loc(sub)
        if name not in known:
            elsewhere = name in STRUCTURE
            ctx.warning(sub, "unknown-directive",
                        f"opspec:{name} does not belong on {what}; it is ignored" if elsewhere
                        else f"unknown directive opspec:{name} on {what}; it is ignored",
                        f"known on {what}: "
                        + ", ".join(f"opspec:{k}" for k in (*known, *structure))
                        + " (docs/bpmn.md)")
            continue
        if name in found and name not in REPEATABLE:
            ctx.warning(sub, "duplicate-directive",
                        f"opspec:{name} is given twice on {what}; the last one counts",
                        "remove one of them")
        found[name] = Directive(name, _value(sub), sub, where)
        text = sub.text.strip() if sub.text is not None and sub.text.strip() else None
        kept.append(ExtendedAttribute(
            name=f"opspec:{name}", value=sub.get("Value"), text=text,
            raw_xml="".join(raw_xml(c) for c in sub if isinstance(c.tag, str)) or None,
            location=where))
    return found, tuple(kept)


def _kind(element: etree._Element, defs: Defs, owner: str) -> BasicType:
    raw = (element.get("Type") or "STRING").strip().upper()
    try:
        return BasicType(kind=BasicKind(raw))
    except ValueError:
        defs.ctx.warning(element, "unknown-basic-type", f"{owner}: unknown Type {raw!r}; "
                         "STRING is assumed",
                         "use one of " + ", ".join(k.value for k in BasicKind))
        return BasicType(kind=BasicKind.STRING)


def _id(element: etree._Element, defs: Defs, what: str) -> str:
    value = (element.get("Id") or "").strip()
    if not value:
        defs.ctx.error(element, "missing-id", f"opspec:{what} has no Id",
                       f"add Id=\"…\" to <opspec:{what}>")
        line = defs.ctx.loc(element).line
        return f"<{what} without Id at line {line}>"
    return value


def data_field(element: etree._Element, defs: Defs) -> DataField:
    """``<opspec:DataField Id Name Type InitialValue IsArray/>`` (Type a BasicType, default
    STRING; the initial value as XPDL's InitialValue, JSON for arrays)."""
    field_id = _id(element, defs, "DataField")
    data_type = _kind(element, defs, f"data field {field_id!r}")
    text = element.get("InitialValue")
    if text is None:
        text = (element.text or "").strip() or None
    is_array = (element.get("IsArray") or "").strip().lower() == "true"
    initial = None
    if text is not None and not is_array:
        initial, understood = typed_value(text, data_type)
        if not understood:
            defs.ctx.warning(element, "bad-initial-value",
                             f"initial value {text!r} of data field {field_id!r} is not a valid "
                             f"{data_type.kind.value}; the field starts without a value",
                             "write a literal of the field's type")
    return DataField(id=field_id, name=element.get("Name"), type=data_type,
                     initial_value=text, initial=initial, is_array=is_array,
                     location=defs.loc(element))


def formal_parameter(element: etree._Element, defs: Defs) -> FormalParameter:
    """``<opspec:FormalParameter Id Name Mode Type/>`` (Mode IN, OUT or INOUT)."""
    parameter_id = _id(element, defs, "FormalParameter")
    raw = (element.get("Mode") or "IN").strip().upper()
    try:
        mode = ParameterMode(raw)
    except ValueError:
        defs.ctx.warning(element, "bad-parameter-mode", f"unknown parameter Mode {raw!r}; IN "
                         "assumed", "use IN, OUT or INOUT")
        mode = ParameterMode.IN
    return FormalParameter(id=parameter_id, name=element.get("Name"), mode=mode,
                           type=_kind(element, defs, f"formal parameter {parameter_id!r}"),
                           location=defs.loc(element))


def application(element: etree._Element, defs: Defs) -> Application:
    """``<opspec:Application Id Name>`` with ``opspec:FormalParameter`` children."""
    formals = tuple(formal_parameter(sub, defs) for sub in element
                    if isinstance(sub.tag, str) and is_opspec(sub)
                    and local(sub) == "FormalParameter")
    return Application(id=_id(element, defs, "Application"), name=element.get("Name"),
                       formal_parameters=formals, location=defs.loc(element))


def _actual(element: etree._Element, defs: Defs) -> ActualParameter:
    return actual_parameter(element, defs.loc(element))


def actual_parameters(element: etree._Element, defs: Defs) -> tuple[ActualParameter, ...]:
    """The ``opspec:ActualParameter`` children of ``element`` (an extension element or the
    flow node itself, through its extensionElements)."""
    if is_opspec(element):
        subs = [s for s in element if isinstance(s.tag, str) and is_opspec(s)
                and local(s) == "ActualParameter"]
    else:
        subs = opspec_named(element, "ActualParameter")
    return tuple(_actual(sub, defs) for sub in subs)


def task_applications(element: etree._Element, defs: Defs) -> tuple[TaskApplication, ...]:
    """``<opspec:TaskApplication Id>`` children (each with ``opspec:ActualParameter``s)."""
    return tuple(TaskApplication(application=_id(sub, defs, "TaskApplication"),
                                 actual_parameters=actual_parameters(sub, defs))
                 for sub in opspec_named(element, "TaskApplication"))


def execution(element: etree._Element, defs: Defs) -> Execution:
    """``<opspec:Execution Value="ASYNCHR"/>`` of a call activity (default SYNCHR, as BPMN)."""
    found = opspec_named(element, "Execution")
    if not found:
        return Execution.SYNCHR
    raw = _value(found[-1]).upper()
    try:
        return Execution(raw)
    except ValueError:
        defs.ctx.warning(found[-1], "bad-execution", f"unknown Execution {raw!r}; SYNCHR "
                         "assumed", "write SYNCHR (the caller waits) or ASYNCHR")
        return Execution.SYNCHR


def assignments(element: etree._Element, defs: Defs) -> tuple[Assignment, ...]:
    """``<opspec:Assignment Target AssignTime>expression</opspec:Assignment>`` children."""
    out: list[Assignment] = []
    for sub in opspec_named(element, "Assignment"):
        target = (sub.get("Target") or "").strip()
        text = "".join(sub.itertext()).strip()
        if not target:
            defs.ctx.warning(sub, "bad-assignment", "opspec:Assignment has no Target; it is "
                             "ignored", "add Target=\"data_field\"")
            continue
        out.append(build_assignment(sub, defs.ctx, target, text,
                                    (sub.get("AssignTime") or "End").strip()))
    return tuple(out)
