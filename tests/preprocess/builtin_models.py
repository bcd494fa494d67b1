"""Models for the writer and preprocessor tests: a package using every built-in, and the
official XPDL 2.1 schema check."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Any

from lxml import etree

from opspec.model import (
    Activity,
    ActivityDirectives,
    BasicKind,
    BasicType,
    CoordinationBuiltIn,
    CoordinationKind,
    DataField,
    Event,
    EventPosition,
    Lane,
    Package,
    Participant,
    ParticipantType,
    Pool,
    ProcessDirectives,
    Route,
    Transition,
    Trigger,
    TriggerRef,
    WorkflowMode,
    WorkflowProcess,
)

SCHEMA_PATH = Path("/work/shared/corpus/schemas/bpmnxpdl_31.localimport.xsd")
DATA = Path(__file__).parent / "data"

BUILTINS = {
    "arbiter": CoordinationBuiltIn(kind=CoordinationKind.ARBITER,
                                   inputs=("avoid_cmd", "wander_cmd"), output="motor_cmd"),
    "voter": CoordinationBuiltIn(kind=CoordinationKind.VOTER,
                                 inputs=("vote_a", "vote_b", "vote_c"), output="motor_cmd",
                                 options=("forward", "left", "stop")),
    "superposition": CoordinationBuiltIn(kind=CoordinationKind.SUPERPOSITION,
                                         inputs=("v_avoid", "v_goal"), weights=(0.7, 0.3),
                                         output="v"),
    "push": CoordinationBuiltIn(kind=CoordinationKind.PUSH_DATA, channel="range",
                                inputs=("distance",)),
    "pull": CoordinationBuiltIn(kind=CoordinationKind.PULL_DATA, channel="range",
                                output="distance"),
    "mode-change": CoordinationBuiltIn(kind=CoordinationKind.MODE_CHANGE, target_mode="dock"),
}


def _field(field_id: str, kind: BasicKind, initial: str) -> DataField:
    return DataField(id=field_id, type=BasicType(kind=kind), initial_value=initial)


def builtin_process(key: str) -> WorkflowProcess:
    """start -> <built-in activity> -> end, with the built-in ``BUILTINS[key]``."""
    pid = f"p_{key.replace('-', '_')}"
    return WorkflowProcess(
        id=pid,
        name=f"uses the {key} built-in",
        activities=(
            Activity(id=f"{pid}_start", body=Event(position=EventPosition.START),
                     lane="device_lane"),
            Activity(id=f"{pid}_coordinate", name=f"{key} built-in", body=Route(),
                     performers=("robot",), lane="device_lane", coordination=BUILTINS[key],
                     directives=ActivityDirectives(priority_increment=1)),
            Activity(id=f"{pid}_end", body=Event(position=EventPosition.END,
                                                 trigger=Trigger(catching=False),
                                                 result="None"),
                     lane="device_lane"),
        ),
        transitions=(
            Transition(id=f"{pid}_t1", source=f"{pid}_start", target=f"{pid}_coordinate"),
            Transition(id=f"{pid}_t2", source=f"{pid}_coordinate", target=f"{pid}_end"),
        ),
        directives=ProcessDirectives(period=0.1, priority=2,
                                     start_trigger=TriggerRef(kind="period", every=0.1)),
    )


def builtin_package(keys: tuple[str, ...] = tuple(BUILTINS)) -> Package:
    fields = (
        _field("avoid_cmd", BasicKind.STRING, '""'),
        _field("wander_cmd", BasicKind.STRING, '"forward"'),
        _field("motor_cmd", BasicKind.STRING, '""'),
        _field("vote_a", BasicKind.STRING, '"left"'),
        _field("vote_b", BasicKind.STRING, '"left"'),
        _field("vote_c", BasicKind.STRING, '"stop"'),
        _field("v_avoid", BasicKind.FLOAT, "1.0"),
        _field("v_goal", BasicKind.FLOAT, "2.0"),
        _field("v", BasicKind.FLOAT, "0.0"),
        _field("distance", BasicKind.FLOAT, "0.0"),
    )
    return Package(
        id="robot",
        name="Robot using every coordination built-in",
        participants=(Participant(id="robot", type=ParticipantType.SYSTEM),),
        data_fields=fields,
        pools=(Pool(id="robot_pool", process=f"p_{keys[0].replace('-', '_')}",
                    lanes=(Lane(id="device_lane", performers=("robot",)),)),),
        processes=tuple(builtin_process(key) for key in keys),
        modes=(WorkflowMode(id="dock", workflows=tuple(
            f"p_{k.replace('-', '_')}" for k in keys)),),
    )


def schema_errors(schema: etree.XMLSchema, data: bytes) -> list[str]:
    document = etree.fromstring(data)
    if schema.validate(document):
        return []
    return [f"{e.line}: {e.message}" for e in schema.error_log]


def without_locations(value: Any) -> Any:
    """``value`` with every source location removed (a rewrite moves every line), and the
    whitespace between the tags of verbatim extension XML collapsed (a rewrite re-indents
    it; whitespace between elements carries nothing there)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        changes = {}
        for f in dataclasses.fields(value):
            item = getattr(value, f.name)
            if f.name == "raw_xml" and isinstance(item, str):
                squashed = re.sub(r">\s+<", "><", item.strip())
                if squashed != item:
                    changes[f.name] = squashed
                continue
            new = None if f.name == "location" else without_locations(item)
            if new is not item:
                changes[f.name] = new
        return dataclasses.replace(value, **changes) if changes else value
    if isinstance(value, tuple):
        return tuple(without_locations(item) for item in value)
    return value
