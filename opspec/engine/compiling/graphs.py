"""Graphs and processes: transitions, where boundary events attach, start activities, what an
OR join must wait for, deferred choices, and a process's start trigger and data.

Each activity in a graph is compiled by the construct table of
:mod:`opspec.engine.compiling.constructs`.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from opspec.engine.compiled import (
    J_OR,
    K_CATCH,
    K_GATEWAY,
    K_MANUAL,
    K_NOOP,
    K_THROW,
    S_XOR,
    T_COND,
    T_EXCEPTION,
    T_NONE,
    CompiledActivity,
    CompiledGraph,
    CompiledPackage,
    CompiledProcess,
    CTransition,
    CTrigger,
)
from opspec.engine.compiling.constructs import Site, compile_activity, transition_kind
from opspec.engine.compiling.context import Context, spec_error
from opspec.engine.conditions import field_name
from opspec.model import Activity, Event, EventPosition, Package, Transition, WorkflowProcess
from opspec.model.checks_support import names_read

__all__ = ["Compiler", "compile_package"]


class Compiler(Context):
    """Compiles a package's processes, graph by graph."""

    def graph(self, proc: WorkflowProcess, name: str, activities: tuple[Activity, ...],
              transitions: tuple[Any, ...], proc_lane: str | None,
              start: str | None = None) -> CompiledGraph:
        graph = CompiledGraph(name=name, process=proc.id)
        by_id = {a.id: i for i, a in enumerate(activities)}
        graph.by_id = by_id
        acts = [CompiledActivity(index=i, id=act.id, label=act.label, process=proc.id,
                                 location=act.location) for i, act in enumerate(activities)]
        outgoing: dict[int, list[CTransition]] = {i: [] for i in range(len(activities))}
        incoming: dict[int, list[int]] = {i: [] for i in range(len(activities))}
        for ti, tr in enumerate(transitions):
            ct = self.transition(ti, tr, name, activities, acts, by_id)
            outgoing[by_id[tr.source]].append(ct)
            incoming[ct.target].append(ti)
        for i, act in enumerate(activities):
            compile_activity(self, Site(proc, act, acts[i], outgoing[i], incoming[i],
                                        proc_lane))
        _attach_boundary_events(activities, acts, by_id)
        graph.starts = _starts(proc, name, activities, acts, incoming, by_id, start)
        graph.activities = tuple(acts)
        if any(ca.join == J_OR for ca in acts):
            graph.has_or_join = True
            _or_reach(acts, outgoing)
        return graph

    def transition(self, ti: int, tr: Transition, name: str,
                   activities: tuple[Activity, ...], acts: list[CompiledActivity],
                   by_id: dict[str, int]) -> CTransition:
        """One transition: its kind, condition, exception, assignments and tokens; the run
        inputs a drawn branch's condition reads are noted on its source activity."""
        if tr.source not in by_id or tr.target not in by_id:
            missing = tr.source if tr.source not in by_id else tr.target
            raise spec_error(
                f"transition {tr.id!r} of {name!r} points to activity {missing!r}, which "
                f"is not in it", tr.location, "activity ids are scoped per process")
        kind = transition_kind(tr.condition.kind)
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
        assigns = tuple((field_name(a.target), self.expr(a.expression, a.text, a.location,
                                             f"assignment to {a.target!r}"))
                        for a in tr.assignments)
        if tr.probability is not None and self.run_inputs and tr.condition.expression:
            reads = [n for n in names_read(tr.condition.expression) if n in self.run_inputs]
            if reads:
                source = acts[by_id[tr.source]]
                source.inputs = tuple(dict.fromkeys((*source.inputs, *reads)))
        return CTransition(index=ti, id=tr.id, target=by_id[tr.target], kind=kind,
                           condition=cond, exception=exc, assignments=assigns,
                           label=(tr.condition.text or None) if kind == T_NONE else None,
                           probability=-1.0 if tr.probability is None else tr.probability,
                           tokens=tr.quantity * activities[by_id[tr.source]].completion_quantity)

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
                             and not ca.terminate and ca.error is None
                             and ca.escalation is None)
            only = ca.out[0] if len(ca.out) == 1 else None
            if (only is not None and only.kind == T_NONE and not only.assignments
                    and only.tokens == 1
                    and not ca.otherwise and not ca.choice and not ca.terminate):
                ca.next = only.target
        for ca in acts:
            ca.lone = _lone(ca, acts)

    def process(self, proc: WorkflowProcess) -> CompiledProcess:
        directives = proc.directives
        lane = directives.lane
        graph = self.graph(proc, proc.id, proc.activities, proc.transitions, lane)
        self.finish_choices(graph)
        # (the names interned, as every name the engine reads or writes a field by: see
        # opspec.engine.compiling.context.field_name)
        data: dict[str, Any] = {field_name(f.id): None for f in proc.formal_parameters}
        data.update({field_name(f.id): self.initial(f) for f in proc.data_fields})
        start, start_events = self.start_trigger(proc, graph)
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
            location=proc.location, start_events=start_events, called_starts=called_starts,
            one_start=_one_start(graph, (called_starts or graph.starts) if start_events
                                 else graph.starts))

    def start_trigger(self, proc: WorkflowProcess, graph: CompiledGraph
                      ) -> tuple[CTrigger | None, tuple[tuple[CTrigger, int], ...]]:
        """What starts the process's instances: its directive, its arrivals, its start
        events' triggers (several triggered start events: each with its start event), its
        period."""
        directives = proc.directives
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
        return start, start_events


