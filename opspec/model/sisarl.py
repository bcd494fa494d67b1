"""SISARL-XPDL extensions: engine directives, behaviour-coordination built-ins, stochastic
parameters and declared metrics.

How each is written in a file is documented in ``docs/sisarl-xpdl.md``; this module is only the
parsed, immutable form. Times are seconds (floats) once parsed.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from opspec.errors import SourceLocation
from opspec.model.expressions import Expression

__all__ = [
    "ActivityDirectives",
    "CoordinationBuiltIn",
    "CoordinationKind",
    "DeclaredDistribution",
    "EventSelector",
    "MetricDefinition",
    "MetricKind",
    "ProcessDirectives",
    "TriggerRef",
    "WorkflowMode",
]


@dataclass(frozen=True, slots=True, kw_only=True)
class DeclaredDistribution:
    """A stochastic parameter in BPSim style: ``kind`` is a BPSim distribution name
    (``LogNormalDistribution``, ``ConstantParameter``, ``UniformDistribution``…) or an opspec
    name, and ``parameters`` are its named values in declaration order."""

    kind: str
    parameters: tuple[tuple[str, float], ...] = ()

    def get(self, key: str, default: float | None = None) -> float | None:
        for name, value in self.parameters:
            if name == key:
                return value
        return default


@dataclass(frozen=True, slots=True, kw_only=True)
class TriggerRef:
    """A named trigger a workflow or activity starts or ends on.

    ``kind`` is one of ``none``, ``timer``, ``period``, ``message``, ``signal``, ``rule``.
    ``name`` is the message/signal name; ``at`` lists absolute times of day in seconds for
    calendar timers; ``every`` is a period in seconds; ``condition`` is a rule.
    """

    kind: str
    name: str | None = None
    at: tuple[float, ...] = ()
    every: float | None = None
    offset: float = 0.0
    condition: Expression | None = None
    location: SourceLocation | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class ProcessDirectives:
    """Engine directives of a workflow (SISARL-XPDL)."""

    period: float | None = None          # seconds between periodic starts (rate = 1/period)
    priority: int | None = None           # WfPriority
    deadline: float | None = None         # latency bound of one instance, seconds
    start_trigger: TriggerRef | None = None
    end_trigger: TriggerRef | None = None
    auto_start: bool | None = None        # start at engine start (None: only when triggered)
    lane: str | None = None               # "device" or "user" role of the process, if declared
    mode: str | None = None               # the mode this workflow belongs to, if any
    # stochastic arrivals (opspec:Arrival; BPSim InterTriggerTimer, QBP arrivalRateDistribution
    # in BPMN): an instance when the run starts, then one after each inter-arrival time drawn
    # from ``arrival`` (seconds), ``arrival_count`` instances in all (None: no end)
    arrival: DeclaredDistribution | None = None
    arrival_count: int | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class ActivityDirectives:
    """Engine directives of an activity (SISARL-XPDL)."""

    auto_run: bool | None = None          # False: manual, waits for its performer
    priority_increment: int = 0
    start_trigger: TriggerRef | None = None
    end_trigger: TriggerRef | None = None
    cpu_demand: float | None = None       # seconds of processor time (software activities)
    # processor time drawn per execution, when CpuDemand is a distribution (cpu_demand None)
    cpu_distribution: DeclaredDistribution | None = None
    duration: DeclaredDistribution | None = None  # simulated duration (BPSim ProcessingTime)
    raises: TriggerRef | None = None      # trigger raised when the activity completes


class CoordinationKind(enum.Enum):
    ARBITER = "arbiter"                   # fixed-priority arbiter
    VOTER = "voter"
    SUPERPOSITION = "superposition"
    PUSH_DATA = "push"
    PULL_DATA = "pull"
    MODE_CHANGE = "mode-change"


@dataclass(frozen=True, slots=True, kw_only=True)
class CoordinationBuiltIn:
    """A behaviour-coordination built-in carried by an activity.

    - arbiter: ``inputs`` are command data fields in priority order (highest first);
      ``output`` receives the winning command.
    - voter: ``inputs`` are vote data fields; ``options`` the commands voted on; ties are
      broken by the order of ``options``.
    - superposition: ``inputs`` are vector data fields, ``weights`` their weights.
    - push/pull: ``channel`` names the supervisor mailbox; ``inputs`` (push) or ``output``
      (pull) the data field.
    - mode change: ``target_mode`` names the mode to switch to.
    """

    kind: CoordinationKind
    inputs: tuple[str, ...] = ()
    output: str | None = None
    weights: tuple[float, ...] = ()
    options: tuple[str, ...] = ()
    channel: str | None = None
    target_mode: str | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class WorkflowMode:
    """A named set of workflows active together; a mode change switches between them."""

    id: str
    workflows: tuple[str, ...] = ()
    initial: bool = False
    source: str | None = None             # href of a package to load when switching, if any
    location: SourceLocation | None = field(default=None, compare=False)  # where declared


class MetricKind(enum.Enum):
    COUNT = "count"          # number of matching trace events
    DURATION = "duration"    # seconds between two matching events of the same instance
    RATIO = "ratio"          # one metric divided by another


@dataclass(frozen=True, slots=True, kw_only=True)
class EventSelector:
    """Which trace events a metric looks at.

    ``event`` is a trace event kind (``activity.completed``, ``process.started``…);
    ``process``/``activity`` restrict by id (``None`` matches any); ``which`` picks the
    ``first`` or ``last`` match per process instance for durations.
    """

    event: str
    process: str | None = None
    activity: str | None = None
    which: str = "first"


@dataclass(frozen=True, slots=True, kw_only=True)
class MetricDefinition:
    """A metric declared in the spec and computed from the trace."""

    name: str
    kind: MetricKind
    description: str | None = None
    select: EventSelector | None = None        # COUNT
    start: EventSelector | None = None         # DURATION
    end: EventSelector | None = None           # DURATION
    numerator: str | None = None               # RATIO: metric names
    denominator: str | None = None
    #: RATIO: declared a proportion (``Proportion="true"``): each numerator event is one of
    #: the denominator's trials, at most one per trial; its interval is Wilson's, an
    #: undeclared ratio's the ratio's (docs/evaluation.md), never chosen from the data
    proportion: bool = False
    unit: str | None = None
    location: SourceLocation | None = None
