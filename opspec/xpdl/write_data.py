"""Writing a package's data as XPDL 2.1: data types (basic, declared, schema, external,
record and union, enumeration, array, list), type declarations, data fields with their
initial values, formal and actual parameters, and assignments (an expression from the text the
spec wrote, else printed from the parsed expression).
"""

from __future__ import annotations

from lxml import etree

from opspec.model import (
    ActualParameter,
    ArrayType,
    Assignment,
    BasicType,
    DataField,
    DataType,
    DeclaredType,
    EnumerationType,
    ExternalReferenceType,
    FormalParameter,
    ListType,
    RecordType,
    SchemaType,
    TypeDeclaration,
    UnionType,
)
from opspec.xpdl.sisarl_write import expression_text, literal_text
from opspec.xpdl.write_elements import append_raw_xml, each, sub, write_extended, xml_bool

__all__ = [
    "write_actual_parameters",
    "write_assignments",
    "write_data_fields",
    "write_data_type",
    "write_formal_parameters",
    "write_type_declaration",
]


def write_data_type(parent: etree._Element, data_type: DataType) -> None:
    if isinstance(data_type, BasicType):
        basic = sub(parent, "BasicType", Type=data_type.kind.value)
        for local, value in (("Length", data_type.length), ("Precision", data_type.precision),
                             ("Scale", data_type.scale)):
            if value is not None:
                sub(basic, local, str(value))
    elif isinstance(data_type, DeclaredType):
        sub(parent, "DeclaredType", Id=data_type.ref)
    elif isinstance(data_type, SchemaType):
        schema = sub(parent, "SchemaType")
        if data_type.raw_xml:
            append_raw_xml(schema, data_type.raw_xml)
    elif isinstance(data_type, ExternalReferenceType):
        sub(parent, "ExternalReference", location=data_type.location, xref=data_type.xref,
            namespace=data_type.namespace)
    elif isinstance(data_type, (RecordType, UnionType)):
        record = sub(parent, "RecordType" if isinstance(data_type, RecordType) else "UnionType")
        for index, member in enumerate(data_type.members, start=1):
            # XPDL 2.1 Members have no Name (the reader numbers them member1, member2…);
            # a real name is kept as the Name attribute some editors write.
            element = sub(record, "Member")
            if member.name != f"member{index}":
                element.set("Name", member.name)
            write_data_type(element, member.type)
    elif isinstance(data_type, EnumerationType):
        enumeration = sub(parent, "EnumerationType")
        for enum_value in data_type.values:
            sub(enumeration, "EnumerationValue", Name=enum_value)
    elif isinstance(data_type, ArrayType):
        array = sub(parent, "ArrayType", LowerIndex=str(data_type.lower or 0),
                    UpperIndex=str(data_type.upper if data_type.upper is not None else 0))
        write_data_type(array, data_type.element)
    elif isinstance(data_type, ListType):
        write_data_type(sub(parent, "ListType"), data_type.element)
    else:
        raise TypeError(f"cannot write data type {data_type!r}")


def write_data_fields(parent: etree._Element, fields: tuple[DataField, ...]) -> None:
    for container, field in each(parent, "DataFields", fields):
        element = sub(container, "DataField", Id=field.id, Name=field.name,
                      ReadOnly=xml_bool(True) if field.read_only else None,
                      IsArray=xml_bool(True) if field.is_array else None,
                      Correlation=xml_bool(True) if field.correlation else None)
        write_data_type(sub(element, "DataType"), field.type)
        if field.initial_value is not None:
            sub(element, "InitialValue", field.initial_value)
        elif field.initial is not None:
            sub(element, "InitialValue", literal_text(field.initial))
        if field.description is not None:
            sub(element, "Description", field.description)
        write_extended(element, field.extended_attributes)


def write_formal_parameters(parent: etree._Element,
                            parameters: tuple[FormalParameter, ...]) -> None:
    for container, parameter in each(parent, "FormalParameters", parameters):
        element = sub(container, "FormalParameter", Id=parameter.id, Mode=parameter.mode.value,
                      Name=parameter.name,
                      Required=xml_bool(True) if parameter.required else None,
                      IsArray=xml_bool(True) if parameter.is_array else None)
        write_data_type(sub(element, "DataType"), parameter.type)
        if parameter.description is not None:
            sub(element, "Description", parameter.description)


def _as_written(value: ActualParameter | Assignment) -> str | None:
    """An expression's text as the spec wrote it, else as opspec prints the parsed one."""
    if not value.text and value.expression is not None:
        return expression_text(value.expression)
    return value.text


def write_actual_parameters(parent: etree._Element,
                            parameters: tuple[ActualParameter, ...]) -> None:
    for container, parameter in each(parent, "ActualParameters", parameters):
        sub(container, "ActualParameter", _as_written(parameter))


def write_assignments(parent: etree._Element, assignments: tuple[Assignment, ...]) -> None:
    for container, assignment in each(parent, "Assignments", assignments):
        element = sub(container, "Assignment", AssignTime=assignment.assign_time)
        sub(element, "Target", assignment.target)
        sub(element, "Expression", _as_written(assignment))


def write_type_declaration(parent: etree._Element, declaration: TypeDeclaration) -> None:
    element = sub(parent, "TypeDeclaration", Id=declaration.id, Name=declaration.name)
    write_data_type(element, declaration.type)
    if declaration.description is not None:
        sub(element, "Description", declaration.description)
    write_extended(element, declaration.extended_attributes)
