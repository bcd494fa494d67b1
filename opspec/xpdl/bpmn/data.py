"""BPMN data into the model's data fields: data objects, properties, input/output
specifications, data associations, and the data Camunda keeps in its extensions (form fields,
input/output parameters).

opspec's data fields are per workflow (docs/semantics.md): BPMN's scopes (a data object of a
sub-process, a task's inputs and outputs, Camunda's local input parameters) all become fields
of the process, named by their id, as SpiffWorkflow names them. What moves data between them
becomes assignments of the model:

* a ``dataInputAssociation`` into a task's ``dataInput`` sets that input from its source when
  the task starts; a ``dataOutputAssociation`` from a ``dataOutput`` sets its target when the
  task ends; a ``transformation`` or ``assignment`` (``from``/``to``) says how;
* ``camunda:inputParameter`` is set when the activity starts, ``camunda:outputParameter`` when
  it ends (a plain text is a string constant, ``${…}`` an expression);
* a ``camunda:formField`` is a field whose initial value is its ``defaultValue``; completing
  the user task is submitting the form: the performer's completion sets the fields it
  supplies, the others keep their value (the default the form shows).

A value opspec cannot know (a task's ``dataOutput`` or a form field without default that the
performer does not supply, a parameter computed by a script) leaves the field without value;
reading it then stops the instance with a located fault. docs/bpmn.md says how a script or a
bound device supplies it.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from lxml import etree

from opspec.errors import SpecError
from opspec.model.data import (
    Assignment,
    BasicKind,
    BasicType,
    DataField,
    FormalParameter,
    ParameterMode,
)
from opspec.model.expressions import Expression, Literal, Name
from opspec.xpdl.bpmn.common import (
    Defs,
    expression_text,
    first,
    kids,
    local,
    namespace,
    tag,
    text_of,
)

__all__ = [
    "CAMUNDA",
    "ActivityData",
    "activity_data",
    "index_data",
    "process_fields",
]

#: Camunda Platform 7's extension namespace (Camunda Modeler writes it; SpiffWorkflow reads it).
CAMUNDA = "http://camunda.org/schema/1.0/bpmn"
_PLACEHOLDER = "__targetRef_placeholder"        # bpmn-js writes it for input associations

# XML Schema and Java type names (an itemDefinition's structureRef) -> basic kinds.
_STRUCTURES: dict[str, BasicKind] = {
    **{n: BasicKind.STRING for n in ("string", "normalizedstring", "token", "anyuri",
                                     "java.lang.string", "str", "text")},
    **{n: BasicKind.INTEGER for n in (
        "int", "integer", "long", "short", "byte", "nonnegativeinteger", "positiveinteger",
        "negativeinteger", "nonpositiveinteger", "unsignedint", "unsignedlong",
        "unsignedshort", "unsignedbyte", "java.lang.integer", "java.lang.long",
        "java.lang.short")},
    **{n: BasicKind.FLOAT for n in ("double", "float", "decimal", "number",
                                    "java.lang.double", "java.lang.float",
                                    "java.math.bigdecimal")},
    **{n: BasicKind.BOOLEAN for n in ("boolean", "bool", "java.lang.boolean")},
    "date": BasicKind.DATE, "datetime": BasicKind.DATETIME, "time": BasicKind.TIME,
    "java.util.date": BasicKind.DATETIME,
}
# camunda:formField types -> basic kinds (enum is text: one of its value ids).
_FORM_TYPES: dict[str, BasicKind] = {
    "string": BasicKind.STRING, "long": BasicKind.INTEGER, "integer": BasicKind.INTEGER,
    "boolean": BasicKind.BOOLEAN, "date": BasicKind.DATETIME, "enum": BasicKind.STRING,
    "double": BasicKind.FLOAT,
}


def _bare(ref: str) -> str:
    """A QName reference without its prefix (``xsd:string`` -> ``string``)."""
    return ref.strip().rsplit(":", 1)[-1]


def index_data(root: etree._Element, defs: Defs) -> None:
    """The file's item definitions (``defs.item_kinds``) and the input/output specification
    of each process (``defs.process_io``: what a call activity passes and gets back)."""
    for item in root.iter(tag("itemDefinition")):
        structure = (item.get("structureRef") or "").strip()
        kind = _STRUCTURES.get(_bare(structure).lower()) or _STRUCTURES.get(structure.lower())
        if kind is not None and item.get("id"):
            defs.item_kinds[item.get("id") or ""] = kind
    for element in root.iter(tag("dataObject"), tag("property"), tag("dataObjectReference")):
        target = element.get("dataObjectRef") if local(element) == "dataObjectReference" \
            else element.get("id")
        name = " ".join((element.get("name") or "").split())
        if target and name and name != target:
            defs.data_names.setdefault(name, target.strip())
    for process in kids(root, "process"):
        spec = first(process, "ioSpecification")
        if spec is not None:
            defs.process_io[process.get("id") or ""] = [
                (sub.get("id") or "", ParameterMode.IN if local(sub) == "dataInput"
                 else ParameterMode.OUT)
                for sub in spec if local(sub) in ("dataInput", "dataOutput") and sub.get("id")]


def _type(element: etree._Element, defs: Defs) -> BasicType:
    """The type an ``itemSubjectRef`` gives (STRING when it names no simple type)."""
    ref = (element.get("itemSubjectRef") or "").strip()
    kind = defs.item_kinds.get(ref) or defs.item_kinds.get(_bare(ref)) if ref else None
    return BasicType(kind=kind or BasicKind.STRING)


def _field(element: etree._Element, defs: Defs) -> DataField:
    return DataField(id=element.get("id") or "", name=element.get("name"),
                     type=_type(element, defs), location=defs.loc(element))


def process_fields(process: etree._Element, defs: Defs
                   ) -> tuple[list[DataField], list[FormalParameter]]:
    """The data fields of a process — its data objects (at every level: a sub-process's are
    the process's), its properties and its activities' properties — and the formal
    parameters its ``ioSpecification`` declares (``dataInput`` IN, ``dataOutput`` OUT)."""
    fields: list[DataField] = []
    for element in process.iter():
        if not isinstance(element.tag, str) or namespace(element) != namespace(process):
            continue
        name = local(element)
        if name == "dataObject" or name == "property" and element.get("name") != _PLACEHOLDER:
            fields.append(_field(element, defs))
    formals: list[FormalParameter] = []
    spec = first(process, "ioSpecification")
    if spec is not None:
        for sub in spec:
            if local(sub) in ("dataInput", "dataOutput"):
                formals.append(FormalParameter(
                    id=sub.get("id") or "", name=sub.get("name"), type=_type(sub, defs),
                    mode=ParameterMode.IN if local(sub) == "dataInput" else ParameterMode.OUT,
                    location=defs.loc(sub)))
    return fields, formals


@dataclass(slots=True)
class ActivityData:
    """What one activity adds: ``assignments`` (start and end), ``fields`` it creates (a
    form's fields, its outputs, Camunda parameters), ``reads`` (names its ``dataInput``s take
    from the process by name, which something must declare) and ``writes`` (what its
    performer's completion supplies)."""

    assignments: list[Assignment] = field(default_factory=list)
    fields: list[DataField] = field(default_factory=list)
    reads: list[tuple[str, etree._Element]] = field(default_factory=list)
    writes: list[str] = field(default_factory=list)


def activity_data(element: etree._Element, defs: Defs, label: str) -> ActivityData:
    """The data of one flow node (see the module docstring)."""
    out = ActivityData()
    _io_specification(element, defs, out)
    _associations(element, defs, out, label)
    extensions = first(element, "extensionElements")
    if extensions is not None:
        for sub in extensions:
            if not isinstance(sub.tag, str) or namespace(sub) != CAMUNDA:
                continue
            if local(sub) == "formData":
                _form(sub, element, defs, out, label)
            elif local(sub) == "inputOutput":
                _parameters(sub, defs, out, label, connector=False)
            elif local(sub) == "connector":
                for io in sub:
                    if isinstance(io.tag, str) and local(io) == "inputOutput":
                        _parameters(io, defs, out, label, connector=True)
    if local(element) == "callActivity":
        called = (element.get("calledElement") or "").strip()
        for name, mode in defs.process_io.get(called, []):
            if mode is ParameterMode.OUT:
                out.fields.append(DataField(id=name, type=BasicType(kind=BasicKind.STRING),
                                            location=defs.loc(element)))
    return out


def _io_specification(element: etree._Element, defs: Defs, out: ActivityData) -> None:
    spec = first(element, "ioSpecification")
    if spec is None:
        return
    fed = {text_of(first(a, "targetRef")) for a in kids(element, "dataInputAssociation")}
    for sub in spec:
        if not isinstance(sub.tag, str):
            continue
        name = sub.get("id") or ""
        if local(sub) == "dataInput":
            if name in fed:                   # set by its association when the task starts
                out.fields.append(_field(sub, defs))
            else:                             # taken from the process by name (SpiffWorkflow)
                out.reads.append((name, sub))
        elif local(sub) == "dataOutput":
            out.fields.append(_field(sub, defs))
            out.writes.append(name)


def _object_id(ref: str, defs: Defs) -> str | None:
    """The data field a data association's ``sourceRef``/``targetRef`` stands for: a data
    object reference's data object, else the element itself (a data object, a property, a
    task's data input or output); ``None`` for a data store."""
    target = defs.by_id.get(ref)
    if target is None:
        return ref
    kind = local(target)
    if kind == "dataObjectReference":
        return (target.get("dataObjectRef") or "").strip() or None
    if kind in ("dataStoreReference", "dataStore"):
        return None
    return ref


def _associations(element: etree._Element, defs: Defs, out: ActivityData, label: str) -> None:
    for kind, when in (("dataInputAssociation", "Start"), ("dataOutputAssociation", "End")):
        for association in kids(element, kind):
            refs: dict[str, list[str]] = {"sourceRef": [], "targetRef": []}
            for role, found in refs.items():
                for ref_element in kids(association, role):
                    ref = (text_of(ref_element) or "").strip()
                    if ref and ref not in defs.by_id:
                        defs.ctx.error(ref_element, "unknown-reference",
                                       f"{label}: the {kind} names {ref!r} as its {role}, which "
                                       "is nothing in this file", "fix the reference")
                        return
                    if ref:
                        found.append(ref)
            sources = [s for s in (_object_id(r, defs) for r in refs["sourceRef"]) if s]
            targets = [t for t in (_object_id(r, defs) for r in refs["targetRef"]) if t]
            target = targets[0] if targets else None
            placeholder = (target is not None and defs.by_id.get(target) is not None
                           and defs.by_id[target].get("name") == _PLACEHOLDER)
            if target is None or (len(refs["targetRef"]) and not targets):
                defs.info(association, "data-store",
                          f"{label}: a data association with a data store moves no data in "
                          "opspec (data stores are not run)", "use a data object")
                continue
            transformation = first(association, "transformation")
            if transformation is not None:
                value = _expression(transformation, defs, f"the transformation of {label}")
                if value is not None and not placeholder:
                    out.assignments.append(Assignment(
                        target=target, text=expression_text(transformation) or "",
                        expression=value, assign_time=when, location=defs.loc(transformation)))
                continue
            explicit = kids(association, "assignment")
            for assignment in explicit:
                to = expression_text(first(assignment, "to"))
                value = _expression(first(assignment, "from"), defs,
                                    f"the assignment of {label}")
                if to is None or value is None:
                    continue
                out.assignments.append(Assignment(
                    target=to, text=expression_text(first(assignment, "from")) or "",
                    expression=value, assign_time=when, location=defs.loc(assignment)))
            if explicit or placeholder:
                continue
            if kind == "dataOutputAssociation" and not sources:
                out.writes.append(target)       # the task writes the data object itself
            for source in sources[:1]:
                if source != target:
                    out.assignments.append(Assignment(
                        target=target, text=source, expression=Name((source,)),
                        assign_time=when, location=defs.loc(association)))


def _expression(element: etree._Element | None, defs: Defs, what: str) -> Expression | None:
    from opspec.xpdl.bpmn.scripts import bpmn_condition

    return bpmn_condition(element, expression_text(element), defs, what)


def _named(parent: etree._Element, attribute: str, kinds: tuple[str, ...], defs: Defs,
           label: str, hint: str) -> Iterator[tuple[etree._Element, str]]:
    """The camunda elements of ``kinds`` in ``parent``, each with its ``attribute`` (the
    variable it sets); one without it is reported (missing-id, ``hint``) and skipped."""
    for element in parent:
        if not (isinstance(element.tag, str) and local(element) in kinds):
            continue
        name = (element.get(attribute) or "").strip()
        if not name:
            defs.ctx.error(element, "missing-id",
                           f"{label}: a camunda:{local(element)} has no {attribute}", hint)
            continue
        yield element, name


def _form(form: etree._Element, owner: etree._Element, defs: Defs, out: ActivityData,
          label: str) -> None:
    """``camunda:formData``: one field per ``camunda:formField`` (type and default)."""
    described: list[str] = []
    for form_field, name in _named(form, "id", ("formField",), defs, label,
                                   "give the form field the id of the variable it sets"):
        raw_type = (form_field.get("type") or "string").strip()
        kind = _FORM_TYPES.get(raw_type.lower())
        if kind is None:
            defs.ctx.warning(form_field, "unknown-form-type",
                             f"{label}: form field {name!r} has type {raw_type!r}, which opspec "
                             "reads as text", "use string, long, boolean, date or enum")
            kind = BasicKind.STRING
        default = form_field.get("defaultValue")
        data_type = BasicType(kind=kind)
        initial = None
        if default is not None and default.strip().startswith(("${", "#{")):
            defs.ctx.warning(form_field, "form-default-expression",
                             f"{label}: the defaultValue of form field {name!r} is an "
                             "expression, which opspec does not evaluate; the field starts "
                             "without a value", "write the default as a constant")
            default = None
        if default is not None:
            from opspec.xpdl.handlers.data import typed_value

            initial, understood = typed_value(default, data_type)
            if not understood:
                defs.ctx.warning(form_field, "bad-initial-value",
                                 f"{label}: the defaultValue {default!r} of form field {name!r} "
                                 f"is not a {raw_type}; the field is read as text, starting as "
                                 f"{default!r}", f"write a {raw_type} default or change the type")
                data_type = BasicType(kind=BasicKind.STRING)
                initial = default
        if raw_type.lower() == "enum" and default is not None:
            values = [(v.get("id") or "") for v in form_field if isinstance(v.tag, str)
                      and local(v) == "value"]
            if values and default not in values:
                defs.ctx.warning(form_field, "bad-initial-value",
                                 f"{label}: the defaultValue {default!r} of enum form field "
                                 f"{name!r} is none of its values ({', '.join(values)})",
                                 "use the id of one of its camunda:value elements")
        out.fields.append(DataField(id=name, name=form_field.get("label"), type=data_type,
                                    initial_value=default, initial=initial,
                                    location=defs.loc(form_field)))
        out.writes.append(name)
        described.append(f"{name} ({data_type.kind.value}, "
                         + (f"default {default}" if default is not None else "no default") + ")")
    if described:
        who = ("starting the process" if local(owner) == "startEvent"
               else "completing the task")
        defs.info(form, "form-fields",
                  f"{label} has a form: {who} sets {', '.join(described)}; a field the "
                  "performer does not supply keeps its value (the default)",
                  "a script supplies values: complete TASK field=value (docs/bpmn.md)")


def _parameters(io: etree._Element, defs: Defs, out: ActivityData, label: str,
                connector: bool) -> None:
    """``camunda:inputParameter`` (set when the activity starts) and
    ``camunda:outputParameter`` (when it ends); a connector's input parameters are the
    connector's own inputs, not process data."""
    kinds = ("outputParameter",) if connector else ("inputParameter", "outputParameter")
    for parameter, name in _named(io, "name", kinds, defs, label,
                                  "give it the name of the variable it sets"):
        kind = local(parameter)
        when = "Start" if kind == "inputParameter" else "End"
        out.fields.append(DataField(id=name, type=BasicType(kind=BasicKind.STRING),
                                    location=defs.loc(parameter)))
        value, text = _parameter_value(parameter, defs, label, name)
        if value is None:
            out.writes.append(name)
            continue
        out.assignments.append(Assignment(target=name, text=text, expression=value,
                                          assign_time=when, location=defs.loc(parameter)))


def _parameter_value(parameter: etree._Element, defs: Defs, label: str, name: str
                     ) -> tuple[Expression | None, str]:
    """The value of a Camunda parameter: a constant, a ``${…}`` expression, or a script
    whose text is an expression; ``None`` (with a warning) when opspec cannot compute it."""
    from opspec.xpdl.bpmn.scripts import construct_of
    from opspec.xpdl.conditions import parse_expression

    children = [c for c in parameter if isinstance(c.tag, str)]
    if not children:
        raw = "".join(parameter.itertext()).strip()
        if not raw.startswith(("${", "#{")):
            return Literal(raw or None), raw      # Camunda: plain text is a string constant
        text = expression_text(parameter) or ""
        what = "expression"
    elif local(children[0]) == "script" and not children[0].get("resource"):
        text = (text_of(children[0]) or "").rstrip(";").strip()
        what = f"{children[0].get('scriptFormat') or 'script'} script"
    else:
        text = ""
        what = (f"script resource {children[0].get('resource')!r}"
                if children[0].get("resource") else f"camunda:{local(children[0])}")
    if text:
        try:
            return parse_expression(text, location=defs.loc(parameter)), text
        except (SpecError, ValueError, RecursionError) as error:
            construct = construct_of(text)
            reason = (f"{construct} is not in opspec's expression grammar" if construct
                      else getattr(error, "problem", None) or getattr(error, "message", error))
            what = f"{what} ({reason})"
    defs.ctx.warning(parameter, "parameter-not-run",
                     f"{label}: the value of camunda:{local(parameter)} {name!r} is a {what}, "
                     f"which opspec does not compute; {name!r} gets no value there",
                     "a performer bound to the task supplies it on completion (docs/bpmn.md), "
                     "or write the value as a constant or a ${…} expression over data fields")
    return None, ""
