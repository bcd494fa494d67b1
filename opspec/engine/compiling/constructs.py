"""The construct table: one small compiler per kind of activity body and per aspect of an
activity (as SpiffWorkflow's parser maps each BPMN tag to its parser class).

:func:`compile_activity` resolves a referenced body, then runs every compiler of
:data:`ASPECTS` in order on the activity's :class:`Site`; the body's own compiler is looked up
in :data:`BODIES` by the body's type. Adding a construct is adding a row: a function that
reads the model and fills in the :class:`~opspec.engine.compiled.CompiledActivity`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from opspec.engine.compiled import (
    J_AND,
    J_COMPLEX,
    J_COUNT,
    J_OR,
    J_XOR,
    K_ASYNC,
    K_BLOCK,
    K_CATCH,
    K_COORD,
    K_GATEWAY,
    K_MANUAL,
    K_NOOP,
    K_SUBFLOW,
    K_TASK,
    K_THROW,
    MI_ALL,
    MI_CANCEL,
    MI_COMPLEX,
    MI_NONE,
    MI_ONE,
    S_AND,
    S_OR,
    S_XOR,
    T_COND,
    T_DEFAULT,
    T_EXCEPTION,
    T_NONE,
    T_OTHERWISE,
    CompiledActivity,
    CTransition,
)
from opspec.engine.compiling.context import Context, spec_error
from opspec.engine.conditions import field_name
from opspec.engine.coordination import APPLICATION_BUILTINS, application_builtin
from opspec.engine.sampling import make_sampler
from opspec.model import (
    Activity,
    BlockActivity,
    ConditionKind,
    Event,
    EventPosition,
    Execution,
    GatewayType,
    LoopKind,
    MIFlow,
    NoImplementation,
    Reference,
    Route,
    SubFlow,
    Task,
    TriggerKind,
    WorkflowProcess,
)

__all__ = ["ASPECTS", "BODIES", "Site", "compile_activity", "transition_kind"]

_USER_LANES = frozenset({"user", "user_lane", "user lane", "users"})
# model kinds -> the engine's, made once (not a dict literal of enum keys per transition)
_TRANSITION_KINDS: dict[ConditionKind, int] = {
    ConditionKind.NONE: T_NONE, ConditionKind.CONDITION: T_COND,
    ConditionKind.OTHERWISE: T_OTHERWISE, ConditionKind.EXCEPTION: T_EXCEPTION,
    ConditionKind.DEFAULTEXCEPTION: T_DEFAULT}
_JOINS: dict[GatewayType, int] = {GatewayType.AND: J_AND, GatewayType.OR: J_OR,
                                  GatewayType.COMPLEX: J_COMPLEX}
# a diverging complex gateway behaves as an inclusive one (BPMN 2.0 §13.3.6)
_SPLITS: dict[GatewayType, int] = {GatewayType.AND: S_AND, GatewayType.OR: S_OR,
                                   GatewayType.COMPLEX: S_OR}
_MI_FLOWS: dict[MIFlow, int] = {MIFlow.NONE: MI_NONE, MIFlow.ONE: MI_ONE, MIFlow.ALL: MI_ALL,
                                MIFlow.COMPLEX: MI_COMPLEX}
_SAMPLERS_HINT = "see docs/sisarl-xpdl.md for the distributions"


def transition_kind(kind: ConditionKind) -> int:
    return _TRANSITION_KINDS[kind]


class Site:
    """One activity being compiled: the model activity, its compiled form, its transitions
    and the process around it. ``body`` is the activity's body (a reference's target's)."""

    def __init__(self, proc: WorkflowProcess, act: Activity, ca: CompiledActivity,
                 outgoing: list[CTransition], incoming: list[int],
                 proc_lane: str | None) -> None:
        self.proc = proc
        self.act = act
        self.ca = ca
        self.outgoing = outgoing
        self.incoming = incoming
        self.proc_lane = proc_lane
        self.body: Any = act.body


Compile = Callable[[Context, Site], None]


def compile_activity(c: Context, site: Site) -> None:
    """Fill in ``site.ca`` from ``site.act``: every aspect compiler in order."""
    act = site.act
    if isinstance(site.body, Reference):
        target = site.proc.activity(site.body.activity)
        if target is None:
            raise spec_error(f"activity {act.id!r} references unknown activity "
                             f"{site.body.activity!r}", act.location)
        site.body = target.body
    for aspect in ASPECTS:
        aspect(c, site)


