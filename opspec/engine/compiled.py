"""Compile a model :class:`~opspec.model.Package` into runtime tables, once per package.

A :class:`CompiledPackage` is immutable after :func:`compile_package` returns and is shared by
every :class:`~opspec.engine.simulation.Simulation` built from it (an evaluation builds
thousands), so everything that does not depend on one run is decided here: activities are
indexed by small ints, outgoing transitions are kept in the declared split order and split by
condition kind, joins know their incoming transitions, conditions/assignments/deadlines are
compiled closures, subflow targets and parameter mappings are resolved, distributions are
samplers, lanes and participants are looked up.

What an activity *is* at run time is one of the ``K_*`` kinds below; the interpreter
(:mod:`opspec.engine.interpreter`) dispatches on it.
"""

from __future__ import annotations

import datetime
import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from opspec.clock import try_duration
from opspec.engine.conditions import compile_condition, compile_expression
from opspec.engine.coordination import APPLICATION_BUILTINS, application_builtin
from opspec.engine.sampling import Sampler, make_sampler
from opspec.errors import OpspecError, SourceLocation, SpecError
from opspec.model import (
    Activity,
    Binary,
    BlockActivity,
    Call,
    ConditionKind,
    CoordinationBuiltIn,
    DataField,
    Event,
    EventPosition,
    Execution,
    Expression,
    GatewayType,
    Literal,
    LoopKind,
    MIFlow,
    Name,
    NoImplementation,
    Package,
    ParameterMode,
    Reference,
    Route,
    SubFlow,
    Task,
    TaskApplication,
    Transition,
    TriggerKind,
    TriggerRef,
    Unary,
    WorkflowProcess,
)
from opspec.model.bulk import gc_paused
from opspec.model.checks_support import names_read
from opspec.model.data import is_structured, structured_value

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
    "compile_package",
    "expand_selectors_over",
]

Evaluator = Callable[[Mapping[str, Any], float], Any]
"""A compiled expression: ``fn(data, now) -> value``."""

# activity kinds
K_NOOP, K_TASK, K_MANUAL, K_SUBFLOW, K_ASYNC, K_CATCH, K_THROW, K_BLOCK, K_COORD, K_GATEWAY = (
    range(10))
KIND_NAMES = ("noop", "task", "manual", "subflow", "async-subflow", "catch", "throw", "block",
              "coordination", "event-gateway")
# joins and splits
J_XOR, J_AND, J_OR, J_COMPLEX = range(4)
J_COUNT = 4      # StartQuantity > 1 without another join: starts once per N arriving tokens
S_XOR, S_AND, S_OR = range(3)
# multi-instance flow conditions: when the token moves on
MI_NONE, MI_ONE, MI_ALL, MI_COMPLEX = range(4)
MI_CANCEL = 4    # BPMN completionCondition: like MI_COMPLEX, and the rest are cancelled
# transition kinds
T_NONE, T_COND, T_OTHERWISE, T_EXCEPTION, T_DEFAULT = range(5)
# model kinds -> the above, made once (not a dict literal of enum keys per transition/activity)
_TRANSITION_KINDS: dict[ConditionKind, int] = {
    ConditionKind.NONE: T_NONE, ConditionKind.CONDITION: T_COND,
    ConditionKind.OTHERWISE: T_OTHERWISE, ConditionKind.EXCEPTION: T_EXCEPTION,
    ConditionKind.DEFAULTEXCEPTION: T_DEFAULT}
_JOINS: dict[GatewayType, int] = {GatewayType.AND: J_AND, GatewayType.OR: J_OR,
                                  GatewayType.COMPLEX: J_COMPLEX}
# a diverging complex gateway behaves as an inclusive one (BPMN 2.0 §13.3.6)
_SPLITS: dict[GatewayType, int] = {GatewayType.AND: S_AND, GatewayType.OR: S_OR,
                                   GatewayType.COMPLEX: S_OR}

_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_.]*$")
_USER_LANES = frozenset({"user", "user_lane", "user lane", "users"})


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


@dataclass(slots=True, eq=False)
class CompiledActivity:
    """One activity of a graph, ready to run. Not mutated after compilation."""

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


def _spec_error(message: str, location: SourceLocation | None, hint: str = "") -> SpecError:
    return SpecError(message, location=location, hint=hint)


