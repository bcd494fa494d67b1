"""Multi-instance activities (XPDL ``MI_Condition``, BPMN ``multiInstanceLoopCharacteristics``):
how many instances start, in parallel or one after another, and which of them move on
(``MI_FlowCondition``: NONE each, ONE the first, ALL the last, COMPLEX when a condition over
the instance counters holds; a BPMN completionCondition also cancels the rest). The instances
of a group share one holder for the activity's deadlines and boundary events."""

from __future__ import annotations

from collections import ChainMap
from typing import TYPE_CHECKING, Any

from opspec.engine.compiled import MI_ALL, MI_CANCEL, MI_NONE, MI_ONE, CompiledActivity
from opspec.engine.instances import ActivityInstance, Frame, MultiInstance
from opspec.engine.lifecycle import COMPLETED, RUNNING, TERMINATED
from opspec.engine.trace import EventKind as EK
from opspec.errors import OpspecError

if TYPE_CHECKING:
    from opspec.engine.activities import Activities

__all__ = ["begin", "cancel", "done", "release"]


def begin(acts: Activities, ai: ActivityInstance) -> bool:
    """Start the instances of multi-instance activity ``ai.act``; ``ai`` becomes the
    first. Each instance holds a token of the frame; the flow condition decides which
    of them move on (see :func:`done`). Returns whether ``ai`` runs now."""
    act = ai.act
    frame = ai.frame
    inst = frame.inst
    count_fn, parallel, _flow, _cond = act.mi  # type: ignore[misc]
    try:
        raw = count_fn(inst.scope, acts.state.now)
    except OpspecError as error:
        acts.flow.abort(inst, act, f"the MI_Condition failed: {error.message}")
        return False
    items: tuple[Any, ...] | None = None
    if act.mi_element is not None:      # one instance per item of the list (Camunda collection)
        if not isinstance(raw, (tuple, list)):
            acts.flow.abort(inst, act, f"the multi-instance collection gave {raw!r}, not a "
                            "list (one instance per item)")
            return False
        items = tuple(raw)
        raw = len(items)
    count = raw if isinstance(raw, int) and not isinstance(raw, bool) else (
        int(raw) if isinstance(raw, float) and raw.is_integer() else -1)
    if count < 0:
        acts.flow.abort(inst, act, f"the MI_Condition gave {raw!r}, not a number of instances "
                   "(an integer >= 0)")
        return False
    if count == 0:                      # no instance: the activity is done at once
        acts.state.emit_act(EK.ACTIVITY_STARTED, inst, act)
        ai.state = COMPLETED
        ai.gen += 1
        frame.running.pop(ai.key, None)
        # its assignments are each instance's (as its start assignments, never run here)
        acts.flow.finish(frame, act, None, False)
        return False
    group = MultiInstance(count, items)
    if act.deadlines or act.boundary:
        holder = ActivityInstance(acts.state.next_key(), act, frame, acts.state.now)
        holder.state = RUNNING
        holder.mi = group
        group.holder = holder
    frame.live += count - 1
    _join(ai, group, act.mi_element)
    if parallel:
        for _ in range(count - 1):
            _next(acts, frame, act, group)
    return True


def _join(ai: ActivityInstance, group: MultiInstance, element: str | None) -> None:
    ai.mi = group
    ai.iteration = group.started            # the instance's loopCounter
    if element is not None and group.items is not None:
        ai.local = {element: group.items[group.started]}    # its own item, nobody else's
    group.started += 1
    group.members.append(ai)


def _next(acts: Activities, frame: Frame, act: CompiledActivity, group: MultiInstance) -> None:
    ai = ActivityInstance(acts.state.next_key(), act, frame, acts.state.now)
    ai.state = RUNNING
    frame.running[ai.key] = ai
    _join(ai, group, act.mi_element)
    acts.state.ready.append((acts.activate_q, ai, None, None))


def done(acts: Activities, ai: ActivityInstance, group: MultiInstance) -> None:
    """One instance completed: its token moves on or is consumed, per MI_FlowCondition."""
    act = ai.act
    frame = ai.frame
    inst = frame.inst
    group.completed += 1
    group.members.remove(ai)
    if group.completed == group.count and group.holder is not None:
        release(group)
    _count, parallel, flow, cond = act.mi  # type: ignore[misc]
    if flow == MI_NONE:
        moves = True
    elif flow == MI_ONE:
        moves = not group.passed
    elif flow == MI_ALL:
        moves = group.completed == group.count
    else:
        moves = False
        if not group.passed and cond is not None:
            counters = {"nrOfInstances": group.count,
                        "nrOfCompletedInstances": group.completed,
                        "nrOfActiveInstances": len(group.members)}
            try:
                moves = bool(cond(ChainMap(counters, ai.scope()), acts.state.now))
            except OpspecError as error:
                acts.flow.abort(inst, act, f"the ComplexMI_FlowCondition failed: "
                           f"{error.message}")
                return
    if moves and flow == MI_CANCEL:
        # BPMN 2.0 §13.3.7: the completionCondition "cancels the remaining Activity
        # instances and produces a token"
        cancel(acts, group, frame, "the completionCondition holds")
        group.passed = True
        acts.flow.finish(frame, act, ai.local)
        return
    if not parallel and group.started < group.count and inst.state == RUNNING:
        _next(acts, frame, act, group)
    if moves:
        group.passed = True
        acts.flow.finish(frame, act, ai.local)
        return
    if act.end_assign and not acts.flow.assign(inst, act, act.end_assign, ai.scope()):
        return
    acts.state.emit_act(EK.ACTIVITY_COMPLETED, inst, act, {"instance": ai.iteration})
    acts.flow.token_gone(frame)


def cancel(acts: Activities, group: MultiInstance, frame: Frame, reason: str) -> None:
    """An interrupting event ends every instance of the group (the interrupted one
    included); their tokens, and those of instances not started yet, are consumed."""
    for member in list(group.members):
        acts.stop(member, TERMINATED, reason)
    frame.live -= len(group.members) + (group.count - group.started)
    group.members.clear()
    group.started = group.count
    if group.holder is not None:
        release(group)


def release(group: MultiInstance) -> None:
    """The multi-instance activity is over: its deadlines and boundary events end."""
    holder = group.holder
    if holder is not None and holder.state == RUNNING:
        holder.state = COMPLETED
        holder.gen += 1
        cleanup = holder.cleanup
        if cleanup:
            for undo in cleanup:
                undo()
            cleanup.clear()