# -- who performs it ---------------------------------------------------------------------

def _performer(c: Context, site: Site) -> None:
    """Participant, the lanes a performer may be bound to (most specific first), the lane in
    the trace, and whether it is the user's."""
    act, ca, proc_lane = site.act, site.ca, site.proc_lane
    ca.participant = act.performers[0] if act.performers else None
    lanes: list[str] = []
    if act.lane:
        lanes.append(act.lane)
    if ca.participant and ca.participant in c.participant_lane:
        lanes.extend(c.participant_lane[ca.participant])
    if proc_lane:
        lanes.append(proc_lane)
    ca.lanes = tuple(dict.fromkeys(lanes))
    ca.lane = proc_lane or (lanes[0] if lanes else None)
    # a process-level Participant hides a package-level one with its Id
    participant = next((p for p in site.proc.participants if p.id == ca.participant),
                       None) or c.participants.get(ca.participant or "")
    ca.user_lane = any(n.lower() in _USER_LANES for n in ca.lanes) or bool(
        participant is not None and participant.is_human)


# -- the body: one compiler per kind ---------------------------------------------------

def _route(c: Context, site: Site) -> None:
    site.ca.kind = K_GATEWAY if site.body.gateway is GatewayType.EVENT else K_NOOP


def _subflow(c: Context, site: Site) -> None:
    body, act, ca = site.body, site.act, site.ca
    ca.kind = K_SUBFLOW if body.execution is Execution.SYNCHR else K_ASYNC
    called = c.package.process(body.process)
    if called is None:
        raise spec_error(f"subflow {act.id!r} calls unknown process {body.process!r}",
                         act.location, "name a WorkflowProcess of this package")
    ca.subflow = called.id
    ca.params = c.params(body.actual_parameters, called.formal_parameters, act,
                         f"process {called.id!r}")


def _block(c: Context, site: Site) -> None:
    body, act, ca = site.body, site.act, site.ca
    ca.kind = K_BLOCK
    aset = site.proc.activity_set(body.activity_set)
    if aset is None:
        raise spec_error(f"block activity {act.id!r} names unknown activity set "
                         f"{body.activity_set!r}", act.location)
    ca.block = c.graph(site.proc, aset.id, aset.activities, aset.transitions, site.proc_lane,
                       body.start_activity)
    if aset.ad_hoc:
        ca.block.sequential = aset.ad_hoc_sequential
        if aset.completion_condition is not None or aset.completion_condition_text:
            ca.block.completion = c.cond(
                aset.completion_condition, aset.completion_condition_text,
                aset.location or act.location,
                f"AdHocCompletionCondition of activity set {aset.id!r}")


def _event(c: Context, site: Site) -> None:
    body, ca = site.body, site.ca
    trig = c.event_trigger(body, site.act)
    if body.trigger.kind is TriggerKind.ESCALATION and body.position is not EventPosition.START:
        # handed to the nearest enclosing boundary escalation event, not broadcast as a
        # message (BPMN 2.0 §10.4.3, §13.5.3): see opspec.engine.escalations
        if body.trigger.attached_to:
            ca.catches_escalation = body.trigger.name or ""
            return
        if body.position is EventPosition.END or not body.trigger.catching:
            ca.escalation = body.trigger.name or ""
            return
    if body.position is EventPosition.INTERMEDIATE:
        if trig is not None and not body.trigger.catching and trig.kind in (
                "message", "signal"):
            ca.kind = K_THROW
            c.throwable.add(trig.name or "")
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
            c.throwable.add(trig.name or "")
    else:
        ca.trigger = trig      # start events: the process start trigger (see graphs)


def _task(c: Context, site: Site) -> None:
    body, ca = site.body, site.ca
    if body.applications:
        ca.tools = tuple(c.tool(site.proc, site.act, call) for call in body.applications)
        ca.application = ca.tools[0].application
        ca.params = ca.tools[0].params
        ca.toolchain = len(ca.tools) > 1 or ca.tools[0].script is not None
    ca.kind = K_TASK
    ca.general = True


def _no_implementation(c: Context, site: Site) -> None:
    site.ca.general = True


