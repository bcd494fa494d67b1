"""The immutable specification model: frozen dataclasses and tuples, no I/O, no lxml.

Everything the front end reads ends up here; the engine runs these values. A model can be
built in plain Python (tests do) and round-trips through the ``.wfs`` JSON form.
"""

from opspec.model.activities import (
    Activity,
    ActivityBody,
    BlockActivity,
    Deadline,
    Event,
    EventPosition,
    Execution,
    GatewayType,
    Join,
    Loop,
    LoopKind,
    MIFlow,
    Mode,
    NoImplementation,
    Reference,
    Route,
    Split,
    SubFlow,
    Task,
    TaskApplication,
    TaskKind,
    Trigger,
    TriggerKind,
)
from opspec.model.common import Element, ExtendedAttribute, find_extended
from opspec.model.data import (
    ActualParameter,
    ArrayType,
    Assignment,
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
)
from opspec.model.expressions import Binary, Call, Expression, Literal, Name, Unary
from opspec.model.package import ExternalPackage, Package, PackageHeader, XpdlVersion
from opspec.model.process import (
    ActivitySet,
    Condition,
    ConditionKind,
    ProcessHeader,
    Transition,
    WorkflowProcess,
)
from opspec.model.resources import Application, Lane, Participant, ParticipantType, Pool
from opspec.model.sisarl import (
    ActivityDirectives,
    CoordinationBuiltIn,
    CoordinationKind,
    Distribution,
    EventSelector,
    MetricDefinition,
    MetricKind,
    ProcessDirectives,
    TriggerRef,
)
from opspec.model.sisarl import Mode as WorkflowMode

__all__ = [
    "Activity", "ActivityBody", "ActivityDirectives", "ActivitySet", "ActualParameter",
    "Application", "ArrayType", "Assignment", "BasicKind", "BasicType", "Binary", "BlockActivity", "Call",
    "Condition", "ConditionKind", "CoordinationBuiltIn", "CoordinationKind", "DataField",
    "DataType", "Deadline", "DeclaredType", "Distribution", "Element", "EnumerationType",
    "Event", "EventPosition", "EventSelector", "Execution", "Expression", "ExtendedAttribute",
    "ExternalPackage", "ExternalReferenceType", "FormalParameter", "GatewayType", "Join",
    "Lane", "ListType", "Literal", "Loop", "LoopKind", "MIFlow", "MetricDefinition", "MetricKind", "Mode",
    "Name", "NoImplementation", "Package", "PackageHeader", "ParameterMode", "Participant",
    "ParticipantType", "Pool", "ProcessDirectives", "ProcessHeader", "RecordMember",
    "RecordType", "Reference", "Route", "SchemaType", "Split", "SubFlow", "Task",
    "TaskApplication", "TaskKind", "Transition", "Trigger", "TriggerKind", "TriggerRef",
    "TypeDeclaration", "Unary", "UnionType", "WorkflowMode", "WorkflowProcess", "XpdlVersion",
    "find_extended",
]