class _Compiler:
    def __init__(self, package: Package) -> None:
        self.package = package
        self.throwable: set[str] = set()
        # package data fields a BPMN diagram's conditions read but nothing sets: a gateway
        # deciding on one is drawn at random while the run is not given its value
        self.run_inputs = frozenset(
            f.id for f in package.data_fields
            if any(e.name == "opspec:RunInput" for e in f.extended_attributes))
        self.participants = {p.id: p for p in package.participants}
        self.participant_lane: dict[str, tuple[str, ...]] = {}
        for pool in package.pools:
            for lane in pool.all_lanes():
                for performer in lane.performers:
                    names = tuple(n for n in (lane.id, lane.name) if n)
                    self.participant_lane.setdefault(performer, names)
        # calendar dates in timers: the earliest one's day is day 1 of the run
        dates = [a.body.trigger.date for p in package.processes for a in p.all_activities()
                 if isinstance(a.body, Event) and a.body.trigger.calendar
                 and a.body.trigger.date is not None]
        # ... and so are the dates data fields hold for a timeDate that reads them
        for proc in package.processes:
            fields = {f.id: f for f in (*package.data_fields, *proc.data_fields)}
            for a in proc.all_activities():
                trig = a.body.trigger if isinstance(a.body, Event) else None
                if (trig is not None and trig.time_date and trig.date is None
                        and isinstance(trig.duration, Name) and len(trig.duration.path) == 1):
                    held = fields.get(trig.duration.path[0])
                    moment = _moment(held.initial_value) if held is not None else None
                    if moment is not None:
                        dates.append(moment)
        self.anchor = min(d // 86_400.0 for d in dates) * 86_400.0 if dates else 0.0
        self.subflow_targets = {
            a.body.process for p in package.processes for a in p.all_activities()
            if isinstance(a.body, SubFlow)}

    # -- expressions -------------------------------------------------------------------
    def expr(self, expression: Expression | None, text: str | None,
             location: SourceLocation | None, what: str, condition: bool = False) -> Evaluator:
        if expression is None:
            if text is None or not text.strip():
                raise _spec_error(f"{what} has no expression", location)
            stripped = text.strip()
            if _IDENT.match(stripped) and stripped not in ("true", "false", "null"):
                expression = Name(tuple(stripped.split(".")))
            else:
                seconds = try_duration(stripped)
                if seconds is None:
                    raise _spec_error(f"{what} {stripped!r} was not understood", location,
                                      "write an expression over data fields")
                expression = Literal(seconds)
        try:
            if condition:
                return compile_condition(expression, location=location)
            return compile_expression(expression, location=location)
        except OpspecError as error:  # the evaluator rejects an expression it cannot run
            raise _spec_error(f"{what} cannot be evaluated: {error.message}", location) from None

    def cond(self, expression: Expression | None, text: str | None,
             location: SourceLocation | None, what: str) -> Evaluator:
        """Like :meth:`expr`, but the value is a boolean under the truthiness rules."""
        return self.expr(expression, text, location, what, condition=True)

    def seconds(self, expression: Expression | None, text: str | None,
                location: SourceLocation | None, what: str) -> Evaluator:
        if expression is None and text is not None:
            value = try_duration(text)
            if value is not None:
                return _constant(value)
        return self.expr(expression, text, location, what)

    def trigger_ref(self, ref: TriggerRef | None) -> CTrigger | None:
        if ref is None or ref.kind == "none":
            return None
        condition = None
        if ref.condition is not None:
            condition = self.cond(ref.condition, None, ref.location, "rule trigger")
        return CTrigger(kind=ref.kind, name=ref.name, at=tuple(sorted(ref.at)), every=ref.every,
                        offset=ref.offset, condition=condition, location=ref.location)

    def arrivals(self, proc: WorkflowProcess) -> CTrigger:
        """Stochastic arrivals: the first instance when armed, then one after each
        inter-arrival time drawn from the process's own stream (``arrivals/PROCESS``)."""
        directives = proc.directives
        assert directives.arrival is not None
        try:
            interval = make_sampler(directives.arrival)
        except ValueError as error:
            raise _spec_error(f"inter-arrival time of process {proc.id!r}: {error}",
                              proc.location, "see docs/sisarl-xpdl.md for the distributions"
                              ) from None
        count = directives.arrival_count
        return CTrigger(kind="arrival", name=proc.id, interval=interval,
                        count=-1 if count is None else count, location=proc.location)

    def event_trigger(self, event: Event, act: Activity) -> CTrigger | None:
        trig = event.trigger
        kind = trig.kind
        if kind in (TriggerKind.MESSAGE, TriggerKind.SIGNAL, TriggerKind.LINK,
                    TriggerKind.ERROR, TriggerKind.ESCALATION):
            name = trig.name or act.id
            mapped = "signal" if kind is TriggerKind.SIGNAL else "message"
            return CTrigger(kind=mapped, name=name, location=act.location)
        if kind is TriggerKind.TIMER and (trig.date is not None or trig.repeat != 0):
            return self.planned_timer(trig, act)
        if kind is TriggerKind.TIMER:
            seconds = None
            if trig.duration is not None or trig.time_cycle or trig.time_date:
                seconds = self.seconds(trig.duration, trig.time_cycle or trig.time_date,
                                       act.location, f"timer of activity {act.id!r}")
                if trig.time_date and not trig.time_cycle:
                    # a timeDate read from data: the date its value holds (or, as XPDL
                    # engines read a number there, a delay)
                    seconds = _date_or_delay(seconds, self.anchor, trig.time_date,
                                             act.location, act.id)
            return CTrigger(kind="timer", seconds=seconds, location=act.location)
        if kind is TriggerKind.RULE:
            cond = self.cond(trig.condition, None, act.location, f"rule of activity {act.id!r}")
            return CTrigger(kind="rule", condition=cond, location=act.location)
        return None

    def initial(self, data_field: DataField) -> Any:
        """A data field's initial value: typed by the front end, or, for arrays and records,
        read from its JSON text (arrays are tuples, records dicts)."""
        text = data_field.initial_value
        declarations = self.package.type_declarations
        if text is None or not is_structured(data_field.type, data_field.is_array, declarations):
            return data_field.initial
        try:
            return structured_value(text, data_field.type, data_field.is_array, declarations)
        except ValueError as error:
            raise _spec_error(f"initial value of data field {data_field.id!r}: {error}",
                              data_field.location,
                              "write arrays as JSON lists ([1, 2, 3]) and records as JSON "
                              'objects ({"x": 1})') from None

    def planned_timer(self, trig: Any, act: Activity) -> CTrigger:
        """A TimeDate or ISO 8601 repeating interval: firings at ``offset``, ``offset +
        every``… (``count`` of them). A TimeDate fires once at its time; ``Rn/start/P`` first
        at its start; ``Rn/P`` (no start) first one period after the run starts (BPMN). Waiting
        in an intermediate event (``seconds``): until the next firing of a dated timer, one
        period for an interval without a start."""
        date = None
        if trig.date is not None:
            date = float(trig.date) - (self.anchor if trig.calendar else 0.0)
        if trig.repeat == 0:                       # TimeDate: once
            moment = date if date is not None else 0.0
            return CTrigger(kind="timer", offset=moment, every=0.0, count=1, planned=True,
                            seconds=_until(moment, 0.0, 1), location=act.location)
        duration = trig.duration
        if not isinstance(duration, Literal) or not isinstance(duration.value, int | float):
            raise _spec_error(f"timer of activity {act.id!r} has no period", act.location)
        period = float(duration.value)
        count = int(trig.repeat)
        first = date if date is not None else period
        wait = _until(first, period, count) if date is not None else _constant(period)
        return CTrigger(kind="timer", offset=first, every=period, count=count, planned=True,
                        seconds=wait, location=act.location, anchored=date is not None)

    # -- graphs --------------------------------------------------------------------------
    def graph(self, proc: WorkflowProcess, name: str, activities: tuple[Activity, ...],
              transitions: tuple[Transition, ...], proc_lane: str | None,
              start: str | None = None) -> CompiledGraph:
        graph = CompiledGraph(name=name, process=proc.id)
        by_id = {a.id: i for i, a in enumerate(activities)}
        graph.by_id = by_id
        acts: list[CompiledActivity] = []
        for i, act in enumerate(activities):
            acts.append(CompiledActivity(index=i, id=act.id, label=act.label, process=proc.id,
                                         location=act.location))
        outgoing: dict[int, list[CTransition]] = {i: [] for i in range(len(activities))}
        incoming: dict[int, list[int]] = {i: [] for i in range(len(activities))}
        trans_by_id: dict[str, CTransition] = {}
        for ti, tr in enumerate(transitions):
            if tr.source not in by_id or tr.target not in by_id:
                missing = tr.source if tr.source not in by_id else tr.target
                raise _spec_error(
                    f"transition {tr.id!r} of {name!r} points to activity {missing!r}, which "
                    f"is not in it", tr.location, "activity ids are scoped per process")
            ck = tr.condition.kind
            kind = _TRANSITION_KINDS[ck]
            cond = None
            if kind == T_COND:
                if tr.condition.expression is None and not (tr.condition.text or "").strip():
                    kind = T_NONE
                else:
                    cond = self.cond(tr.condition.expression, tr.condition.text, tr.location,
                                     f"condition of transition {tr.id!r}")
            exc = tr.condition.exception_name
            if kind == T_EXCEPTION and exc is None and tr.condition.text:
                exc = tr.condition.text.strip() or None
            assigns = tuple((a.target, self.expr(a.expression, a.text, a.location,
                                                 f"assignment to {a.target!r}"))
                            for a in tr.assignments)
            ct = CTransition(index=ti, id=tr.id, target=by_id[tr.target], kind=kind,
                             condition=cond, exception=exc, assignments=assigns,
                             label=(tr.condition.text or None) if kind == T_NONE else None,
                             probability=-1.0 if tr.probability is None else tr.probability,
                             tokens=tr.quantity * activities[by_id[tr.source]].completion_quantity)
            trans_by_id[tr.id] = ct
            outgoing[by_id[tr.source]].append(ct)
            if tr.probability is not None and self.run_inputs and tr.condition.expression:
                reads = [n for n in names_read(tr.condition.expression) if n in self.run_inputs]
                if reads:
                    source = acts[by_id[tr.source]]
                    source.inputs = tuple(dict.fromkeys((*source.inputs, *reads)))
            incoming[by_id[tr.target]].append(ti)
        for i, act in enumerate(activities):
            self.activity(proc, act, acts[i], acts, by_id, outgoing[i], incoming[i],
                          trans_by_id, proc_lane)
        # boundary events attach to their activity
        for i, act in enumerate(activities):
            body = act.body
            if isinstance(body, Event) and body.trigger.attached_to:
                host = by_id.get(body.trigger.attached_to)
                if host is None:
                    raise _spec_error(f"event {act.id!r} is attached to unknown activity "
                                      f"{body.trigger.attached_to!r}", act.location)
                acts[i].attached_to = host
                acts[i].interrupting = body.trigger.interrupting
                acts[host].boundary = (*acts[host].boundary, i)
                acts[host].fast = acts[host].plain = False
        if start is not None:
            if start not in by_id:
                raise _spec_error(f"start activity {start!r} is not in {name!r}", None)
            graph.starts = (by_id[start],)
        else:
            graph.starts = tuple(i for i in range(len(activities))
                                 if not incoming[i] and acts[i].attached_to < 0)
            if activities and not graph.starts:
                raise _spec_error(
                    f"{name!r} has no start activity: every activity has an incoming "
                    f"transition", proc.location,
                    "add a start event (or an activity without incoming transitions) in "
                    "front of the cycle")
        graph.activities = tuple(acts)
        # OR joins need to know, per incoming transition, what can still reach it without
        # passing through the join (only if there are any)
        if any(ca.join == J_OR for ca in acts):
            predecessors: dict[int, set[int]] = {i: set() for i in range(len(acts))}
            for i, outs in outgoing.items():
                for ct in outs:
                    predecessors[ct.target].add(i)
            for ca in acts:
                if ca.attached_to >= 0:     # a boundary event's token comes from its host
                    predecessors[ca.index].add(ca.attached_to)
            sources = {ct.index: i for i, outs in outgoing.items() for ct in outs}
            for ca in acts:
                if ca.join == J_OR:
                    graph.has_or_join = True
                    reach: list[frozenset[int]] = [frozenset()] * len(ca.in_slots)
                    for ti, slot in ca.in_slots.items():
                        seen: set[int] = set()
                        stack = [sources[ti]]
                        while stack:
                            node = stack.pop()
                            if node in seen or node == ca.index:
                                continue
                            seen.add(node)
                            stack.extend(predecessors[node])
                        reach[slot] = frozenset(seen)
                    ca.or_reach = tuple(reach)
        return graph

    def activity(self, proc: WorkflowProcess, act: Activity, ca: CompiledActivity,
                 acts: list[CompiledActivity], by_id: dict[str, int],
                 outgoing: list[CTransition], incoming: list[int],
                 trans_by_id: dict[str, CTransition], proc_lane: str | None) -> None:
        body = act.body
        if isinstance(body, Reference):
            target = proc.activity(body.activity)
            if target is None:
                raise _spec_error(f"activity {act.id!r} references unknown activity "
                                  f"{body.activity!r}", act.location)
            body = target.body
        directives = act.directives
        ca.participant = act.performers[0] if act.performers else None
        lanes: list[str] = []
        if act.lane:
            lanes.append(act.lane)
        if ca.participant and ca.participant in self.participant_lane:
            lanes.extend(self.participant_lane[ca.participant])
        if proc_lane:
            lanes.append(proc_lane)
        ca.lanes = tuple(dict.fromkeys(lanes))
        ca.lane = proc_lane or (lanes[0] if lanes else None)
        # a process-level Participant hides a package-level one with its Id
        participant = next((p for p in proc.participants if p.id == ca.participant),
                           None) or self.participants.get(ca.participant or "")
        ca.user_lane = any(n.lower() in _USER_LANES for n in ca.lanes) or bool(
            participant is not None and participant.is_human)
        # kind
        if isinstance(body, Route):
            ca.kind = K_GATEWAY if body.gateway is GatewayType.EVENT else K_NOOP
        elif isinstance(body, SubFlow):
            ca.kind = K_SUBFLOW if body.execution is Execution.SYNCHR else K_ASYNC
            called = self.package.process(body.process)
            if called is None:
                raise _spec_error(f"subflow {act.id!r} calls unknown process {body.process!r}",
                                  act.location, "name a WorkflowProcess of this package")
            ca.subflow = called.id
            ca.params = self.params(body.actual_parameters, called.formal_parameters, act,
                                    f"process {called.id!r}")
        elif isinstance(body, BlockActivity):
            ca.kind = K_BLOCK
            aset = proc.activity_set(body.activity_set)
            if aset is None:
                raise _spec_error(f"block activity {act.id!r} names unknown activity set "
                                  f"{body.activity_set!r}", act.location)
            ca.block = self.graph(proc, aset.id, aset.activities, aset.transitions, proc_lane,
                                  body.start_activity)
            if aset.ad_hoc:
                ca.block.sequential = aset.ad_hoc_sequential
                if aset.completion_condition is not None or aset.completion_condition_text:
                    ca.block.completion = self.cond(
                        aset.completion_condition, aset.completion_condition_text,
                        aset.location or act.location,
                        f"AdHocCompletionCondition of activity set {aset.id!r}")
        elif isinstance(body, Event):
            trig = self.event_trigger(body, act)
            if body.position is EventPosition.INTERMEDIATE:
                if trig is not None and not body.trigger.catching and trig.kind in (
                        "message", "signal"):
                    ca.kind = K_THROW
                    self.throwable.add(trig.name or "")
                elif trig is not None:
                    ca.kind = K_CATCH
                ca.trigger = trig
            elif body.position is EventPosition.END:
                result = (body.result or "").lower()
                if result == "terminate" or body.trigger.kind is TriggerKind.TERMINATE:
                    ca.terminate = True
                elif result == "error" or body.trigger.kind is TriggerKind.ERROR:
                    ca.error = body.trigger.name or ""
                elif result in ("message", "signal") and trig is not None:
                    ca.kind = K_THROW
                    ca.trigger = trig
                    self.throwable.add(trig.name or "")
            else:
                ca.trigger = trig      # start events: the process start trigger (see below)
        elif isinstance(body, Task):
            if body.applications:
                ca.tools = tuple(self.tool(proc, act, call) for call in body.applications)
                ca.application = ca.tools[0].application
                ca.params = ca.tools[0].params
                ca.toolchain = len(ca.tools) > 1 or ca.tools[0].script is not None
            ca.kind = K_TASK
            ca.general = True
        elif isinstance(body, NoImplementation):
            ca.general = True
        if act.coordination is not None:
            ca.kind = K_COORD
            ca.coordination = act.coordination
            ca.general = False
        elif ca.application in APPLICATION_BUILTINS and isinstance(body, Task):
            # a preprocessed push/pull/mode change: run it as the built-in it stands for
            builtin = application_builtin(ca.application, body.applications[0].actual_parameters)
            if isinstance(builtin, str):
                raise _spec_error(f"activity {act.id!r} calls {ca.application!r}, but {builtin}",
                                  act.location, "write it as opspec preprocess does "
                                  "(docs/sisarl-xpdl.md)")
            ca.kind = K_COORD
            ca.coordination = builtin
            ca.general = False
        manual_body = isinstance(body, NoImplementation | Task)
        if manual_body and ca.coordination is None and (
                ca.user_lane or self.package.is_manual_work(act, proc, body)):
            ca.kind = K_MANUAL
            ca.general = False
        # joins and splits
        if act.join is not None and len(incoming) > 1:
            ca.join = _JOINS.get(act.join.type, J_XOR)
            if ca.join == J_COMPLEX:
                if act.join.condition is None:
                    raise _spec_error(
                        f"activity {act.id!r} is a Complex join without an IncomingCondition "
                        "opspec can evaluate", act.location,
                        "give the Route an IncomingCondition over activationCount, e.g. "
                        "\"activationCount >= 1\" for a discriminator")
                ca.join_condition = self.cond(act.join.condition, act.join.condition_text,
                                              act.location,
                                              f"IncomingCondition of activity {act.id!r}")
        if act.start_quantity > 1 and ca.join == J_XOR:
            ca.join = J_COUNT
            ca.start_quantity = act.start_quantity
        ca.in_slots = {ti: slot for slot, ti in enumerate(incoming)}
        ordered = list(outgoing)
        if act.split is not None and act.split.transition_refs:
            rank = {ref: n for n, ref in enumerate(act.split.transition_refs)}
            ordered.sort(key=lambda t: rank.get(t.id, len(rank) + t.index))
        normal_list: list[CTransition] = []
        otherwise: list[CTransition] = []
        exceptions: list[CTransition] = []
        for t in ordered:       # one pass, in order, into the four kinds
            if t.kind == T_NONE or t.kind == T_COND:
                normal_list.append(t)
            elif t.kind == T_OTHERWISE:
                otherwise.append(t)
            elif t.kind == T_EXCEPTION:
                exceptions.append(t)
            elif ca.default_exception is None:
                ca.default_exception = t
        normal = tuple(normal_list)
        ca.out = normal
        ca.otherwise = tuple(otherwise)
        ca.exceptions = tuple(exceptions)
        ca.path_may_end = act.split is None or act.split.type is GatewayType.AND
        if act.split is not None:
            # a diverging complex gateway behaves as an inclusive one (BPMN 2.0 §13.3.6)
            ca.split = _SPLITS.get(act.split.type, S_XOR)
        elif len(normal) > 1 and all(t.kind == T_NONE for t in normal) and not ca.otherwise:
            ca.split = S_AND      # no split declared, several unconditional: run them all
        elif len(normal) > 1:
            # no split declared and some conditions: BPMN conditional sequence flows, every
            # one whose condition holds is taken (OTHERWISE is the default flow)
            ca.split = S_OR
        if ca.split in (S_XOR, S_OR) and any(t.probability >= 0.0 for t in ordered):
            # a gateway the spec leaves undecided: its branches are drawn with the declared
            # probabilities (the reader gives every branch one), never by file order
            ca.drawn = tuple(t for t in ordered if t.kind in (T_NONE, T_COND, T_OTHERWISE))
        # directives
        if act.assignments:
            ca.start_assign = tuple(
                (a.target, self.expr(a.expression, a.text, a.location,
                                     f"assignment to {a.target!r}"))
                for a in act.assignments if a.assign_time.lower() == "start")
            ca.end_assign = tuple(
                (a.target, self.expr(a.expression, a.text, a.location,
                                     f"assignment to {a.target!r}"))
                for a in act.assignments if a.assign_time.lower() != "start")
        ca.raises = self.trigger_ref(directives.raises)
        if ca.raises is not None and ca.raises.name:
            self.throwable.add(ca.raises.name)
        ca.start_trigger = self.trigger_ref(directives.start_trigger)
        ca.end_trigger = self.trigger_ref(directives.end_trigger)
        ca.priority_increment = directives.priority_increment
        ca.priority = act.priority
        ca.cpu = float(directives.cpu_demand or 0.0)
        if directives.cpu_distribution is not None:
            try:
                ca.cpu_sampler = make_sampler(directives.cpu_distribution)
            except ValueError as error:
                raise _spec_error(f"CPU demand of activity {act.id!r}: {error}", act.location,
                                  "see docs/sisarl-xpdl.md for the distributions") from None
        if directives.duration is not None:
            try:
                ca.sampler = make_sampler(directives.duration)
            except ValueError as error:
                raise _spec_error(f"duration of activity {act.id!r}: {error}", act.location,
                                  "see docs/sisarl-xpdl.md for the distributions") from None
        if act.deadlines:
            ca.deadlines = tuple(
                (self.seconds(d.duration, d.duration_text, d.location or act.location,
                              f"deadline of activity {act.id!r}"),
                 d.execution is Execution.SYNCHR, d.exception_name or "deadline")
                for d in act.deadlines)
        if act.loop is not None and act.loop.kind is LoopKind.STANDARD:
            cond = None
            if act.loop.condition is not None or act.loop.condition_text:
                cond = self.cond(act.loop.condition, act.loop.condition_text, act.location,
                                 f"loop condition of activity {act.id!r}")
            ca.loop = (cond, act.loop.maximum, act.loop.test_before)
        elif act.loop is not None and act.loop.kind is LoopKind.MULTI_INSTANCE:
            loop = act.loop
            if loop.condition is None and not loop.condition_text:
                raise _spec_error(f"multi-instance activity {act.id!r} has no MI_Condition",
                                  act.location, "write MI_Condition=\"N\" (how many instances)")
            count = self.expr(loop.condition, loop.condition_text, act.location,
                              f"MI_Condition of activity {act.id!r}")
            flow = {MIFlow.NONE: MI_NONE, MIFlow.ONE: MI_ONE, MIFlow.ALL: MI_ALL,
                    MIFlow.COMPLEX: MI_COMPLEX}[loop.flow]
            flow_cond = None
            if flow == MI_COMPLEX and loop.cancel_remaining:
                flow = MI_CANCEL
            if flow == MI_COMPLEX or flow == MI_CANCEL:
                flow_cond = self.cond(loop.flow_condition, loop.flow_condition_text,
                                      act.location,
                                      f"ComplexMI_FlowCondition of activity {act.id!r}")
            ca.mi = (count, loop.parallel, flow, flow_cond)
        # instantaneous under the dedicated model (tasks: unless a callable is bound to the
        # application at run time; general activities: unless the pooled model queues them)
        ca.plain = (not ca.deadlines and ca.loop is None and ca.mi is None and ca.sampler is None
                    and ca.cpu == 0.0 and ca.cpu_sampler is None and ca.start_trigger is None and ca.end_trigger is None
                    and not ca.boundary)
        ca.fast = ca.plain and ca.kind in (K_NOOP, K_THROW, K_TASK, K_ASYNC) and not (
            ca.kind == K_TASK and ca.toolchain)

    def tool(self, proc: WorkflowProcess, act: Activity, call: TaskApplication) -> CTool:
        """One application call of a task: its parameters and, for a script, its statements."""
        # XPDL scoping: a process-level Application hides a package-level one with its Id
        app = next((a for a in proc.applications if a.id == call.application),
                   None) or self.package.application(call.application)
        formals = app.formal_parameters if app is not None else ()
        params = self.params(call.actual_parameters, formals, act,
                             f"application {call.application!r}")
        script = None
        if app is not None and app.script:
            known = {f.id for f in formals}
            statements: list[tuple[str, Evaluator]] = []
            for a in app.script:
                where = a.location or app.location
                unknown = sorted(_names(a.expression) - known) if a.expression else []
                if unknown:
                    raise _spec_error(
                        f"script statement {a.text!r} of application {app.id!r} reads "
                        f"{', '.join(map(repr, unknown))}, which is neither a formal parameter "
                        "of the application nor set by an earlier statement", where,
                        "a script sees only its application's formal parameters")
                statements.append((a.target, self.expr(
                    a.expression, a.text, where,
                    f"script statement {a.text!r} of application {app.id!r}")))
                known.add(a.target)
            script = tuple(statements)
        return CTool(application=call.application, params=params, script=script)

    def finish_choices(self, graph: CompiledGraph) -> None:
        """Deferred choice on an XOR split: all unconditional branches go to manual
        activities of the same performer (checked after every activity is compiled)."""
        acts = graph.activities
        for ca in acts:
            if ca.block is not None:
                self.finish_choices(ca.block)
            if ca.kind == K_GATEWAY or ca.split != S_XOR or ca.kind == K_MANUAL:
                continue
            branches = [t for t in ca.out if t.kind == T_NONE]
            if len(branches) < 2 or len(branches) != len(ca.out):
                continue
            targets = [acts[t.target] for t in branches]
            if all(t.kind == K_MANUAL for t in targets) and len(
                    {(t.participant, t.lanes) for t in targets}) == 1:
                ca.choice = tuple(branches)
            elif all(t.label for t in branches):
                # labels an editor wrote for people (ScriptGrammar="Text"): whoever performs
                # the deciding activity picks the branch (see Interpreter._offer_choice)
                ca.choice = tuple(branches)
                ca.labelled = True
        for ca in acts:
            ca.simple_end = (not ca.end_assign and ca.kind != K_THROW and ca.raises is None
                             and not ca.terminate and ca.error is None)
            only = ca.out[0] if len(ca.out) == 1 else None
            if (only is not None and only.kind == T_NONE and not only.assignments
                    and only.tokens == 1
                    and not ca.otherwise and not ca.choice and not ca.terminate):
                ca.next = only.target

    def params(self, actuals: tuple[Any, ...], formals: tuple[Any, ...], act: Activity,
               what: str) -> tuple[tuple[ParameterMode, str, Evaluator | None, str | None], ...]:
        if formals and len(actuals) != len(formals):
            raise _spec_error(
                f"activity {act.id!r} passes {len(actuals)} actual parameters to {what}, which "
                f"declares {len(formals)} formal parameters", act.location,
                "give one actual parameter per formal parameter, in order")
        out = []
        for n, actual in enumerate(actuals):
            if formals:
                formal_id, mode = formals[n].id, formals[n].mode
            else:
                formal_id, mode = f"p{n}", ParameterMode.IN
            expression = actual.expression
            if expression is None and _IDENT.match(actual.text.strip()):
                expression = Name(tuple(actual.text.strip().split(".")))
            target = expression.path[0] if isinstance(expression, Name) else None
            if mode is not ParameterMode.IN and target is None:
                raise _spec_error(
                    f"actual parameter {n + 1} of activity {act.id!r} ({actual.text!r}) must "
                    f"name a data field: formal {formal_id!r} is {mode.value}",
                    actual.location or act.location)
            fn = None
            if mode is not ParameterMode.OUT:
                fn = self.expr(expression, actual.text, actual.location or act.location,
                               f"actual parameter {n + 1} of activity {act.id!r}")
            out.append((mode, formal_id, fn, target))
        return tuple(out)

    def process(self, proc: WorkflowProcess) -> CompiledProcess:
        directives = proc.directives
        lane = directives.lane
        graph = self.graph(proc, proc.id, proc.activities, proc.transitions, lane)
        self.finish_choices(graph)
        data: dict[str, Any] = {f.id: None for f in proc.formal_parameters}
        data.update({f.id: self.initial(f) for f in proc.data_fields})
        start = self.trigger_ref(directives.start_trigger)
        start_events: tuple[tuple[CTrigger, int], ...] = ()
        if start is None and directives.arrival is not None:
            start = self.arrivals(proc)
        if start is None:
            start_events = tuple((_start_trigger(graph.activities[index].trigger), index)
                                 for index in graph.starts
                                 if graph.activities[index].trigger is not None
                                 and graph.activities[index].kind == K_NOOP)
            if start_events:
                start = start_events[0][0]
            if len(graph.starts) < 2:      # one start: it is the process's start trigger
                start_events = ()
        if start is None and directives.period is not None:
            start = CTrigger(kind="period", every=directives.period, location=proc.location)
        if start is not None and start.kind == "timer" and not start.at and start.every:
            start = CTrigger(kind="period", every=start.every, offset=start.offset,
                             location=start.location)
        # several start events: the untriggered (none) ones are where an instance started
        # without a trigger begins (auto-start, API, call; BPMN 2.0 §13.3.4)
        called_starts = tuple(i for i in graph.starts
                              if not any(i == index for _t, index in start_events))
        auto = directives.auto_start
        if auto is None:
            # a none start event beside triggered ones starts an instance as a process with
            # only none start events does (BPMN 2.0 §10.4.2: each start event is independent)
            auto = ((start is None or (bool(start_events) and any(
                        _is_start_event(proc.activity(graph.activities[i].id))
                        for i in called_starts)))
                    and proc.id not in self.subflow_targets)
        priority = directives.priority if directives.priority is not None else (
            proc.priority or 0)
        return CompiledProcess(
            id=proc.id, label=proc.label, graph=graph, data=data,
            formals=tuple((f.id, f.mode) for f in proc.formal_parameters), priority=priority,
            lane=lane, start_trigger=start, end_trigger=self.trigger_ref(directives.end_trigger),
            auto_start=bool(auto), deadline=directives.deadline, mode=directives.mode,
            location=proc.location, start_events=start_events, called_starts=called_starts)


def _is_start_event(activity: Activity | None) -> bool:
    return (activity is not None and isinstance(activity.body, Event)
            and activity.body.position is EventPosition.START)


def _start_trigger(trig: CTrigger | None) -> CTrigger:
    """The process start trigger a start event's trigger stands for: a timer start fires
    periodically when it is a cycle (or, as a duration, every that long)."""
    assert trig is not None
    if trig.kind == "timer" and trig.planned:
        return CTrigger(kind="period", every=trig.every, offset=trig.offset, count=trig.count,
                        location=trig.location)
    if trig.kind == "timer" and trig.seconds is not None:
        every = float(trig.seconds({}, 0.0))
        return CTrigger(kind="period", every=every, offset=every, location=trig.location)
    return trig


def _names(expression: Expression) -> set[str]:
    """Roots of the data names ``expression`` reads."""
    found: set[str] = set()
    stack: list[Expression] = [expression]
    while stack:
        node = stack.pop()
        if isinstance(node, Name):
            found.add(node.path[0])
        elif isinstance(node, Unary):
            stack.append(node.operand)
        elif isinstance(node, Binary):
            stack.append(node.left)
            stack.append(node.right)
        elif isinstance(node, Call):
            stack.extend(node.args)
    return found


def _until(first: float, every: float, count: int) -> Evaluator:
    """Seconds from ``now`` to the next of the firings ``first + k * every`` (``count`` of
    them, -1 for no end); 0 when they are all past (a past date fires at once, as BPMN)."""
    def wait(data: Mapping[str, Any], now: float) -> float:
        if now <= first:
            return first - now
        if every <= 0.0:
            return 0.0
        k = int((now - first) // every)
        if first + k * every < now:
            k += 1
        if 0 <= count <= k:
            return 0.0
        return first + k * every - now
    return wait


_EPOCH = datetime.datetime(1970, 1, 1)


def _moment(value: Any) -> float | None:
    """Seconds since 1970-01-01 of an ISO 8601 date(-time) text, date or datetime (the
    simulated clock has no time zone: a zone suffix is ignored); ``None`` for anything else."""
    if isinstance(value, str):
        text = value.strip()
        if len(text) < 10 or not text[:4].isdigit() or text[4:5] != "-":
            return None
        try:
            value = datetime.datetime.fromisoformat(text)
        except ValueError:
            return None
    if isinstance(value, datetime.datetime):
        return (value.replace(tzinfo=None) - _EPOCH).total_seconds()
    if isinstance(value, datetime.date):
        return float((value - _EPOCH.date()).days * 86_400)
    return None


def _date_or_delay(inner: Evaluator, anchor: float, text: str,
                   location: SourceLocation | None, activity: str) -> Evaluator:
    """Seconds from ``now`` to the date a timeDate expression's value holds (0 when past:
    a past date fires at once); a number is a delay in seconds."""
    def wait(data: Mapping[str, Any], now: float) -> float:
        value = inner(data, now)
        if isinstance(value, int | float) and not isinstance(value, bool):
            return float(value)
        moment = _moment(value)
        if moment is None:
            delay = try_duration(value) if isinstance(value, str) else None
            if delay is not None:
                return delay
            raise OpspecError(f"the timeDate {text!r} of activity {activity!r} gave {value!r}, "
                              "which is no date", location=location,
                              hint="give it an ISO 8601 date-time such as 2026-01-01T08:00:00")
        return max(0.0, moment - anchor - now)
    return wait


def _constant(value: float) -> Evaluator:
    return lambda data, now: value


def compile_package(package: Package) -> CompiledPackage:
    """Compile ``package`` (fatal problems raise :class:`~opspec.errors.SpecError` with the
    location of the element at fault)."""
    with gc_paused():       # a big package: no full collections while it is compiled
        return _compile_package(package)


def _compile_package(package: Package) -> CompiledPackage:
    compiler = _Compiler(package)
    processes = {p.id: compiler.process(p) for p in package.processes}
    modes = {m.id: frozenset(m.workflows) for m in package.modes}
    for proc in processes.values():
        if proc.mode is not None:
            modes[proc.mode] = modes.get(proc.mode, frozenset()) | {proc.id}
    initial = next((m.id for m in package.modes if m.initial), None)
    if initial is None and modes:
        initial = next(iter(modes))
    return CompiledPackage(
        id=package.id, source=package.source, package=package, processes=processes,
        data={f.id: compiler.initial(f) for f in package.data_fields},
        throwable=frozenset(compiler.throwable), modes=modes, initial_mode=initial,
        mode_sources={m.id: m.source for m in package.modes if m.source},
        catchers=_catchers(processes.values()))


def _catchers(processes: Iterable[CompiledProcess]) -> dict[tuple[str, str], frozenset[str]]:
    found: dict[tuple[str, str], set[str]] = {}
    for proc in processes:
        stack = [proc.graph]
        while stack:
            graph = stack.pop()
            for act in graph.activities:
                if act.block is not None:
                    stack.append(act.block)
                for trig in (act.trigger if act.kind == K_CATCH or act.attached_to >= 0
                             else None, act.start_trigger):
                    if trig is not None and trig.kind in ("message", "signal"):
                        found.setdefault((trig.kind, trig.name or ""), set()).add(proc.id)
    return {key: frozenset(ids) for key, ids in found.items()}