#: the compiler of each kind of activity body
BODIES: dict[type, Compile] = {
    Route: _route, SubFlow: _subflow, BlockActivity: _block, Event: _event, Task: _task,
    NoImplementation: _no_implementation,
}


def _body(c: Context, site: Site) -> None:
    compile_body = BODIES.get(type(site.body))
    if compile_body is not None:
        compile_body(c, site)


def _coordination(c: Context, site: Site) -> None:
    """A coordination built-in (push, pull, mode change), written as one or as a
    preprocessed task calling the application it stands for."""
    act, ca, body = site.act, site.ca, site.body
    if act.coordination is not None:
        ca.kind = K_COORD
        ca.coordination = act.coordination
        ca.general = False
    elif ca.application in APPLICATION_BUILTINS and isinstance(body, Task):
        builtin = application_builtin(ca.application, body.applications[0].actual_parameters)
        if isinstance(builtin, str):
            raise spec_error(f"activity {act.id!r} calls {ca.application!r}, but {builtin}",
                             act.location, "write it as opspec preprocess does "
                             "(docs/sisarl-xpdl.md)")
        ca.kind = K_COORD
        ca.coordination = builtin
        ca.general = False


def _manual(c: Context, site: Site) -> None:
    ca = site.ca
    manual_body = isinstance(site.body, NoImplementation | Task)
    if manual_body and ca.coordination is None and (
            ca.user_lane or c.package.is_manual_work(site.act, site.proc, site.body)):
        ca.kind = K_MANUAL
        ca.general = False


# -- the flow around it ----------------------------------------------------------------

def _join(c: Context, site: Site) -> None:
    act, ca = site.act, site.ca
    if act.join is not None and len(site.incoming) > 1:
        ca.join = _JOINS.get(act.join.type, J_XOR)
        if ca.join == J_COMPLEX:
            if act.join.condition is None:
                raise spec_error(
                    f"activity {act.id!r} is a Complex join without an IncomingCondition "
                    "opspec can evaluate", act.location,
                    "give the Route an IncomingCondition over activationCount, e.g. "
                    "\"activationCount >= 1\" for a discriminator")
            ca.join_condition = c.cond(act.join.condition, act.join.condition_text,
                                       act.location,
                                       f"IncomingCondition of activity {act.id!r}")
    if act.start_quantity > 1 and ca.join == J_XOR:
        ca.join = J_COUNT
        ca.start_quantity = act.start_quantity
    ca.in_slots = {ti: slot for slot, ti in enumerate(site.incoming)}


def _split(c: Context, site: Site) -> None:
    """Outgoing transitions in the declared order, by kind, and how the split takes them."""
    act, ca = site.act, site.ca
    ordered = list(site.outgoing)
    if act.split is not None and act.split.transition_refs:
        rank = {ref: n for n, ref in enumerate(act.split.transition_refs)}
        ordered.sort(key=lambda t: rank.get(t.id, len(rank) + t.index))
    normal: list[CTransition] = []
    otherwise: list[CTransition] = []
    exceptions: list[CTransition] = []
    for t in ordered:       # one pass, in order, into the four kinds
        if t.kind == T_NONE or t.kind == T_COND:
            normal.append(t)
        elif t.kind == T_OTHERWISE:
            otherwise.append(t)
        elif t.kind == T_EXCEPTION:
            exceptions.append(t)
        elif ca.default_exception is None:
            ca.default_exception = t
    ca.out = tuple(normal)
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


# -- directives: data, triggers, time --------------------------------------------------

def _assignments(c: Context, site: Site) -> None:
    act, ca = site.act, site.ca
    if act.assignments:
        ca.start_assign = tuple(
            (field_name(a.target),
             c.expr(a.expression, a.text, a.location, f"assignment to {a.target!r}"))
            for a in act.assignments if a.assign_time.lower() == "start")
        ca.end_assign = tuple(
            (field_name(a.target),
             c.expr(a.expression, a.text, a.location, f"assignment to {a.target!r}"))
            for a in act.assignments if a.assign_time.lower() != "start")


