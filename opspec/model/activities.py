"""Activities of every kind, with their events, triggers, deadlines, loops and restrictions.

XPDL 1.0 and 2.x spellings of the same thing arrive here as the same values: ``Tool`` and
``TaskApplication`` become :class:`TaskApplication`, ``BlockId`` and ``ActivitySetId`` become
:class:`BlockActivity`, ``AND``/``XOR`` and ``Parallel``/``Exclusive`` become
:class:`GatewayType` members.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from opspec.errors import SourceLocation
from opspec.model.common import Element
from opspec.model.data import ActualParameter, Assignment
from opspec.model.expressions import Expression
from opspec.model.sisarl import ActivityDirectives, CoordinationBuiltIn

__all__ = [
    "Activity",
    "ActivityBody",
    "BlockActivity",
    "Deadline",
    "Event",
    "EventPosition",
    "Execution",
    "GatewayType",
    "Join",
    "Loop",
    "LoopKind",
    "MIFlow",
    "Mode",
    "NoImplementation",
    "Reference",
    "Route",
    "Split",
    "SubFlow",
    "Task",
    "TaskApplication",
    "TaskKind",
    "Trigger",
    "TriggerKind",
]


class GatewayType(enum.Enum):
    XOR = "XOR"              # exclusive, data-based (XPDL 1.0 XOR, 2.x Exclusive)
    EVENT = "EVENT"          # exclusive, event-based (deferred choice)
    AND = "AND"              # parallel
    OR = "OR"                # inclusive
    COMPLEX = "COMPLEX"


class Mode(enum.Enum):
    """StartMode / FinishMode."""

    AUTOMATIC = "Automatic"
    MANUAL = "Manual"


class Execution(enum.Enum):
    SYNCHR = "SYNCHR"
    ASYNCHR = "ASYNCHR"


class TaskKind(enum.Enum):
    APPLICATION = "application"   # XPDL 1.0 Tool / 2.x TaskApplication
    MANUAL = "manual"
    USER = "user"
    SCRIPT = "script"
    SERVICE = "service"
    SEND = "send"
    RECEIVE = "receive"
    REFERENCE = "reference"
    BUSINESS_RULE = "business-rule"


class TriggerKind(enum.Enum):
    NONE = "none"
    MESSAGE = "message"
    TIMER = "timer"
    RULE = "rule"                 # 2.0 Rule, 2.1+ Conditional
    SIGNAL = "signal"
    LINK = "link"
    ERROR = "error"
    ESCALATION = "escalation"
    COMPENSATION = "compensation"
    CANCEL = "cancel"
    TERMINATE = "terminate"
    MULTIPLE = "multiple"
    PARALLEL_MULTIPLE = "parallel-multiple"


class EventPosition(enum.Enum):
    START = "start"
    INTERMEDIATE = "intermediate"
    END = "end"


class LoopKind(enum.Enum):
    STANDARD = "standard"
    MULTI_INSTANCE = "multi-instance"


@dataclass(frozen=True, slots=True, kw_only=True)
class Trigger:
    """What an event waits for or throws.

    ``name`` is the message, signal, link or error name (or code); timers carry
    ``time_date``/``time_cycle`` as written plus ``duration``, a parsed expression giving seconds
    when the front end understood it; rules carry ``condition``. ``attached_to`` is the activity
    a boundary (intermediate) event is attached to; ``interrupting`` tells whether it cancels it.
    """

    kind: TriggerKind = TriggerKind.NONE
    name: str | None = None
    time_date: str | None = None
    time_cycle: str | None = None
    duration: Expression | None = None
    condition: Expression | None = None
    attached_to: str | None = None
    interrupting: bool = True
    catching: bool = True
    # timers, as read by the front end: ``date`` is a TimeDate (or the start of a repeating
    # interval ``Rn/start/period``) in seconds, counted from 1970-01-01 when ``calendar`` (the
    # engine makes the package's earliest calendar date day 1 of the run) else from day 1
    # 00:00; ``repeat`` is 0 for a plain TimeCycle duration, n for ``Rn/…``, -1 for ``R/…``
    # (the period is ``duration``).
    date: float | None = None
    calendar: bool = False
    repeat: int = 0


@dataclass(frozen=True, slots=True)
class ActivityBody:
    """Base of what an activity *is* (its XPDL implementation or kind)."""


@dataclass(frozen=True, slots=True)
class NoImplementation(ActivityBody):
    """``Implementation/No``: performed outside the engine (manual work, a device)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class TaskApplication:
    application: str
    actual_parameters: tuple[ActualParameter, ...] = ()
    package_ref: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Task(ActivityBody):
    kind: TaskKind
    applications: tuple[TaskApplication, ...] = ()
    message: str | None = None
    script: str | None = None
    implementation: str | None = None       # WebService / Unspecified / Other, as written


