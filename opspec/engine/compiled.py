"""Compile a model :class:`~opspec.model.Package` into runtime tables, once per package.

A :class:`CompiledPackage` is immutable after :func:`compile_package` returns and is shared by
every :class:`~opspec.engine.simulation.Simulation` built from it (an evaluation builds
thousands), so everything that does not depend on one run is decided here: activities are
indexed by small ints, outgoing transitions are kept in the declared split order and split by
condition kind, joins know their incoming transitions, conditions/assignments/deadlines are
compiled closures, subflow targets and parameter mappings are resolved, distributions are
samplers, lanes and participants are looked up.

What an activity *is* at run time is one of the ``K_*`` kinds below; the interpreter
(:mod:`opspec.engine.interpreter`) dispatches on it. How each construct of the model becomes
these tables is :mod:`opspec.engine.compiling` (one small compiler per construct).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, Final

from opspec.engine.sampling import Sampler
from opspec.errors import SourceLocation
from opspec.model import CoordinationBuiltIn, Package, ParameterMode
from opspec.model.bulk import gc_paused

__all__ = [
    "J_AND",
    "J_COMPLEX",
    "J_COUNT",
    "J_OR",
    "J_XOR",
    "K_ASYNC",
    "K_BLOCK",
    "K_CATCH",
    "K_COORD",
    "K_GATEWAY",
    "K_MANUAL",
    "K_NOOP",
    "K_SUBFLOW",
    "K_TASK",
    "K_THROW",
    "MI_ALL",
    "MI_CANCEL",
    "MI_COMPLEX",
    "MI_NONE",
    "MI_ONE",
    "S_AND",
    "S_OR",
    "S_XOR",
    "CTool",
    "CTransition",
    "CTrigger",
    "CompiledActivity",
    "CompiledGraph",
    "CompiledPackage",
    "CompiledProcess",
    "Evaluator",
    "FlagCache",
    "compile_package",
    "expand_selectors_over",
]

Evaluator = Callable[[Mapping[str, Any], float], Any]
"""A compiled expression: ``fn(data, now) -> value``."""

# activity kinds
K_NOOP: Final = 0
K_TASK: Final = 1
K_MANUAL: Final = 2
K_SUBFLOW: Final = 3
K_ASYNC: Final = 4
K_CATCH: Final = 5
K_THROW: Final = 6
K_BLOCK: Final = 7
K_COORD: Final = 8
K_GATEWAY: Final = 9
KIND_NAMES = ("noop", "task", "manual", "subflow", "async-subflow", "catch", "throw", "block",
              "coordination", "event-gateway")
# joins and splits
J_XOR: Final = 0
J_AND: Final = 1
J_OR: Final = 2
J_COMPLEX: Final = 3
J_COUNT: Final = 4      # StartQuantity > 1 without another join: starts once per N arriving tokens
S_XOR: Final = 0
S_AND: Final = 1
S_OR: Final = 2
# multi-instance flow conditions: when the token moves on
MI_NONE: Final = 0
MI_ONE: Final = 1
MI_ALL: Final = 2
MI_COMPLEX: Final = 3
MI_CANCEL: Final = 4    # BPMN completionCondition: like MI_COMPLEX, and the rest are cancelled
# transition kinds
T_NONE: Final = 0
T_COND: Final = 1
T_OTHERWISE: Final = 2
T_EXCEPTION: Final = 3
T_DEFAULT: Final = 4


@dataclass(frozen=True, slots=True, eq=False)
class CTrigger:
    """A start/end/catch/throw trigger ready to arm: ``kind`` is message, signal, timer,
    period, rule or none."""

    kind: str
    name: str | None = None
    at: tuple[float, ...] = ()
    every: float | None = None
    offset: float = 0.0
    seconds: Evaluator | None = None       # timer catch events: delay from data
    condition: Evaluator | None = None     # rules
    location: SourceLocation | None = None
    count: int = -1                        # period: number of firings (-1: no end)
    planned: bool = False                  # timer: a TimeDate / repeating interval whose
    #                                        firings are ``offset``, +``every``… (``count``)
    anchored: bool = False                 # planned: ``offset`` is a date (else the firings
    #                                        count from when the timer is armed)
    interval: Sampler | None = None        # arrival: the inter-arrival time, drawn each time


@dataclass(frozen=True, slots=True, eq=False)
class CTransition:
    index: int
    id: str
    target: int
    kind: int
    condition: Evaluator | None
    exception: str | None
    assignments: tuple[tuple[str, Evaluator], ...]
    label: str | None = None          # a ScriptGrammar="Text" condition: a label, no test
    probability: float = -1.0         # drawn with this probability (undecided gateway); < 0: none
    tokens: int = 1                   # tokens sent along it: Quantity x CompletionQuantity


@dataclass(frozen=True, slots=True, eq=False)
class CTool:
    """One application a task calls (XPDL 1.0 ``Tool``, 2.x ``TaskApplication``): its
    parameter mapping and, for a script tool agent's application, the compiled statements
    (``(variable, expression)`` in order; ``None`` when the application is no script)."""

    application: str
    params: tuple[tuple[ParameterMode, str, Evaluator | None, str | None], ...] = ()
    script: tuple[tuple[str, Evaluator], ...] | None = None


class FlagCache:
    """Which trace kinds a run's listeners want of an activity or process, as bits, and the
    listener selection they were computed for (one object: set in one store)."""

    __slots__ = ("bits", "key")

    def __init__(self, key: object, bits: int) -> None:
        self.key = key
        self.bits = bits


#: what an activity or process holds before any run asked: of no selection (never ``None``,
#: so the hot path reads ``flag_cache.key`` without a test first)
NO_FLAGS: Final = FlagCache(object(), 0)


@dataclass(slots=True, eq=False)
class CompiledActivity:
    """One activity of a graph, ready to run. Not mutated after compilation but for the
    caches a run fills (``flag_cache``, ``coord``)."""

    index: int
    id: str
    label: str
    process: str
    location: SourceLocation | None
    kind: int = K_NOOP
    general: bool = False            # a general activity (queued by the pooled processor)
    participant: str | None = None
    lane: str | None = None          # lane shown in the trace
    lanes: tuple[str, ...] = ()      # names a performer may be bound to, most specific first
    user_lane: bool = False
    join: int = J_XOR
    join_condition: Evaluator | None = None  # complex joins: fires when it holds
    in_slots: dict[int, int] = field(default_factory=dict)   # transition index -> join slot
    split: int = S_XOR
    # no declared split, or an AND split: when no transition's condition holds the path
    # ends there (XPDL 1.0 engines, JaWE/Shark); a declared XOR/OR split aborts (BPMN)
    path_may_end: bool = False
    out: tuple[CTransition, ...] = ()
    otherwise: tuple[CTransition, ...] = ()
    exceptions: tuple[CTransition, ...] = ()
    default_exception: CTransition | None = None
    choice: tuple[CTransition, ...] = ()      # deferred choice offered after completion
    labelled: bool = False                   # the choice is between labelled branches
    drawn: tuple[CTransition, ...] = ()      # an undecided gateway's branches, drawn at random
    inputs: tuple[str, ...] = ()             # run inputs its conditions read: drawn while unset
    start_assign: tuple[tuple[str, Evaluator], ...] = ()
    end_assign: tuple[tuple[str, Evaluator], ...] = ()
    raises: CTrigger | None = None
    trigger: CTrigger | None = None          # catch/throw events; activity start trigger
    start_trigger: CTrigger | None = None
    end_trigger: CTrigger | None = None
    terminate: bool = False                  # end event with Terminate result
    error: str | None = None                 # error end event: its error code ("": none)
    escalation: str | None = None            # escalation end/throw event: its code ("": none)
    catches_escalation: str | None = None    # boundary escalation event: its code ("": any)
    start_quantity: int = 1                  # J_COUNT: the tokens one start consumes
    deadlines: tuple[tuple[Evaluator, bool, str], ...] = ()   # (seconds, synchronous, exception)
    sampler: Sampler | None = None
    cpu: float = 0.0
    cpu_sampler: Sampler | None = None   # CpuDemand as a distribution: drawn per execution
    priority_increment: int = 0
    priority: int | None = None              # XPDL Activity/Priority: replaces the workflow's
    subflow: str | None = None
    params: tuple[tuple[ParameterMode, str, Evaluator | None, str | None], ...] = ()
    application: str | None = None
    tools: tuple[CTool, ...] = ()            # every application of a task, in order
    toolchain: bool = False                  # several tools or a script: run them in order
    loop: tuple[Evaluator | None, int | None, bool] | None = None
    # multi-instance: (how many, parallel, MI_* flow condition, ComplexMI_FlowCondition)
    mi: tuple[Evaluator, bool, int, Evaluator | None] | None = None
    # a collection multi-instance (Camunda's elementVariable): ``mi``'s first evaluator gives
    # the list, and each instance sees its own item under this name
    mi_element: str | None = None
    block: CompiledGraph | None = None
    coordination: CoordinationBuiltIn | None = None
    boundary: tuple[int, ...] = ()
    attached_to: int = -1
    interrupting: bool = True
    # OR joins: per incoming slot, the activities from which that slot's transition can be
    # reached without passing through the join (BPMN 2.0 Table 13.3's directed paths)
    or_reach: tuple[frozenset[int], ...] = ()
    fast: bool = False                       # instantaneous without any wait (no ActInst)
    plain: bool = False                      # waits, but without deadline/loop/trigger/boundary
    next: int = -1                           # the one unconditional successor, if that is all
    simple_end: bool = False                 # completes with no assignment/throw/raise/terminate
    # the one token of an instance without a frame can pass it (compiling.graphs._lone)
    lone: bool = False
    # which trace kinds the run's listeners want of it, as bits, with the selection they were
    # computed for (RunState.act_bits): one attribute read on the hot path, not a lookup
    flag_cache: FlagCache = NO_FLAGS
    # a coordination built-in's compiled fields (opspec.engine.coordinating.Coord), made at
    # its first run: one attribute read a run, not a look-up by the activity
    coord: Any = None

    def where(self) -> str:
        return str(self.location) if self.location is not None else "<built in Python>"


@dataclass(slots=True, eq=False)
class CompiledGraph:
    """The activities and transitions of a process or activity set."""

    name: str
    process: str
    activities: tuple[CompiledActivity, ...] = ()
    starts: tuple[int, ...] = ()
    by_id: dict[str, int] = field(default_factory=dict)
    has_or_join: bool = False
    # an ad-hoc activity set run one activity at a time (its starts in order), and its
    # AdHocCompletionCondition, checked whenever one of its activities has run
    sequential: bool = False
    completion: Evaluator | None = None


@dataclass(slots=True, eq=False)
class CompiledProcess:
    id: str
    label: str
    graph: CompiledGraph
    data: dict[str, Any]
    formals: tuple[tuple[str, ParameterMode], ...]
    priority: int
    lane: str | None
    start_trigger: CTrigger | None
    end_trigger: CTrigger | None
    auto_start: bool
    deadline: float | None
    mode: str | None
    location: SourceLocation | None
    # several start events with a trigger (BPMN 2.0 §10.4.2: each one independent): each
    # trigger with the start event it starts an instance at (only that one's path runs)
    start_events: tuple[tuple[CTrigger, int], ...] = ()
    # with several triggered start events: where an instance called as a subflow starts (its
    # none start events; BPMN 2.0 §13.3.4: the triggered ones "are ignored when the Process
    # is called from another Process")
    called_starts: tuple[int, ...] = ()
    flag_cache: FlagCache = NO_FLAGS       # as CompiledActivity.flag_cache
    # where an instance not started by a triggered start event starts when that is one
    # activity (its token then runs without a frame at first: opspec.engine.lone), else -1
    one_start: int = -1
    # from source, that token's plan (opspec.engine.plans: straight-line code, made per
    # package at its first run), which the ready queue calls as plan(inst, activities, _)
    plan: Any = None


@dataclass(slots=True, eq=False)
class CompiledPackage:
    """Everything a run needs from a package, computed once."""

    id: str
    source: str | None
    package: Package
    processes: dict[str, CompiledProcess]
    data: dict[str, Any]
    throwable: frozenset[str]
    modes: dict[str, frozenset[str]]
    initial_mode: str | None
    mode_sources: dict[str, str]
    # (kind, name) -> workflows with an activity that catches it (catch event, event-gateway
    # branch, boundary event, activity start trigger): where a reply is correlated
    catchers: dict[tuple[str, str], frozenset[str]] = field(default_factory=dict)
    _want_cache: dict[Any, frozenset[tuple[str, str | None, str | None]]] = field(
        default_factory=dict)
    # whether its workflows have their plans (opspec.engine.plans.attach: made at the
    # first run from source)
    plans: bool = False

    def expand_selectors(
        self, selectors: frozenset[tuple[str, str | None, str | None]]
    ) -> frozenset[tuple[str, str | None, str | None]]:
        """(kind, process, activity) keys matched by ``selectors`` (``None`` = any), cached."""
        cached = self._want_cache.get(selectors)
        if cached is not None:
            return cached
        result = expand_selectors_over(self.processes.values(), selectors)
        self._want_cache[selectors] = result
        return result


def expand_selectors_over(
    processes: Iterable[CompiledProcess],
    selectors: frozenset[tuple[str, str | None, str | None]], *, package_level: bool = True,
) -> frozenset[tuple[str, str | None, str | None]]:
    """(kind, process, activity) keys that ``selectors`` match among ``processes`` (their
    activities, nested blocks included), plus the package-level ``(kind, None, None)`` keys
    when ``package_level``. The interpreter calls it again with ``package_level=False`` for
    the workflows a mode change loads at run time, so listeners see their events too."""
    keys: set[tuple[str, str | None, str | None]] = set()
    pairs: list[tuple[str | None, str | None]] = [(None, None)] if package_level else []
    for proc in processes:
        pairs.append((proc.id, None))
        stack = [proc.graph]
        while stack:
            graph = stack.pop()
            for act in graph.activities:
                pairs.append((proc.id, act.id))
                if act.block is not None:
                    stack.append(act.block)
    for kind, process, activity in selectors:
        for pid, aid in pairs:
            if (process is None or process == pid) and (activity is None or activity == aid):
                keys.add((kind, pid, aid))
    return frozenset(keys)


def compile_package(package: Package) -> CompiledPackage:
    """Compile ``package`` (fatal problems raise :class:`~opspec.errors.SpecError` with the
    location of the element at fault). The compilers live in :mod:`opspec.engine.compiling`:
    a table of small compilers, one per construct."""
    from opspec.engine.compiling.graphs import compile_package as compile_graphs

    with gc_paused():       # a big package: no full collections while it is compiled
        return compile_graphs(package)
