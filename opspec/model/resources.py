"""Resources (XPDL class B and structure): participants, applications, pools and lanes."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from opspec.model.common import Element
from opspec.model.data import Assignment, FormalParameter

__all__ = ["Application", "Lane", "Participant", "ParticipantType", "Pool"]


class ParticipantType(enum.Enum):
    RESOURCE_SET = "RESOURCE_SET"
    RESOURCE = "RESOURCE"
    ROLE = "ROLE"
    ORGANIZATIONAL_UNIT = "ORGANIZATIONAL_UNIT"
    HUMAN = "HUMAN"
    SYSTEM = "SYSTEM"


@dataclass(frozen=True, slots=True, kw_only=True)
class Participant(Element):
    type: ParticipantType = ParticipantType.ROLE

    @property
    def is_human(self) -> bool:
        return self.type is ParticipantType.HUMAN


@dataclass(frozen=True, slots=True, kw_only=True)
class Application(Element):
    """An application an activity can invoke (a device operation, a software routine).

    ``kind`` names the XPDL 2.x application type when one was given (``WebService``,
    ``BusinessRule``, ``Script``…), else ``None``.

    ``script`` holds the statements of a JaWE/Shark script tool agent (ExtendedAttributes
    ``ToolAgentClass=…JavaScriptToolAgent`` or ``…BshToolAgent`` and ``Script="…"``), read as
    assignments over the formal parameters (and local variables), run in order; empty when the
    application is no script. The front end derives it from the extended attributes, which
    stay as written, so writing the package back keeps the script.
    """

    formal_parameters: tuple[FormalParameter, ...] = ()
    kind: str | None = None
    script: tuple[Assignment, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class Lane(Element):
    """A lane of a pool; ``performers`` are participant ids; lanes nest."""

    performers: tuple[str, ...] = ()
    lanes: tuple[Lane, ...] = ()
    parent_pool: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Pool(Element):
    process: str | None = None
    participant: str | None = None
    lanes: tuple[Lane, ...] = ()
    boundary_visible: bool = True

    def all_lanes(self) -> tuple[Lane, ...]:
        """Every lane of the pool, nested ones included, depth first."""
        out: list[Lane] = []
        stack = list(reversed(self.lanes))
        while stack:
            lane = stack.pop()
            out.append(lane)
            stack.extend(reversed(lane.lanes))
        return tuple(out)
