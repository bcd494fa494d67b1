"""The one token of a new workflow instance, carried before the instance has a frame.

Most instances start with one token (one start activity). :meth:`Flow.start_process
<opspec.engine.flow.Flow.start_process>` queues that token without making the instance's top
:class:`~opspec.engine.instances.Frame`; :func:`run` carries it through the instance's
``lone`` activities (``opspec.engine.compiling.graphs``: instantaneous, with one way out and
no join ahead) exactly as :meth:`Activities.start <opspec.engine.activities.Activities.start>`
would: the same assignments, trace events, zero-time counts and, at an end, the instance's
completion. At the first activity that is not ``lone`` (one that waits, splits into several
tokens or joins), the instance gets its frame with the token in it and ``Activities.start``
goes on from there. A workflow that only computes data or only starts another (the
dispenser's schedule and timer workflows) thus runs without a frame and without the
token-gone and frame-done steps of the general path.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from opspec.engine.compiled import K_ASYNC, K_TASK, CompiledActivity, CTransition
from opspec.engine.instances import Frame, ProcessInstance
from opspec.engine.lifecycle import RUNNING
from opspec.engine.trace import EventKind as EK
from opspec.errors import OpspecError

if TYPE_CHECKING:
    from opspec.engine.activities import Activities
    from opspec.engine.flow import Flow

__all__ = ["run", "xor_transition"]


def run(activities: Activities, inst: ProcessInstance, act: CompiledActivity | None,
        steps: int = 0, limit: int = -1) -> None:
    """Carry the one token of ``inst`` (no frame yet) from ``act`` on: the steps of
    ``Activities.start`` and ``Flow.done_next`` for ``lone`` activities, in their order.
    (``steps`` and ``limit``: where a plan, :mod:`opspec.engine.plans`, had got to.)"""
    # (the run's applications and the flow read where used, not held: compiled, a local
    # takes and drops a reference, and most instances use neither)
    state = activities.state
    pooled = state.pooled
    if limit < 0:
        limit = state.start_limit
    acts = inst.process.graph.activities
    while act is not None:
        if not act.lone or (act.general and pooled) or (
                act.kind == K_TASK and act.application in state.apps):
            # the instance gets its frame, with the token in it, and from here the
            # token goes the general way (a plan writes the same steps out)
            frame = Frame(inst.process.graph, inst, None)
            inst.frames.append(frame)
            frame.live = 1
            if act.fast:
                activities.start(frame, act, steps, limit)
            else:
                activities.start_slow(frame, act)       # start's first step
            return
        steps += 1
        if steps > limit:                       # a zero-time cycle (see RunState.drain)
            state.zero_time(inst, act)
        cached = act.flag_cache
        bits = (cached.bits if cached.key is state.flag_key else state.act_bits(act))
        if bits & 1:
            state.emit(EK.ACTIVITY_STARTED, act.process, inst.id, act.id, act.lane,
                       act.participant)
        if act.simple_end and not act.start_assign and act.kind != K_ASYNC:
            if bits & 2:
                state.emit(EK.ACTIVITY_COMPLETED, act.process, inst.id, act.id, act.lane,
                           act.participant)
        else:
            if act.start_assign and not activities.flow.assign(inst, act, act.start_assign):
                return
            if act.kind == K_ASYNC:
                data = activities.params_in(inst, act)
                if data is None:
                    return
                activities.flow.start_process(
                    state.processes[act.subflow], data,  # type: ignore[index]
                    trigger=f"subflow:{act.id}")
            # Flow.done_next's steps for a lone activity (no throw, raise, error,
            # escalation or terminate to take care of)
            if not act.simple_end and act.end_assign and not activities.flow.assign(
                    inst, act, act.end_assign):
                return
            cached = act.flag_cache
            if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 2:
                state.emit(EK.ACTIVITY_COMPLETED, act.process, inst.id, act.id, act.lane,
                           act.participant)
            if not act.simple_end and inst.state != RUNNING:
                return
        nxt = act.next
        act = acts[nxt] if nxt >= 0 else _split(activities.flow, inst, act)


def _split(flow: Flow, inst: ProcessInstance, act: CompiledActivity) -> CompiledActivity | None:
    """``Flow.split`` of a ``lone`` activity without a single successor: an XOR split into
    activities without a join, or an end (the token is gone: the instance completes)."""
    if act.out or act.otherwise:
        trans = xor_transition(flow, inst, act, None)
        if trans is None:
            return None
        if trans.assignments:
            scope = inst.scope
            now = flow.state.now
            for target_name, fn in trans.assignments:
                flow.set_field(inst, None, target_name, fn(scope, now))
        return inst.process.graph.activities[trans.target]
    flow.instance_done(inst)                    # an end: the token is gone
    return None


def xor_transition(flow: Flow, inst: ProcessInstance, act: CompiledActivity,
                   frame: Frame | None) -> CTransition | None:
    """The transition ``act``'s exclusive split takes: the first whose condition holds, in
    order, else its OTHERWISE transition. ``None`` when it takes none: where no condition
    holds and the path may end, the token is gone (``frame``'s, or a frameless instance is
    done); otherwise, or when a condition fails, the instance is aborted. The one choice of
    both the general path (``Flow.split``) and the frameless token."""
    scope = inst.scope
    now: Any = flow.state.now                   # (boxed once for all the conditions tried)
    try:
        for trans in act.out:
            cond = trans.condition
            if cond is None or cond(scope, now):
                return trans
        if act.otherwise:
            return act.otherwise[0]
        if act.path_may_end:                    # no condition holds: this path ends
            if frame is None:
                flow.instance_done(inst)
            else:
                flow.token_gone(frame)
            return None
        flow.abort(inst, act, "no outgoing transition can be taken (no "
                   "condition holds and there is no OTHERWISE transition)")
    except OpspecError as error:
        flow.abort(inst, act, f"a transition condition failed: {error.message}")
    return None