def _triggers(c: Context, site: Site) -> None:
    directives, ca = site.act.directives, site.ca
    ca.raises = c.trigger_ref(directives.raises)
    if ca.raises is not None and ca.raises.name:
        c.throwable.add(ca.raises.name)
    ca.start_trigger = c.trigger_ref(directives.start_trigger)
    ca.end_trigger = c.trigger_ref(directives.end_trigger)
    ca.priority_increment = directives.priority_increment
    ca.priority = site.act.priority


def _time(c: Context, site: Site) -> None:
    """CPU demand (fixed or drawn) and duration."""
    act, ca = site.act, site.ca
    directives = act.directives
    ca.cpu = float(directives.cpu_demand or 0.0)
    if directives.cpu_distribution is not None:
        ca.cpu_sampler = _sampler(directives.cpu_distribution, "CPU demand", act)
    if directives.duration is not None:
        ca.sampler = _sampler(directives.duration, "duration", act)
    # a Deadline with no DeadlineDuration (XPDL 2.x: minOccurs="0") never expires, as the
    # reader's warning says: it is left out, not refused
    timed = [d for d in act.deadlines if d.duration is not None or (d.duration_text or "").strip()]
    if timed:
        ca.deadlines = tuple(
            (c.seconds(d.duration, d.duration_text, d.location or act.location,
                       f"deadline of activity {act.id!r}"),
             d.execution is Execution.SYNCHR, d.exception_name or "deadline")
            for d in timed)


def _sampler(distribution: Any, what: str, act: Activity) -> Any:
    """A sampler of the activity's ``what`` (its duration or CPU demand), or the spec error
    naming the activity and its line."""
    try:
        return make_sampler(distribution)
    except ValueError as error:
        raise spec_error(f"{what} of activity {act.id!r}: {error}", act.location,
                         _SAMPLERS_HINT) from None


def _loop(c: Context, site: Site) -> None:
    """A standard loop: (condition, maximum, test before)."""
    act, ca = site.act, site.ca
    if act.loop is not None and act.loop.kind is LoopKind.STANDARD:
        cond = None
        if act.loop.condition is not None or act.loop.condition_text:
            cond = c.cond(act.loop.condition, act.loop.condition_text, act.location,
                          f"loop condition of activity {act.id!r}")
        ca.loop = (cond, act.loop.maximum, act.loop.test_before)


def _multi_instance(c: Context, site: Site) -> None:
    """Multi-instance: (how many, parallel, flow condition kind, complex flow condition)."""
    act, ca = site.act, site.ca
    loop = act.loop
    if loop is None or loop.kind is not LoopKind.MULTI_INSTANCE:
        return
    if loop.condition is None and not loop.condition_text:
        raise spec_error(f"multi-instance activity {act.id!r} has no MI_Condition",
                         act.location, "write MI_Condition=\"N\" (how many instances)")
    count = c.expr(loop.condition, loop.condition_text, act.location,
                   f"MI_Condition of activity {act.id!r}")
    flow = _MI_FLOWS[loop.flow]
    flow_cond = None
    if flow == MI_COMPLEX and loop.cancel_remaining:
        flow = MI_CANCEL
    if flow == MI_COMPLEX or flow == MI_CANCEL:
        flow_cond = c.cond(loop.flow_condition, loop.flow_condition_text, act.location,
                           f"ComplexMI_FlowCondition of activity {act.id!r}")
    ca.mi = (count, loop.parallel, flow, flow_cond)
    ca.mi_element = loop.element_variable


def _speed(c: Context, site: Site) -> None:
    """Whether it can run without waiting (``plain``) and without an activity instance
    (``fast``): under the dedicated model, tasks unless a callable is bound to the
    application at run time, general activities unless the pooled model queues them."""
    ca = site.ca
    ca.plain = (not ca.deadlines and ca.loop is None and ca.mi is None and ca.sampler is None
                and ca.cpu == 0.0 and ca.cpu_sampler is None and ca.start_trigger is None
                and ca.end_trigger is None and not ca.boundary)
    ca.fast = ca.plain and ca.kind in (K_NOOP, K_THROW, K_TASK, K_ASYNC) and not (
        ca.kind == K_TASK and ca.toolchain)


#: what compiling one activity is, in order (each reads what the ones before it decided)
ASPECTS: tuple[Compile, ...] = (
    _performer, _body, _coordination, _manual, _join, _split, _assignments, _triggers, _time,
    _loop, _multi_instance, _speed,
)