def _attach_boundary_events(activities: tuple[Activity, ...], acts: list[CompiledActivity],
                            by_id: dict[str, int]) -> None:
    """Boundary events attach to their host activity (which then never runs instantly)."""
    for i, act in enumerate(activities):
        body = act.body
        if isinstance(body, Event) and body.trigger.attached_to:
            host = by_id.get(body.trigger.attached_to)
            if host is None:
                raise spec_error(f"event {act.id!r} is attached to unknown activity "
                                 f"{body.trigger.attached_to!r}", act.location)
            acts[i].attached_to = host
            acts[i].interrupting = body.trigger.interrupting
            acts[host].boundary = (*acts[host].boundary, i)
            acts[host].fast = acts[host].plain = False


def _starts(proc: WorkflowProcess, name: str, activities: tuple[Activity, ...],
            acts: list[CompiledActivity], incoming: dict[int, list[int]],
            by_id: dict[str, int], start: str | None) -> tuple[int, ...]:
    """Where a graph's instances start: the named start activity, else every activity
    without an incoming transition (boundary events excepted), else (a cycle) the activities
    marked StartActivity="true" (:meth:`opspec.model.graph.FlowGraph.starts`)."""
    if start is not None:
        if start not in by_id:
            raise spec_error(f"start activity {start!r} is not in {name!r}", None)
        return (by_id[start],)
    starts = tuple(i for i in range(len(activities))
                   if not incoming[i] and acts[i].attached_to < 0)
    if not starts:
        starts = tuple(i for i, activity in enumerate(activities) if activity.marked_start)
    if activities and not starts:
        raise spec_error(
            f"{name!r} has no start activity: every activity has an incoming "
            f"transition", proc.location,
            "add a start event (or an activity without incoming transitions) in "
            "front of the cycle, or mark where it starts (XPDL: StartActivity=\"true\")")
    return starts


def _or_reach(acts: list[CompiledActivity], outgoing: dict[int, list[CTransition]]) -> None:
    """OR joins: per incoming transition, the activities from which it can be reached without
    passing through the join (BPMN 2.0 Table 13.3's directed paths)."""
    predecessors: dict[int, set[int]] = {i: set() for i in range(len(acts))}
    for i, outs in outgoing.items():
        for ct in outs:
            predecessors[ct.target].add(i)
    for ca in acts:
        if ca.attached_to >= 0:     # a boundary event's token comes from its host
            predecessors[ca.index].add(ca.attached_to)
    sources = {ct.index: i for i, outs in outgoing.items() for ct in outs}
    for ca in acts:
        if ca.join != J_OR:
            continue
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


def compile_package(package: Package) -> CompiledPackage:
    """See :func:`opspec.engine.compiled.compile_package`."""
    compiler = Compiler(package)
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
        data={field_name(f.id): compiler.initial(f) for f in package.data_fields},
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


def _one_start(graph: CompiledGraph, starts: tuple[int, ...]) -> int:
    """``CompiledProcess.one_start``: the start activity when an instance has one token."""
    return starts[0] if len(starts) == 1 and graph.completion is None else -1


def _lone(ca: CompiledActivity, acts: tuple[CompiledActivity, ...]) -> bool:
    """Whether the one token of an instance without a frame yet can pass ``ca``
    (:meth:`opspec.engine.activities.Activities.start_lone`): instantaneous, ending without a
    throw, raise, error, escalation or terminate, and leaving by a split that takes one
    transition into an activity without a join to synchronise at (or by none: an end).
    Anything else gives the instance its frame first and goes the general way."""
    if not ca.fast or ca.kind == K_THROW or ca.raises is not None or ca.terminate \
            or ca.error is not None or ca.escalation is not None:
        return False
    if ca.next >= 0:
        return not acts[ca.next].join
    if ca.choice or ca.drawn:
        return False
    branches = ca.out + ca.otherwise
    if not branches:
        return True                                 # an end
    return ca.split == S_XOR and all(not acts[t.target].join and t.tokens == 1
                                     for t in branches)
