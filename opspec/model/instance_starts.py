"""Where the instances of a process start, as the engine starts them: the start sets
``opspec check`` plays, one token game each.

A process level's start nodes are its activities without incoming transitions
(:meth:`opspec.model.graph.FlowGraph.starts`). At the top level of a process with several of
them, some of them start events with a trigger (timer, message, signal, conditional, link,
error, escalation), the engine arms each triggered one to start its own instance, which runs
only its path (BPMN 2.0 §10.4.2: "Each Start Event is an independent Event");
an instance started without a trigger (auto-started beside a none start event, called as a
subflow, from the API) starts at the other start nodes (:mod:`opspec.engine.compiling.graphs`,
``start_events`` and ``called_starts``; :mod:`opspec.engine.flow`). Everything else (one start
node, no triggered start event, a process-level opspec:StartTrigger or opspec:Arrival, an
activity set) starts all its start nodes together in one instance.
"""

from __future__ import annotations

from opspec.model.activities import Activity, Event, EventPosition, SubFlow, TriggerKind
from opspec.model.graph import FlowGraph
from opspec.model.package import Package
from opspec.model.process import WorkflowProcess

__all__ = ["TRIGGERED_KINDS", "called_processes", "instance_starts", "is_triggered_start"]

#: The start event triggers the engine arms (``Context.event_trigger`` gives them a trigger).
TRIGGERED_KINDS = frozenset({
    TriggerKind.MESSAGE, TriggerKind.TIMER, TriggerKind.RULE, TriggerKind.SIGNAL,
    TriggerKind.LINK, TriggerKind.ERROR, TriggerKind.ESCALATION})


def is_triggered_start(activity: Activity) -> bool:
    """A start event whose trigger starts instances of its own."""
    body = activity.body
    return (isinstance(body, Event) and body.position is EventPosition.START
            and body.trigger.kind in TRIGGERED_KINDS)


def _is_start_event(activity: Activity) -> bool:
    body = activity.body
    return isinstance(body, Event) and body.position is EventPosition.START


def instance_starts(process: WorkflowProcess, graph: FlowGraph, *, called: bool
                    ) -> tuple[tuple[str, ...], ...]:
    """The start sets of the instances ``run`` makes of ``process`` (its top level,
    ``graph``): one per triggered start event, and the other start nodes when an instance
    is started without a trigger, which ``run`` does when the process is ``called`` as a
    subflow, or auto-started (opspec:AutoStart, else when a none start event is among
    them). A start node in none of the sets never runs."""
    starts = graph.starts()
    directives = process.directives
    if directives.start_trigger is not None or directives.arrival is not None:
        return (starts,)
    triggered = tuple(s for s in starts if is_triggered_start(graph.by_id[s]))
    if len(starts) < 2 or not triggered:
        return (starts,)
    sets: list[tuple[str, ...]] = [(s,) for s in triggered]
    rest = tuple(s for s in starts if s not in triggered)
    auto = directives.auto_start
    if auto is None:
        auto = not called and any(_is_start_event(graph.by_id[s]) for s in rest)
    if rest and (auto or called):
        sets.append(rest)
    elif called:            # only triggered start events: a call starts them all
        sets.append(starts)
    return tuple(sets)


def called_processes(package: Package) -> frozenset[str]:
    """The ids of the processes a SubFlow of ``package`` calls (the engine's
    ``subflow_targets``: they are not auto-started)."""
    return frozenset(a.body.process for p in package.processes for a in p.all_activities()
                     if isinstance(a.body, SubFlow))
