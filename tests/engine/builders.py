"""Compact builders of test models in plain Python (no XPDL reader involved).

    proc("p", acts=["a", "b", manual("c")], trans=[("a", "b"), ("b", "c", "x > 1")])

Transitions are tuples ``(source, target[, condition])`` where the condition is condition
text, ``"otherwise"``, ``"exception"`` / ``"exception:NAME"`` or ``"default-exception"``.
Activities given as plain strings are automatic activities with no implementation.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from opspec.errors import SourceLocation
from opspec.model import Activity as _Activity
from opspec.model import (
    ActivityDirectives,
    ActivitySet,
    ActualParameter,
    Application,
    Assignment,
    BasicKind,
    BasicType,
    BlockActivity,
    Condition,
    ConditionKind,
    CoordinationBuiltIn,
    CoordinationKind,
    DataField,
    Deadline,
    DeclaredDistribution,
    Event,
    EventPosition,
    EventSelector,
    Execution,
    FormalParameter,
    GatewayType,
    Join,
    Loop,
    MetricDefinition,
    MetricKind,
    Package,
    ParameterMode,
    Participant,
    ParticipantType,
    ProcessDirectives,
    Route,
    Split,
    SubFlow,
    Task,
    TaskApplication,
    TaskKind,
    Transition,
    Trigger,
    TriggerKind,
    TriggerRef,
    WorkflowProcess,
)
from opspec.model import Literal as _Literal
from opspec.xpdl.conditions import parse_condition, parse_expression

AnyAct = _Activity | str

_GW = {"XOR": GatewayType.XOR, "AND": GatewayType.AND, "OR": GatewayType.OR,
       "EVENT": GatewayType.EVENT}


def loc(line: int, path: str = "test.xpdl") -> SourceLocation:
    return SourceLocation(path, line)


def act(id: str, *, join: str | None = None, split: str | None = None,
        order: Sequence[str] = (), performer: str | None = None,
        deadlines: Sequence[Deadline] = (), loop: Loop | None = None,
        assign: Sequence[tuple[str, str]] = (), assign_start: Sequence[tuple[str, str]] = (),
        raises: str | None = None, duration: DeclaredDistribution | None = None,
        cpu: float | None = None, priority_increment: int = 0,
        start_trigger: TriggerRef | None = None, line: int | None = None,
        body: Any = None, auto_run: bool | None = None,
        coordination: CoordinationBuiltIn | None = None) -> _Activity:
    """An activity (no implementation unless ``body``) with the usual decorations."""
    raise_ref = None
    if raises is not None:
        kind, _, name = raises.partition(":") if ":" in raises else ("message", "", raises)
        raise_ref = TriggerRef(kind=kind, name=name)
    assignments = tuple(
        Assignment(target=t, text=e, expression=parse_expression(e), assign_time="End")
        for t, e in assign) + tuple(
        Assignment(target=t, text=e, expression=parse_expression(e), assign_time="Start")
        for t, e in assign_start)
    kwargs: dict[str, Any] = {}
    if body is not None:
        kwargs["body"] = body
    return _Activity(
        id=id, performers=(performer,) if performer else (),
        join=Join(type=_GW[join]) if join else None,
        split=Split(type=_GW[split], transition_refs=tuple(order)) if split else None,
        deadlines=tuple(deadlines), loop=loop, assignments=assignments,
        directives=ActivityDirectives(raises=raise_ref, duration=duration, cpu_demand=cpu,
                                      priority_increment=priority_increment,
                                      start_trigger=start_trigger, auto_run=auto_run),
        location=loc(line) if line is not None else None, coordination=coordination,
        **kwargs)


def manual(id: str, performer: str = "user", **kw: Any) -> _Activity:
    return act(id, performer=performer, auto_run=False, **kw)


def task(id: str, app: str, params: Sequence[str] = (), **kw: Any) -> _Activity:
    body = Task(kind=TaskKind.APPLICATION, applications=(TaskApplication(
        application=app, actual_parameters=tuple(_actual(p) for p in params)),))
    return act(id, body=body, **kw)


def route(id: str, gateway: str = "XOR", **kw: Any) -> _Activity:
    return act(id, body=Route(gateway=_GW[gateway]), **kw)


def catch(id: str, kind: str = "message", name: str | None = None,
          seconds: float | None = None, rule: str | None = None, attached_to: str | None = None,
          interrupting: bool = True, **kw: Any) -> _Activity:
    trig = Trigger(kind=TriggerKind(kind), name=name,
                   duration=_Literal(seconds) if seconds is not None else None,
                   condition=parse_condition(rule) if rule else None,
                   attached_to=attached_to, interrupting=interrupting)
    return act(id, body=Event(position=EventPosition.INTERMEDIATE, trigger=trig), **kw)


def throw(id: str, name: str, kind: str = "message", **kw: Any) -> _Activity:
    trig = Trigger(kind=TriggerKind(kind), name=name, catching=False)
    return act(id, body=Event(position=EventPosition.INTERMEDIATE, trigger=trig), **kw)


def start_event(id: str, kind: str = "none", name: str | None = None) -> _Activity:
    return act(id, body=Event(position=EventPosition.START,
                              trigger=Trigger(kind=TriggerKind(kind), name=name)))


def end_event(id: str, result: str | None = None) -> _Activity:
    return act(id, body=Event(position=EventPosition.END, result=result))


def subflow(id: str, process: str, params: Sequence[str] = (), asynchronous: bool = False,
            **kw: Any) -> _Activity:
    body = SubFlow(process=process,
                   execution=Execution.ASYNCHR if asynchronous else Execution.SYNCHR,
                   actual_parameters=tuple(_actual(p) for p in params))
    return act(id, body=body, **kw)


def block(id: str, activity_set: str, **kw: Any) -> _Activity:
    return act(id, body=BlockActivity(activity_set=activity_set), **kw)


def deadline(seconds: float, exception: str = "timeout", synchronous: bool = True) -> Deadline:
    return Deadline(duration_text=f"PT{seconds:g}S", duration=_Literal(seconds),
                    execution=Execution.SYNCHR if synchronous else Execution.ASYNCHR,
                    exception_name=exception)


def _actual(text: str) -> ActualParameter:
    return ActualParameter(text=text, expression=parse_expression(text))


def transitions(specs: Sequence[tuple[str, ...]], prefix: str = "t") -> tuple[Transition, ...]:
    out = []
    for n, spec in enumerate(specs):
        source, target = spec[0], spec[1]
        text = spec[2] if len(spec) > 2 else None
        tid = spec[3] if len(spec) > 3 else f"{prefix}{n}_{source}_{target}"
        if text is None:
            condition = Condition()
        elif text == "otherwise":
            condition = Condition(kind=ConditionKind.OTHERWISE)
        elif text.startswith("exception"):
            name = text.partition(":")[2] or None
            condition = Condition(kind=ConditionKind.EXCEPTION, text=name, exception_name=name)
        elif text == "default-exception":
            condition = Condition(kind=ConditionKind.DEFAULTEXCEPTION)
        else:
            condition = Condition(kind=ConditionKind.CONDITION, text=text,
                                  expression=parse_condition(text))
        out.append(Transition(id=tid, source=source, target=target, condition=condition))
    return tuple(out)


def field(id: str, initial: Any = None, kind: BasicKind | None = None) -> DataField:
    if kind is None:
        kind = (BasicKind.BOOLEAN if isinstance(initial, bool) else BasicKind.INTEGER
                if isinstance(initial, int) else BasicKind.FLOAT if isinstance(initial, float)
                else BasicKind.STRING)
    return DataField(id=id, type=BasicType(kind=kind), initial=initial,
                     initial_value=None if initial is None else str(initial))


def formal(id: str, mode: str = "IN") -> FormalParameter:
    return FormalParameter(id=id, type=BasicType(kind=BasicKind.STRING),
                           mode=ParameterMode(mode))


def proc(id: str, acts: Sequence[AnyAct], trans: Sequence[tuple[str, ...]] = (), *,
         data: Sequence[DataField] = (), formals: Sequence[FormalParameter] = (),
         sets: Sequence[ActivitySet] = (), start: str | None = None, lane: str | None = None,
         period: float | None = None, priority: int | None = None,
         auto_start: bool | None = None, mode: str | None = None,
         end_trigger: str | None = None, deadline: float | None = None) -> WorkflowProcess:
    """A workflow process. ``start`` is a trigger text: ``message:trg``, ``timer:28800,43200``
    (seconds of the day, daily), ``period:60``, ``rule:x > 1``."""
    return WorkflowProcess(
        id=id, activities=tuple(a if isinstance(a, _Activity) else act(a) for a in acts),
        transitions=transitions(trans, prefix=f"{id}_"), data_fields=tuple(data),
        formal_parameters=tuple(formals), activity_sets=tuple(sets),
        directives=ProcessDirectives(start_trigger=trigger(start), lane=lane, period=period,
                                     priority=priority, auto_start=auto_start, mode=mode,
                                     end_trigger=trigger(end_trigger), deadline=deadline),
        location=loc(1))


def activity_set(id: str, acts: Sequence[AnyAct], trans: Sequence[tuple[str, ...]]
                 ) -> ActivitySet:
    return ActivitySet(id=id, activities=tuple(a if isinstance(a, _Activity) else act(a)
                                               for a in acts),
                       transitions=transitions(trans, prefix=f"{id}_"))


def trigger(text: str | None) -> TriggerRef | None:
    if text is None:
        return None
    kind, _, rest = text.partition(":")
    if kind in ("message", "signal"):
        return TriggerRef(kind=kind, name=rest)
    if kind == "timer":
        times, _, every = rest.partition(" every ")
        return TriggerRef(kind="timer", at=tuple(float(t) for t in times.split(",")),
                          every=float(every) if every else 86400.0)
    if kind == "period":
        return TriggerRef(kind="period", every=float(rest))
    if kind == "rule":
        return TriggerRef(kind="rule", condition=parse_condition(rest))
    raise ValueError(text)


def count(name: str, event: str, process: str | None = None,
          activity: str | None = None) -> MetricDefinition:
    return MetricDefinition(name=name, kind=MetricKind.COUNT,
                            select=EventSelector(event=event, process=process,
                                                 activity=activity))


def duration(name: str, start: tuple[str, str | None, str | None],
             end: tuple[str, str | None, str | None], which: str = "first") -> MetricDefinition:
    return MetricDefinition(
        name=name, kind=MetricKind.DURATION,
        start=EventSelector(event=start[0], process=start[1], activity=start[2], which=which),
        end=EventSelector(event=end[0], process=end[1], activity=end[2]))


def ratio(name: str, numerator: str, denominator: str) -> MetricDefinition:
    return MetricDefinition(name=name, kind=MetricKind.RATIO, numerator=numerator,
                            denominator=denominator)


def pkg(*processes: WorkflowProcess, metrics: Sequence[MetricDefinition] = (),
        data: Sequence[DataField] = (), participants: Sequence[tuple[str, str]] = (),
        applications: Sequence[Application] = (), modes: Sequence[Any] = ()) -> Package:
    parts = tuple(Participant(id=p, type=ParticipantType(t)) for p, t in participants)
    return Package(id="test", processes=tuple(processes), metrics=tuple(metrics),
                   data_fields=tuple(data), participants=parts,
                   applications=tuple(applications), modes=tuple(modes), source="test.xpdl")


def app(id: str, *formals: tuple[str, str]) -> Application:
    return Application(id=id, formal_parameters=tuple(formal(f, m) for f, m in formals))


def coordination(kind: str, **kw: Any) -> CoordinationBuiltIn:
    return CoordinationBuiltIn(kind=CoordinationKind(kind), **kw)


__all__ = [name for name in dir() if not name.startswith("_")]


def lookup_subflow(assignment: str = '"noon"') -> WorkflowProcess:
    """A data-only subflow ``lookup(hour IN, dose OUT)``: an XOR split on its input into
    assignments, a merge, an end (a token that never waits)."""
    return proc("lookup",
                [act("split", split="XOR"), act("low", assign=[("dose", '"morning"')]),
                 act("high", assign=[("dose", assignment)]), act("merge", join="XOR"), "end"],
                [("split", "low", "hour < 12"), ("split", "high", "otherwise"),
                 ("low", "merge"), ("high", "merge"), ("merge", "end")],
                formals=[formal("hour", "IN"), formal("dose", "OUT")])
