"""Workflow data: types, type declarations, data fields and parameters (XPDL class A/B)."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from opspec.errors import SourceLocation
from opspec.model.common import Element
from opspec.model.expressions import Expression

__all__ = [
    "ActualParameter",
    "ArrayType",
    "Assignment",
    "BasicKind",
    "BasicType",
    "DataField",
    "DataType",
    "DeclaredType",
    "EnumerationType",
    "ExternalReferenceType",
    "FormalParameter",
    "ListType",
    "ParameterMode",
    "RecordMember",
    "RecordType",
    "SchemaType",
    "TypeDeclaration",
    "UnionType",
    "is_structured",
    "structured_value",
]


class BasicKind(enum.Enum):
    STRING = "STRING"
    FLOAT = "FLOAT"
    INTEGER = "INTEGER"
    REFERENCE = "REFERENCE"
    DATETIME = "DATETIME"
    DATE = "DATE"
    TIME = "TIME"
    BOOLEAN = "BOOLEAN"
    PERFORMER = "PERFORMER"


@dataclass(frozen=True, slots=True)
class DataType:
    """Base of every data type."""


@dataclass(frozen=True, slots=True, kw_only=True)
class BasicType(DataType):
    kind: BasicKind
    length: int | None = None
    precision: int | None = None
    scale: int | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class DeclaredType(DataType):
    """Reference to a package :class:`TypeDeclaration` by id."""

    ref: str


@dataclass(frozen=True, slots=True, kw_only=True)
class SchemaType(DataType):
    """An inline XML schema, kept as raw XML text."""

    raw_xml: str = ""


@dataclass(frozen=True, slots=True, kw_only=True)
class ExternalReferenceType(DataType):
    location: str
    xref: str | None = None
    namespace: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class RecordMember:
    name: str
    type: DataType


@dataclass(frozen=True, slots=True, kw_only=True)
class RecordType(DataType):
    members: tuple[RecordMember, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class UnionType(DataType):
    members: tuple[RecordMember, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class EnumerationType(DataType):
    values: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class ArrayType(DataType):
    element: DataType
    lower: int | None = None
    upper: int | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class ListType(DataType):
    element: DataType


@dataclass(frozen=True, slots=True, kw_only=True)
class TypeDeclaration(Element):
    type: DataType


@dataclass(frozen=True, slots=True, kw_only=True)
class DataField(Element):
    """A package-wide or workflow-wide variable.

    ``initial_value`` is the text as written; ``initial`` is its typed value (parsed by the front
    end according to ``type``) or ``None`` when there is none or it could not be typed. Array
    and record fields (:func:`is_structured`) keep ``initial`` ``None``: their JSON initial
    value is read by :func:`structured_value` (the engine does, when it compiles the package).
    """

    type: DataType
    initial_value: str | None = None
    initial: str | int | float | bool | None = None
    is_array: bool = False
    correlation: bool = False
    read_only: bool = False


class ParameterMode(enum.Enum):
    IN = "IN"
    OUT = "OUT"
    INOUT = "INOUT"


@dataclass(frozen=True, slots=True, kw_only=True)
class FormalParameter(Element):
    type: DataType
    mode: ParameterMode = ParameterMode.IN
    is_array: bool = False
    required: bool = False


@dataclass(frozen=True, slots=True, kw_only=True)
class ActualParameter:
    """An actual parameter: the text as written and, when it parses, its expression.

    In XPDL 1.0 this is usually a bare data field id; in 2.x an expression.
    """

    text: str
    expression: Expression | None = None
    location: SourceLocation | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Assignment:
    """XPDL 2.1 ``Assignment``: set data field ``target`` to ``expression`` at the activity's
    ``Start`` or ``End`` (``assign_time``), or when a transition is taken."""

    target: str
    text: str
    expression: Expression | None = None
    assign_time: str = "End"
    location: SourceLocation | None = None


def is_structured(data_type: DataType, is_array: bool = False,
                  declarations: tuple[TypeDeclaration, ...] = ()) -> bool:
    """True for array, list and record data (``ArrayType``, ``ListType``, ``RecordType``,
    XPDL 1.0 ``IsArray="TRUE"``, or a ``DeclaredType`` naming one of them)."""
    if is_array:
        return True
    seen: set[str] = set()
    while isinstance(data_type, DeclaredType) and data_type.ref not in seen:
        seen.add(data_type.ref)
        declared = next((d for d in declarations if d.id == data_type.ref), None)
        if declared is None:
            return False
        data_type = declared.type
    return isinstance(data_type, ArrayType | ListType | RecordType)


def structured_value(text: str, data_type: DataType, is_array: bool = False,
                     declarations: tuple[TypeDeclaration, ...] = ()) -> object:
    """The value of an array or record ``InitialValue``, written in JSON: ``[1, 2, 3]``,
    ``[[0, 1], [1, 0]]``, ``{"x": 1.5, "y": 0}``. Arrays become tuples (values are shared by
    every instance, so they are immutable), records dicts. Raises ``ValueError`` saying what
    was expected."""
    import json

    try:
        value = json.loads(text)
    except json.JSONDecodeError as error:
        raise ValueError(f"{text.strip()!r} is not a JSON value ({error.msg} at column "
                         f"{error.colno})") from None
    record = not is_array and _resolved(data_type, declarations)
    if record and not isinstance(value, dict):
        raise ValueError(f"a record's initial value is a JSON object such as "
                         f'{{"x": 1, "y": 2}}, not {text.strip()!r}')
    if not record and not isinstance(value, list):
        raise ValueError(f"an array's initial value is a JSON list such as [1, 2, 3], "
                         f"not {text.strip()!r}")
    return _frozen(value)


def _resolved(data_type: DataType, declarations: tuple[TypeDeclaration, ...]) -> bool:
    """True when ``data_type`` is (or declares) a RecordType."""
    seen: set[str] = set()
    while isinstance(data_type, DeclaredType) and data_type.ref not in seen:
        seen.add(data_type.ref)
        declared = next((d for d in declarations if d.id == data_type.ref), None)
        if declared is None:
            return False
        data_type = declared.type
    return isinstance(data_type, RecordType)


def _frozen(value: object) -> object:
    if isinstance(value, list):
        return tuple(_frozen(item) for item in value)
    if isinstance(value, dict):
        return {key: _frozen(item) for key, item in value.items()}
    return value
