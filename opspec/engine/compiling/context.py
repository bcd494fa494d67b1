"""What every construct compiler shares: the package's tables and how expressions, triggers,
parameters and data fields compile (a :class:`Context` per package).

The constructs themselves compile in :mod:`opspec.engine.compiling.constructs` (a table, one
small compiler per activity body and per aspect of an activity) and the graphs they sit in in
:mod:`opspec.engine.compiling.graphs`.
"""

from __future__ import annotations

import datetime
import re
from collections.abc import Mapping
from typing import Any

from opspec.clock import DURATION_HINT, try_duration
from opspec.engine.compiled import CompiledGraph, CTool, CTrigger, Evaluator
from opspec.engine.conditions import compile_condition, compile_expression, field_name
from opspec.engine.sampling import make_sampler
from opspec.errors import OpspecError, SourceLocation, SpecError
from opspec.model import (
    Activity,
    Binary,
    Call,
    DataField,
    Event,
    Expression,
    Literal,
    Name,
    Package,
    ParameterMode,
    SubFlow,
    TaskApplication,
    TriggerKind,
    TriggerRef,
    Unary,
    WorkflowProcess,
)
from opspec.model.data import is_structured, structured_value

__all__ = ["Context", "spec_error"]

IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_.]*$")


def spec_error(message: str, location: SourceLocation | None, hint: str = "") -> SpecError:
    return SpecError(message, location=location, hint=hint)


class Context:
    """The package being compiled and the compilers of its expressions (see the module)."""


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
                raise spec_error(f"{what} has no expression", location)
            stripped = text.strip()
            if IDENT.match(stripped) and stripped not in ("true", "false", "null"):
                expression = Name(tuple(stripped.split(".")))
            else:
                seconds = try_duration(stripped)
                if seconds is None:
                    raise spec_error(f"{what} {stripped!r} was not understood", location,
                                      "write an expression over data fields")
                expression = Literal(seconds)
        try:
            if condition:
                return compile_condition(expression, location=location)
            return compile_expression(expression, location=location)
        except OpspecError as error:  # the evaluator rejects an expression it cannot run
            raise spec_error(f"{what} cannot be evaluated: {error.message}", location) from None

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
            stripped = text.strip()
            if stripped and not IDENT.match(stripped):
                # text the reader could not read (a deadline in JavaScript): a length of
                # time is meant, so the hint lists the durations as well as the expressions
                raise spec_error(f"{what} {stripped!r} is neither a duration nor an "
                                 "expression opspec reads", location,
                                 f"{DURATION_HINT}, or an expression over data fields "
                                 "giving seconds (timeout * 60)")
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
            raise spec_error(f"inter-arrival time of process {proc.id!r}: {error}",
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
            raise spec_error(f"initial value of data field {data_field.id!r}: {error}",
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
            raise spec_error(f"timer of activity {act.id!r} has no period", act.location)
        period = float(duration.value)
        count = int(trig.repeat)
        first = date if date is not None else period
        wait = _until(first, period, count) if date is not None else _constant(period)
        return CTrigger(kind="timer", offset=first, every=period, count=count, planned=True,
                        seconds=wait, location=act.location, anchored=date is not None)

    # -- graphs --------------------------------------------------------------------------
    def graph(self, proc: WorkflowProcess, name: str, activities: tuple[Activity, ...],
              transitions: tuple[Any, ...], proc_lane: str | None,
              start: str | None = None) -> CompiledGraph:
        """Compile a process's or activity set's graph (the block activity's compiler needs
        it; :class:`~opspec.engine.compiling.graphs.Compiler` implements it)."""
        raise NotImplementedError

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
                    raise spec_error(
                        f"script statement {a.text!r} of application {app.id!r} reads "
                        f"{', '.join(map(repr, unknown))}, which is neither a formal parameter "
                        "of the application nor set by an earlier statement", where,
                        "a script sees only its application's formal parameters")
                statements.append((a.target, self.expr(
                    a.expression, a.text, where,
                    f"script statement {a.text!r} of application {app.id!r}")))
                known.add(a.target)
            script = tuple(statements)
        # (the name interned: performers and worlds compare it with their literals)
        return CTool(application=field_name(call.application), params=params, script=script)


    def params(self, actuals: tuple[Any, ...], formals: tuple[Any, ...], act: Activity,
               what: str) -> tuple[tuple[ParameterMode, str, Evaluator | None, str | None], ...]:
        if formals and len(actuals) != len(formals):
            raise spec_error(
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
            if expression is None and IDENT.match(actual.text.strip()):
                expression = Name(tuple(actual.text.strip().split(".")))
            target = field_name(expression.path[0]) if isinstance(expression, Name) else None
            if mode is not ParameterMode.IN and target is None:
                raise spec_error(
                    f"actual parameter {n + 1} of activity {act.id!r} ({actual.text!r}) must "
                    f"name a data field: formal {formal_id!r} is {mode.value}",
                    actual.location or act.location)
            fn = None
            if mode is not ParameterMode.OUT:
                fn = self.expr(expression, actual.text, actual.location or act.location,
                               f"actual parameter {n + 1} of activity {act.id!r}")
            out.append((mode, formal_id, fn, target))
        return tuple(out)



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