@dataclass(frozen=True, slots=True, kw_only=True)
class SubFlow(ActivityBody):
    process: str
    execution: Execution = Execution.SYNCHR
    actual_parameters: tuple[ActualParameter, ...] = ()
    package_ref: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Reference(ActivityBody):
    """XPDL 2.x ``Reference``: this activity is another activity of the process."""

    activity: str


@dataclass(frozen=True, slots=True, kw_only=True)
class Route(ActivityBody):
    """A gateway: it only routes; its join/split behaviour is in the activity's restrictions."""

    gateway: GatewayType = GatewayType.XOR


@dataclass(frozen=True, slots=True, kw_only=True)
class BlockActivity(ActivityBody):
    activity_set: str
    start_activity: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Event(ActivityBody):
    position: EventPosition
    trigger: Trigger = Trigger()
    result: str | None = None      # end events: None, Message, Error, Terminate…


@dataclass(frozen=True, slots=True, kw_only=True)
class Deadline:
    """``Deadline``: when ``duration`` (seconds) elapses, raise ``exception_name``.

    Synchronous deadlines interrupt the activity; asynchronous ones let it run on and start the
    exception path beside it.
    """

    duration_text: str
    duration: Expression | None = None
    execution: Execution = Execution.SYNCHR
    exception_name: str | None = None
    location: SourceLocation | None = None


class MIFlow(enum.Enum):
    """``MI_FlowCondition`` of a multi-instance loop: when the token moves on (BPMN 1.2 §9.4)."""

    NONE = "None"            # after every instance (one token each)
    ONE = "One"              # after the first instance; the others run on, passing nothing
    ALL = "All"              # after the last instance
    COMPLEX = "Complex"      # once ``flow_condition`` holds after an instance completes


@dataclass(frozen=True, slots=True, kw_only=True)
class Loop:
    """``Loop``: a standard loop (``condition``/``maximum``/``test_before``) or a
    multi-instance loop (``condition`` is the MI_Condition, the number of instances, with
    ``parallel`` ordering, ``flow`` and the ComplexMI_FlowCondition ``flow_condition``;
    ``cancel_remaining`` when it is BPMN's completionCondition)."""

    kind: LoopKind = LoopKind.STANDARD
    condition: Expression | None = None
    condition_text: str | None = None
    maximum: int | None = None
    test_before: bool = False
    parallel: bool = False
    flow: MIFlow = MIFlow.ALL
    flow_condition: Expression | None = None
    flow_condition_text: str | None = None
    # BPMN's completionCondition: once it holds, the instances still running are cancelled
    # and those not started never start (XPDL's ComplexMI_FlowCondition lets them run on)
    cancel_remaining: bool = False
    # a multi-instance over a collection (Camunda's collection/elementVariable): ``condition``
    # gives the list, one instance per item, and each instance reads its own item under this
    # name (no other instance sees it)
    element_variable: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Join:
    """A join; a Complex join fires when ``condition`` (the gateway's IncomingCondition, over
    data fields and ``activationCount``, the number of incoming transitions that have
    delivered a token) holds."""

    type: GatewayType = GatewayType.XOR
    condition: Expression | None = None
    condition_text: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Split:
    """A split; ``transition_refs`` keeps the declared order (XOR evaluates in this order)."""

    type: GatewayType = GatewayType.XOR
    transition_refs: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class Activity(Element):
    """One node of a process graph. Ids are scoped per process (and per activity set)."""

    body: ActivityBody = NoImplementation()
    performers: tuple[str, ...] = ()
    start_mode: Mode = Mode.AUTOMATIC
    finish_mode: Mode = Mode.AUTOMATIC
    priority: int | None = None
    deadlines: tuple[Deadline, ...] = ()
    loop: Loop | None = None
    join: Join | None = None
    split: Split | None = None
    lane: str | None = None
    directives: ActivityDirectives = ActivityDirectives()
    coordination: CoordinationBuiltIn | None = None
    assignments: tuple[Assignment, ...] = ()
    # XPDL 2.1 StartQuantity / CompletionQuantity, BPMN startQuantity / completionQuantity:
    # the tokens that must arrive before it starts (thread merge, WCP-41), and the tokens it
    # sends down each outgoing transition it takes (thread split, WCP-42)
    start_quantity: int = 1
    completion_quantity: int = 1
    # XPDL 2.x Activity StartActivity="true": where an instance starts when nothing else
    # says (every activity of the level has an incoming transition, no start event)
    marked_start: bool = False

    @property
    def is_route(self) -> bool:
        return isinstance(self.body, Route)

    @property
    def is_manual(self) -> bool:
        """True when the activity waits for its performer instead of running by itself."""
        if self.directives.auto_run is not None:
            return not self.directives.auto_run
        if self.start_mode is Mode.MANUAL:
            return True
        return isinstance(self.body, Task) and self.body.kind in (TaskKind.MANUAL, TaskKind.USER)
