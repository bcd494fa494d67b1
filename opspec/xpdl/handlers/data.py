"""Handlers for workflow data: data types, type declarations, data fields, formal and actual
parameters."""

from __future__ import annotations

from lxml import etree

from opspec.errors import SourceLocation, SpecError
from opspec.model.data import (
    ActualParameter,
    ArrayType,
    BasicKind,
    BasicType,
    DataField,
    DataType,
    DeclaredType,
    EnumerationType,
    ExternalReferenceType,
    FormalParameter,
    ListType,
    ParameterMode,
    RecordMember,
    RecordType,
    SchemaType,
    TypeDeclaration,
    UnionType,
    is_structured,
    structured_value,
)
from opspec.xpdl.handlers.common import (
    BuildContext,
    attr,
    base_fields,
    child,
    child_text,
    children,
    enum_attr,
    grandchildren,
    parse_bool,
    parse_int,
    raw_xml,
    required_attr,
    text_of,
)
from opspec.xpdl.handlers.registry import Registry

__all__ = [
    "DATA_TYPES",
    "actual_parameter",
    "build_actual_parameters",
    "build_data_field",
    "build_data_type",
    "build_formal_parameter",
    "build_type_declaration",
    "typed_value",
]

DATA_TYPES: Registry[DataType] = Registry("data type")
_STRING = BasicType(kind=BasicKind.STRING)


def _inner_type(element: etree._Element, ctx: BuildContext, owner: str) -> DataType:
    """The single data-type child of ``element`` (defaults to STRING with a warning)."""
    built = DATA_TYPES.build_first(element, ctx)
    if built is None:
        ctx.warning(element, "missing-type", f"{owner} has no data type; STRING is assumed",
                    f"add one of {', '.join(DATA_TYPES.names())}")
        return _STRING
    return built


@DATA_TYPES.register("BasicType")
def _basic(element: etree._Element, ctx: BuildContext) -> DataType:
    raw = attr(element, "Type") or ""
    try:
        kind = BasicKind(raw.upper())
    except ValueError:
        allowed = ", ".join(k.value for k in BasicKind)
        ctx.warning(element, "unknown-basic-type", f"unknown BasicType {raw!r}; STRING is assumed",
                    f"use one of {allowed}")
        kind = BasicKind.STRING

    def number(name: str) -> int | None:
        return parse_int(child_text(element, name) or attr(element, name))

    return BasicType(kind=kind, length=number("Length"), precision=number("Precision"),
                     scale=number("Scale"))


@DATA_TYPES.register("DeclaredType")
def _declared(element: etree._Element, ctx: BuildContext) -> DataType:
    return DeclaredType(ref=required_attr(element, "Id", ctx, "missing-id",
                                          "DeclaredType has no Id",
                                          "set Id to the Id of a TypeDeclaration"))


@DATA_TYPES.register("SchemaType")
def _schema(element: etree._Element, ctx: BuildContext) -> DataType:
    raw = "".join(raw_xml(sub) for sub in element if isinstance(sub.tag, str))
    return SchemaType(raw_xml=raw)


@DATA_TYPES.register("ExternalReference")
def _external(element: etree._Element, ctx: BuildContext) -> DataType:
    return ExternalReferenceType(location=attr(element, "location") or "",
                                 xref=attr(element, "xref"), namespace=attr(element, "namespace"))


def _members(element: etree._Element, ctx: BuildContext) -> tuple[RecordMember, ...]:
    members: list[RecordMember] = []
    for index, member in enumerate(children(element, "Member"), start=1):
        name = attr(member, "Name") or attr(member, "Id") or f"member{index}"
        members.append(RecordMember(name=name, type=_inner_type(member, ctx, "Member")))
    return tuple(members)


@DATA_TYPES.register("RecordType")
def _record(element: etree._Element, ctx: BuildContext) -> DataType:
    return RecordType(members=_members(element, ctx))


@DATA_TYPES.register("UnionType")
def _union(element: etree._Element, ctx: BuildContext) -> DataType:
    return UnionType(members=_members(element, ctx))


@DATA_TYPES.register("EnumerationType")
def _enumeration(element: etree._Element, ctx: BuildContext) -> DataType:
    values = tuple(attr(value, "Name") or text_of(value) or ""
                   for value in children(element, "EnumerationValue"))
    return EnumerationType(values=values)


@DATA_TYPES.register("ArrayType")
def _array(element: etree._Element, ctx: BuildContext) -> DataType:
    return ArrayType(element=_inner_type(element, ctx, "ArrayType"),
                     lower=parse_int(attr(element, "LowerIndex")),
                     upper=parse_int(attr(element, "UpperIndex")))


@DATA_TYPES.register("ListType")
def _list(element: etree._Element, ctx: BuildContext) -> DataType:
    return ListType(element=_inner_type(element, ctx, "ListType"))


