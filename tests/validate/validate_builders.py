"""Small builders for models made in Python, with source locations so tests can assert
``path:line``. Every builder takes the line its element is "written" on."""

from __future__ import annotations

from typing import Any

from opspec.errors import Diagnostic, SourceLocation
from opspec.model import (
    Activity,
    BasicKind,
    BasicType,
    Condition,
    ConditionKind,
    DataField,
    Event,
    EventPosition,
    Expression,
    Package,
    Participant,
    ParticipantType,
    Transition,
    WorkflowProcess,
)

PATH = "specs/pump.xpdl"


def loc(line: int) -> SourceLocation:
    return SourceLocation(PATH, line)


def act(activity_id: str, line: int, **fields: Any) -> Activity:
    return Activity(id=activity_id, location=loc(line), **fields)


def start(activity_id: str = "start", line: int = 10) -> Activity:
    return act(activity_id, line, body=Event(position=EventPosition.START))


def end(activity_id: str = "end", line: int = 12) -> Activity:
    return act(activity_id, line, body=Event(position=EventPosition.END))


def tr(transition_id: str, source: str, target: str, line: int = 30, *,
       kind: ConditionKind = ConditionKind.NONE, text: str | None = None,
       expression: Expression | None = None, exception: str | None = None,
       **fields: Any) -> Transition:
    condition = Condition(kind=kind, text=text, expression=expression, exception_name=exception)
    return Transition(id=transition_id, source=source, target=target, condition=condition,
                      location=loc(line), **fields)


def field(field_id: str, line: int = 4, kind: BasicKind = BasicKind.INTEGER) -> DataField:
    return DataField(id=field_id, type=BasicType(kind=kind), location=loc(line))


def process(process_id: str = "Pump", activities: tuple[Activity, ...] | None = None,
            transitions: tuple[Transition, ...] | None = None, line: int = 8,
            **fields: Any) -> WorkflowProcess:
    """A clean three-step process start -> work -> end unless told otherwise."""
    if activities is None:
        activities = (start(), act("work", 11, performers=("pump",)), end())
    if transitions is None:
        transitions = (tr("t1", "start", "work", 30), tr("t2", "work", "end", 31))
    return WorkflowProcess(id=process_id, activities=activities, transitions=transitions,
                           location=loc(line), **fields)


def package(*processes: WorkflowProcess, **fields: Any) -> Package:
    fields.setdefault("participants", (
        Participant(id="pump", type=ParticipantType.SYSTEM, location=loc(3)),
        Participant(id="user", type=ParticipantType.HUMAN, location=loc(3))))
    return Package(id="pkg", source=PATH, location=loc(2),
                   processes=processes or (process(),), **fields)


def with_code(diagnostics: list[Diagnostic], code: str) -> list[Diagnostic]:
    return [d for d in diagnostics if d.code == code]


def one(diagnostics: list[Diagnostic], code: str) -> Diagnostic:
    found = with_code(diagnostics, code)
    assert len(found) == 1, f"expected one {code!r}, got {[str(d) for d in diagnostics]}"
    return found[0]
