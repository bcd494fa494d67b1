"""Workflow processes, activity sets and transitions."""

from __future__ import annotations

import dataclasses
import enum
from dataclasses import dataclass

from opspec.model.activities import Activity
from opspec.model.common import Element, ExtendedAttribute, find_by_id
from opspec.model.data import Assignment, DataField, FormalParameter
from opspec.model.expressions import Expression
from opspec.model.resources import Application, Participant
from opspec.model.sisarl import ProcessDirectives

__all__ = [
    "ActivitySet",
    "Condition",
    "ConditionKind",
    "ProcessHeader",
    "Transition",
    "WorkflowProcess",
]


class ConditionKind(enum.Enum):
    NONE = "NONE"                       # unconditional
    CONDITION = "CONDITION"
    OTHERWISE = "OTHERWISE"
    EXCEPTION = "EXCEPTION"
    DEFAULTEXCEPTION = "DEFAULTEXCEPTION"


@dataclass(frozen=True, slots=True, kw_only=True)
class Condition:
    """A transition condition. ``text`` is what the file said; ``expression`` its parse (for
    CONDITION). For EXCEPTION, ``exception_name`` names the exception it catches (from the
    condition text), ``None`` meaning any."""

    kind: ConditionKind = ConditionKind.NONE
    text: str | None = None
    expression: Expression | None = None
    exception_name: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Transition(Element):
    """A sequence flow. ``probability`` is set on the flows out of a gateway whose choice the
    spec leaves undecided (no condition opspec can evaluate): the gateway then draws its
    branch with these probabilities (a simulation parameter: BPSim, QBP, ``opspec:Probability``,
    or uniform with a warning), as simulation tools for process models do."""

    source: str
    target: str
    condition: Condition = Condition()
    assignments: tuple[Assignment, ...] = ()
    probability: float | None = None
    quantity: int = 1          # XPDL 2.1 Transition Quantity: tokens sent along it each time

    def with_probability(self, probability: float, text: str | None = None) -> Transition:
        """This flow taken with ``probability``, written as its ``opspec:Probability``
        extended attribute (``text``, else ``repr(probability)``) in place of any earlier
        one, so that the spec written out says what runs."""
        kept = tuple(e for e in self.extended_attributes
                     if e.name not in ("opspec:Probability", "Probability"))
        written = ExtendedAttribute(name="opspec:Probability",
                                    value=repr(probability) if text is None else text)
        return dataclasses.replace(self, probability=probability,
                                   extended_attributes=(*kept, written))


@dataclass(frozen=True, slots=True, kw_only=True)
class ActivitySet(Element):
    """An activity set (embedded subprocess). An *ad hoc* one (BPMN ad-hoc subprocess) runs
    its activities in parallel or, with ``ad_hoc_sequential``, one at a time, until
    ``completion_condition`` holds (default: when all have run)."""

    activities: tuple[Activity, ...] = ()
    transitions: tuple[Transition, ...] = ()
    ad_hoc: bool = False
    ad_hoc_sequential: bool = False
    completion_condition: Expression | None = None
    completion_condition_text: str | None = None

    def activity(self, activity_id: str) -> Activity | None:
        return find_by_id(self.activities, activity_id)


@dataclass(frozen=True, slots=True, kw_only=True)
class ProcessHeader:
    created: str | None = None
    description: str | None = None
    priority: str | None = None
    limit: str | None = None
    valid_from: str | None = None
    valid_to: str | None = None
    duration: str | None = None
    duration_unit: str | None = None
    waiting_time: str | None = None
    working_time: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class WorkflowProcess(Element):
    header: ProcessHeader = ProcessHeader()
    access_level: str | None = None
    data_fields: tuple[DataField, ...] = ()
    formal_parameters: tuple[FormalParameter, ...] = ()
    participants: tuple[Participant, ...] = ()
    applications: tuple[Application, ...] = ()
    activities: tuple[Activity, ...] = ()
    transitions: tuple[Transition, ...] = ()
    activity_sets: tuple[ActivitySet, ...] = ()
    directives: ProcessDirectives = ProcessDirectives()
    priority: int | None = None
    assignments: tuple[Assignment, ...] = ()

    def activity(self, activity_id: str) -> Activity | None:
        """The top-level activity with this id (activity-set members are not searched)."""
        return find_by_id(self.activities, activity_id)

    def activity_set(self, set_id: str) -> ActivitySet | None:
        return find_by_id(self.activity_sets, set_id)

    def all_activities(self) -> tuple[Activity, ...]:
        """Top-level activities followed by those of every activity set."""
        out = list(self.activities)
        for activity_set in self.activity_sets:
            out.extend(activity_set.activities)
        return tuple(out)