def build_data_type(owner: etree._Element, ctx: BuildContext, what: str) -> DataType:
    """The type of a DataField/FormalParameter: ``owner/DataType/<type>``."""
    wrapper = child(owner, "DataType")
    if wrapper is None:
        # Some exporters put the type directly under the owner.
        direct = DATA_TYPES.build_first(owner, ctx)
        if direct is not None:
            return direct
        ctx.warning(owner, "missing-type", f"{what} has no DataType; STRING is assumed",
                    "add <DataType><BasicType Type=\"STRING\"/></DataType>")
        return _STRING
    return _inner_type(wrapper, ctx, what)


def build_type_declaration(element: etree._Element, ctx: BuildContext) -> TypeDeclaration:
    fields = base_fields(element, ctx, kind="TypeDeclaration")
    return TypeDeclaration(type=_inner_type(element, ctx, "TypeDeclaration"), **fields)


def _unquote(text: str) -> str:
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "\"'":
        return text[1:-1]
    return text


def typed_value(
    text: str, data_type: DataType
) -> tuple[str | int | float | bool | None, bool]:
    """``text`` converted according to ``data_type``: ``(value, understood)``."""
    stripped = text.strip()
    if not isinstance(data_type, BasicType):
        return _unquote(stripped), True
    kind = data_type.kind
    if kind is BasicKind.INTEGER:
        number = parse_int(stripped)
        return number, number is not None
    if kind is BasicKind.FLOAT:
        try:
            return float(stripped), True
        except ValueError:
            return None, False
    if kind is BasicKind.BOOLEAN:
        flag = parse_bool(_unquote(stripped))
        return flag, flag is not None
    return _unquote(stripped), True


def build_data_field(element: etree._Element, ctx: BuildContext) -> DataField:
    fields = base_fields(element, ctx, kind="DataField")
    data_type = build_data_type(element, ctx, "DataField")
    initial_element = child(element, "InitialValue")
    initial_text = None if initial_element is None else (initial_element.text or "").strip() or None
    initial: str | int | float | bool | None = None
    is_array = parse_bool(attr(element, "IsArray")) or False
    if initial_text is not None and is_structured(data_type, is_array):
        try:
            structured_value(initial_text, data_type, is_array)
        except ValueError as error:
            ctx.error(initial_element, "bad-initial-value",
                      f"initial value of DataField {fields['id']!r}: {error}",
                      'write arrays as JSON lists ([1, 2, 3]) and records as JSON objects '
                      '({"x": 1})')
    elif initial_text is not None:
        initial, understood = typed_value(initial_text, data_type)
        if not understood:
            kind = data_type.kind.value if isinstance(data_type, BasicType) else "its type"
            ctx.warning(initial_element, "bad-initial-value",
                        f"initial value {initial_text!r} of DataField {fields['id']!r} is not a "
                        f"valid {kind}; the field starts without a value",
                        "write a literal of the field's type")
    return DataField(
        type=data_type,
        initial_value=initial_text,
        initial=initial,
        is_array=is_array,
        correlation=parse_bool(attr(element, "Correlation")) or False,
        read_only=parse_bool(attr(element, "ReadOnly")) or False,
        **fields,
    )


def build_formal_parameter(element: etree._Element, ctx: BuildContext) -> FormalParameter:
    fields = base_fields(element, ctx, kind="FormalParameter")
    mode = enum_attr(element, "Mode", ParameterMode.IN, ctx, "bad-parameter-mode",
                     "parameter Mode", "use IN, OUT or INOUT")
    return FormalParameter(
        type=build_data_type(element, ctx, "FormalParameter"),
        mode=mode,
        is_array=parse_bool(attr(element, "IsArray")) or False,
        required=parse_bool(attr(element, "Required")) or False,
        **fields,
    )


def build_actual_parameters(owner: etree._Element, ctx: BuildContext) -> tuple[ActualParameter, ...]:
    """``owner/ActualParameters/ActualParameter``, each as :func:`actual_parameter` reads it."""
    return tuple(actual_parameter(parameter, ctx.loc(parameter))
                 for parameter in grandchildren(owner, "ActualParameters", "ActualParameter"))


def actual_parameter(element: etree._Element, location: SourceLocation) -> ActualParameter:
    """One ``ActualParameter`` (XPDL, or a BPMN extension's): its text as written plus, when
    it parses, an expression; a parameter that is no expression is kept as text, without a
    diagnostic, since many engines pass opaque strings."""
    from opspec.xpdl.conditions import parse_expression

    text = "".join(element.itertext()).strip()
    expression = None
    if text:
        try:
            expression = parse_expression(text, location=location)
        except (SpecError, ValueError, RecursionError):
            expression = None
    return ActualParameter(text=text, expression=expression, location=location)
