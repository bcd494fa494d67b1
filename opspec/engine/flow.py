"""Tokens through a workflow's graph: instances, transitions, splits, joins.

A process instance runs its graph in a :class:`~opspec.engine.instances.Frame` (an activity set
runs in a frame of its own); tokens move between activities as items of the ready queue
(:meth:`~opspec.engine.runstate.RunState.drain`). This part decides where a token goes when an
activity completes (:meth:`Flow.done_next`: the split), whether an arriving token starts its
activity (:meth:`Flow.arrive`: the join), when a frame or an instance is done, deadlocked,
terminated or aborted, and which EXCEPTION transition a failure follows. The rules are in the
docstring of :mod:`opspec.engine.interpreter` and in docs/semantics.md."""

from __future__ import annotations

from collections import ChainMap
from collections.abc import Callable, Mapping, MutableMapping
from typing import TYPE_CHECKING, Any, Final

from opspec.engine import drawing, escalations, joins, lone, plans, process_deadlines
from opspec.engine.compiled import (
    J_AND,
    J_COMPLEX,
    J_COUNT,
    K_THROW,
    S_XOR,
    CompiledActivity,
    CompiledProcess,
    CTransition,
)
from opspec.engine.conditions import COMPILED, Constant
from opspec.engine.instances import (
    IN_LINE,
    ActivityInstance,
    Frame,
    ProcessInstance,
    process_instance,
)
from opspec.engine.lifecycle import ABORTED, LIFECYCLE, RUNNING, STATE_NAMES, SUSPENDED, TERMINATED
from opspec.engine.part import Part
from opspec.engine.scope import Scope
from opspec.engine.trace import EventKind as EK
from opspec.errors import OpspecError
from opspec.model import ParameterMode

if TYPE_CHECKING:
    from opspec.engine.runstate import RunState

_NEXT = LIFECYCLE.table
# Final: module statics in the compiled engine, where a plain global is a dictionary lookup
_COMPLETED_FROM_RUNNING: Final = _NEXT[(RUNNING, "complete")]
_IN: Final = ParameterMode.IN


class Flow(Part):
    """Tokens through graphs: process instances, transitions, splits, joins (see the module docstring)."""

    def __init__(self, state: RunState) -> None:
        super().__init__(state)
        # Bound once, for the ready queue (compiled, ``self.start_at`` as a value builds a
        # bound method object each time).
        self.start_at_q: Callable[[Frame, int, Any], None] = self.start_at
        self.arrive_q: Callable[[Frame, int, CTransition | None], None] = self._arrive
        self.performed_q: Callable[[Frame, int, CTransition | None], None] = self.performed
        self.start_lone_q: Callable[[ProcessInstance, int, Any], None] = self.start_lone_at
        # from source, the plans of the deferred choices' branches (opspec.engine.plans): by
        # the transition into the branch, queued in performed's place; empty compiled
        self.performs: dict[CTransition, Callable[[Frame, Any, CTransition], None]] = (
            {} if plans.COMPILED else plans.performs(state.compiled))

    def start_process(self, proc: CompiledProcess, data: Mapping[str, Any] | None = None, *,
                      parent: ActivityInstance | None = None, trigger: str | None = None,
                      start: int = -1) -> ProcessInstance:
        """Create and start an instance of ``proc``: its start activities are queued, or
        only ``start`` when one of several triggered start events started it."""
        state = self.state
        local = proc.data.copy()
        if data:
            local.update(data)
        scope: MutableMapping[str, Any] = (
            Scope(local, state.package_data) if state.package_data else local)
        state.last_id += 1                    # the next instance id (RunState.last_id)
        iid = state.last_id
        priority = proc.priority
        if parent is None:
            if IN_LINE:          # (from source: no class call)
                inst = process_instance(iid, proc, local, scope, priority, None, iid,
                                        state.now, RUNNING, trigger)
            else:
                inst = ProcessInstance(iid, proc, local, scope, priority, None, iid,
                                       state.now, RUNNING, trigger)
        else:
            caller = parent.frame.inst
            if caller.priority > priority:       # (max(), without its call)
                priority = caller.priority
            inst = ProcessInstance(iid, proc, local, scope, priority, parent, caller.root,
                                   state.now, RUNNING, trigger)
            inst.depth = caller.depth + 1
            inst.partner = caller.partner
        state.live[inst.id] = inst          # (the id boxed once, by the instance)
        state.started += 1
        cached = proc.flag_cache              # RunState.proc_bits's cached case, in line
        if (cached.bits if cached.key is state.flag_key else state.proc_bits(proc)) & 1:
            state.emit(EK.PROCESS_STARTED, proc.id, iid, None, proc.lane, None,
                       {"trigger": trigger, "parent": parent.frame.inst.id if parent else None})
        graph = proc.graph
        # RunState.start_counted's common case in line: another instance at this instant
        if state.now == state.starts_at and state.instant_starts < state.max_instant_starts:
            state.instant_starts += 1
        else:
            state.start_counted(inst)
        one = proc.one_start if start < 0 else (start if graph.completion is None else -1)
        if one >= 0:
            # one token: the instance gets its frame only if the token reaches something
            # that needs one (opspec.engine.lone); data-only workflows end without one.
            # From source, the token's plan when it starts where the plan does
            plan = proc.plan
            if plan is not None and one == proc.one_start:
                state.ready.append((plan, inst, self.activities, None))
            else:
                state.ready.append((self.start_lone_q, inst, one, None))
        else:
            if start >= 0:
                starts: tuple[int, ...] = (start,)
            else:
                starts = graph.starts
                if proc.start_events:
                    # not started by one of its triggered start events (called,
                    # auto-started, from the API): its none start events (BPMN 2.0 §13.3.4)
                    starts = proc.called_starts or starts
            frame = Frame(graph, inst, None)
            inst.frames.append(frame)
            for index in starts:
                frame.live += 1
                state.ready.append((self.start_at_q, frame, index, None))
            if not starts:
                state.pending[frame] = None
        if proc.deadline is not None:
            process_deadlines.arm(self, inst, proc.deadline)
        return inst

    def frame_done(self, frame: Frame) -> None:
        inst = frame.inst
        owner = frame.owner
        if owner is not None:                       # an activity set finished
            if frame.queue and inst.state == RUNNING:   # a sequential ad-hoc set: the next
                frame.live += 1
                self.state.ready.append((self.start_at_q, frame, frame.queue.pop(0), None))
                return
            if frame in inst.frames:
                inst.frames.remove(frame)
            owner.child = None
            self.activities.body_done(owner, None)
            return
        self.instance_done(inst)

    def instance_done(self, inst: ProcessInstance) -> None:
        """The instance's top frame is done (or its one token ended before it had one):
        the instance completes, and a synchronous caller gets its OUT parameters."""
        if inst.state != RUNNING:
            return
        inst.state = _COMPLETED_FROM_RUNNING
        inst.frames.clear()          # breaks the instance <-> frame cycle: freed by refcount
        state = self.state
        live = state.live            # RunState.gone, in line, but one look-up: a running
        key = inst.id                # instance is as a rule in the table (boxed once: see
        try:                         # ProcessInstance.__init__; compiled, a try costs
            del live[key]            # nothing until it catches)
        except KeyError:
            pass
        if state.kept and inst.parent is None:
            self.triggers.drop_kept(inst)
        state.completed += 1
        proc = inst.process
        cached = proc.flag_cache              # RunState.proc_bits's cached case, in line
        if (cached.bits if cached.key is state.flag_key else state.proc_bits(proc)) & 2:
            state.emit(EK.PROCESS_COMPLETED, proc.id, inst.id, None, proc.lane, None,
                       {"duration": state.now - inst.started_at})
        parent = inst.parent
        if parent is not None and parent.state == RUNNING:
            parent.child = None
            out = {}
            for mode, formal, _fn, target in parent.act.params:
                if mode is not _IN and target is not None:
                    out[target] = inst.data.get(formal)
            self.activities.body_done(parent, out or None)

    def end_instance(self, inst: ProcessInstance, state: int, reason: str,
                     notify_parent: bool = True) -> None:
        """Terminate or abort ``inst``: cancel everything it waits for; a waiting caller
        (synchronous subflow) sees the exception ``terminated``/``aborted``."""
        if inst.state not in (RUNNING, SUSPENDED) and inst.state != 0:
            return
        trigger = "terminate" if state == TERMINATED else "abort"
        inst.state = LIFECYCLE.next(inst.state, trigger, f"instance {inst.id}")
        for frame in list(inst.frames):
            for ai in list(frame.running.values()):
                self.activities.stop(ai, TERMINATED, reason)
        inst.frames.clear()
        self.state.gone(inst.id)
        if self.state.kept and inst.parent is None:
            self.triggers.drop_kept(inst)
        proc = inst.process
        if state == TERMINATED:
            self.state.terminated += 1
        else:
            self.state.aborted += 1
        kind = EK.PROCESS_TERMINATED if state == TERMINATED else EK.PROCESS_ABORTED
        if self.state.wants(kind, proc.id, None):
            self.state.emit(kind, proc.id, inst.id, None, proc.lane, None, {"reason": reason})
        parent = inst.parent
        if notify_parent and parent is not None and parent.state == RUNNING:
            parent.child = None
            self.activities.fail(parent, STATE_NAMES[state], f"subflow {proc.id!r}: {reason}")

    def abort(self, inst: ProcessInstance, act: CompiledActivity | None, message: str) -> None:
        """Abort ``inst`` with a located message (recorded as a fault); the run goes on."""
        where = act.where() if act is not None else (
            str(inst.process.location) if inst.process.location else "<built in Python>")
        what = f"activity {act.id!r} of " if act is not None else ""
        text = (f"{where}: {what}process {inst.process.id!r} (instance {inst.id}) aborted at "
                f"t={self.state.now:.3f} s: {message}")
        self.state.faults.append({"time": self.state.now, "process": inst.process.id,
                            "instance": inst.id, "activity": act.id if act else None,
                            "message": text})
        self.end_instance(inst, ABORTED, text)

    def start_at(self, frame: Frame, index: int, _unused: Any) -> None:
        inst = frame.inst
        if inst.state != RUNNING or (frame.owner is not None and frame.owner.state != RUNNING):
            self._dropped(frame, self.start_at, index, None)
            return
        self.activities.start(frame, frame.graph.activities[index])

    def start_lone_at(self, inst: ProcessInstance, index: int, _unused: Any) -> None:
        """The one token of a new instance, which has no frame yet, starts at activity
        ``index`` (:func:`opspec.engine.lone.run`: a frame is made if the token needs one)."""
        if inst.state != RUNNING:
            if inst.state == SUSPENDED:
                inst.defer((self.start_lone_at, inst, index, None))
            return
        lone.run(self.activities, inst, inst.process.graph.activities[index])

    def _dropped(self, frame: Frame, fn: Any, a: Any, b: Any) -> None:
        if frame.inst.state == SUSPENDED:
            frame.inst.defer((fn, frame, a, b))
        else:
            frame.live -= 1

    def _arrive(self, frame: Frame, index: int, trans: CTransition | None) -> None:
        """A token reaches activity ``index`` through ``trans``."""
        inst = frame.inst
        if inst.state != RUNNING or (frame.owner is not None and frame.owner.state != RUNNING):
            self._dropped(frame, self._arrive, index, trans)
            return
        act = frame.graph.activities[index]
        join = act.join
        if join and trans is not None:
            if join == J_AND:
                parked = frame.and_joins()
                counts = parked.get(index)
                if counts is None:
                    counts = parked[index] = [0] * len(act.in_slots)
                counts[act.in_slots[trans.index]] += 1
                if 0 in counts:
                    frame.parked += 1
                    self.token_gone(frame)
                    return
                for slot in range(len(counts)):
                    counts[slot] -= 1
                frame.parked -= len(counts) - 1
            elif join == J_COUNT:                  # StartQuantity: N tokens, one start
                parked = frame.and_joins()
                counts = parked.get(index)
                if counts is None:
                    counts = parked[index] = [0]
                counts[0] += 1
                if counts[0] < act.start_quantity:
                    frame.parked += 1
                    self.token_gone(frame)
                    return
                counts[0] = 0
                frame.parked -= act.start_quantity - 1
            elif join == J_COMPLEX:
                frame.parked += 1
                frame.live -= 1
                if joins.complex_arrival(self, frame, act, act.in_slots[trans.index]):
                    frame.live += 1
                    self.activities.start(frame, act)
                elif frame.live <= 0:
                    self.state.pending[frame] = None
                return
            else:                                   # OR join: resolved when the queue is dry
                ors = frame.or_joins()
                tokens = ors.get(index)
                if tokens is None:
                    tokens = ors[index] = [0] * len(act.in_slots)
                tokens[act.in_slots[trans.index]] += 1
                frame.parked += 1
                frame.live -= 1
                self.state.pending[frame] = None
                return
        self.activities.start(frame, act)

    def token_gone(self, frame: Frame) -> None:
        frame.live -= 1
        if frame.graph.completion is not None and self._ad_hoc_complete(frame):
            return
        if frame.live <= 0 or frame.ors:
            if frame.live <= 0 and not frame.parked:
                if frame.owner is None:
                    self.instance_done(frame.inst)      # frame_done's case, without its call
                else:
                    self.frame_done(frame)
            else:
                self.state.pending[frame] = None

    def terminate_frame(self, frame: Frame, reason: str) -> None:
        """A terminate end event inside an activity set (an embedded sub-process) ends that
        sub-process only (BPMN 2.0 §13.5.6, §13.3.4): what still runs in it is stopped, its
        queued and parked tokens are dropped, and its block activity completes, so the
        parent's flow goes on after it."""
        owner = frame.owner
        assert owner is not None
        if frame.queue:
            frame.queue.clear()
        for ai in list(frame.running.values()):
            self.activities.stop(ai, TERMINATED, reason)
        # tokens still in the ready queue see the frame is gone (its owner no longer runs)
        frame.live = 0
        frame.parked = 0
        frame.joins = None
        frame.ors = None
        if frame.cjoins:
            frame.cjoins.clear()
        if frame.owed:
            frame.owed.clear()
        self.state.pending.pop(frame, None)
        if frame in frame.inst.frames:
            frame.inst.frames.remove(frame)
        owner.child = None
        self.activities.body_done(owner, None)

    def _ad_hoc_complete(self, frame: Frame) -> bool:
        """An ad-hoc set's AdHocCompletionCondition holds once one of its paths ended: the
        activities still running are cancelled, those not started are dropped, and the set
        completes (BPMN 2.0 ad-hoc subprocess, cancelRemainingInstances)."""
        condition = frame.graph.completion
        owner = frame.owner
        assert condition is not None
        if owner is None or owner.state != RUNNING:
            return False
        inst = frame.inst
        try:
            holds = condition(inst.scope, self.state.now)
        except OpspecError as error:
            self.abort(inst, owner.act, f"the AdHocCompletionCondition failed: {error.message}")
            return True
        if not holds:
            return False
        if frame.queue:
            frame.queue.clear()
        for ai in list(frame.running.values()):
            self.activities.stop(ai, TERMINATED, "the ad-hoc set's completion condition holds")
        frame.live = 0
        frame.parked = 0
        self.frame_done(frame)
        return True

    def resolve_frames(self) -> None:
        """OR joins that nothing can reach any more fire; a frame with only parked tokens
        left is deadlocked (:func:`opspec.engine.joins.resolve_frames`)."""
        joins.resolve_frames(self)

    def finish(self, frame: Frame, act: CompiledActivity,
               local: dict[str, Any] | None = None, assigns: bool = True) -> None:
        """Completion of ``act``, then on to what follows it (``local``: the element of the
        collection multi-instance's instance that completes it, seen by its end assignments;
        ``assigns`` false: a multi-instance of no instance, whose end assignments never run)."""
        nxt = self.done_next(frame, act, local, assigns)
        if nxt is not None:
            self.activities.start(frame, nxt)

    def done_next(self, frame: Frame, act: CompiledActivity,
                  local: dict[str, Any] | None = None, assigns: bool = True
                  ) -> CompiledActivity | None:
        """Complete ``act`` (end assignments, throw/raise, trace) and take its split.

        Returns the activity the token moves on to when it can be started right away (an
        XOR split or a single transition into an activity without AND/OR join); otherwise
        the token has been queued, parked or has ended, and ``None`` is returned.
        """
        inst = frame.inst
        if act.simple_end:
            state = self.state
            cached = act.flag_cache           # RunState.act_bits's cached case, in line
            if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 2:
                state.emit(EK.ACTIVITY_COMPLETED, act.process, inst.id, act.id, act.lane,
                           act.participant)
            nxt = act.next
            if nxt >= 0:
                target = frame.graph.activities[nxt]
                if not target.join:
                    return target
            return self.split(frame, act, inst)
        if act.end_assign and act.loop is None and assigns and not self.assign(
                inst, act, act.end_assign, inst.scope if local is None else ChainMap(local, inst.scope)):
            return None
        if act.kind == K_THROW and act.trigger is not None:
            self.triggers.broadcast(act.trigger.kind, act.trigger.name or "", None, inst, act)
        cached = act.flag_cache               # RunState.act_bits's cached case, in line
        if (cached.bits if cached.key is self.state.flag_key else self.state.act_bits(act)) & 2:
            self.state.emit(EK.ACTIVITY_COMPLETED, act.process, inst.id, act.id, act.lane,
                      act.participant)
        if act.raises is not None and inst.state == RUNNING:
            self.triggers.broadcast(act.raises.kind, act.raises.name or "", None, inst, act)
        if act.error is not None:
            escalations.throw_error(self, frame, act, act.error)
            return None
        if act.escalation is not None and not escalations.throw(self, frame, act.escalation):
            return None                     # an interrupting catcher cancelled this scope
        if act.terminate:
            if frame.owner is not None:
                self.terminate_frame(frame, f"end event {act.id!r}")
                return None
            self.end_instance(inst, TERMINATED, f"end event {act.id!r}", notify_parent=False)
            parent = inst.parent
            if parent is not None and parent.state == RUNNING:
                parent.child = None
                self.activities.body_done(parent, None)
            return None
        if inst.state != RUNNING:
            return None
        return self.split(frame, act, inst)

    def split(self, frame: Frame, act: CompiledActivity, inst: ProcessInstance
               ) -> CompiledActivity | None:
        """The split of a completed activity (see :meth:`done_next`; Activities.start too)."""
        acts = frame.graph.activities
        nxt = act.next
        if nxt >= 0:
            target = acts[nxt]
            if not target.join:
                return target
            trans = act.out[0]
        elif act.split == S_XOR and not act.choice and not act.drawn and (act.out or act.otherwise):
            chosen = lone.xor_transition(self, inst, act, frame)
            if chosen is None:
                return None
            trans = chosen
            target = acts[trans.target]
            if not target.join and trans.tokens == 1:
                if trans.assignments:
                    scope = inst.scope
                    now = self.state.now
                    for target_name, fn in trans.assignments:
                        self.set_field(inst, None, target_name, fn(scope, now))
                return target
        elif not act.out and not act.otherwise and not act.choice and not act.drawn:
            self.token_gone(frame)          # an end: _leave's last step, without its call
            return None
        else:
            self._leave(frame, act)
            return None
        self.take(frame, trans)
        self.token_gone(frame)
        return None

    def _leave(self, frame: Frame, act: CompiledActivity) -> None:
        if act.choice:
            ai = ActivityInstance(self.state.next_key(), act, frame, self.state.now, RUNNING)
            frame.running[ai.key] = ai
            self.offers.offer_choice(ai, act.choice)
            return
        if act.drawn and (not act.inputs or drawing.inputs_missing(self, act)):
            drawing.draw(self, frame, act)
            self.token_gone(frame)
            return
        outs = act.out
        if outs or act.otherwise:
            inst = frame.inst
            scope = inst.scope
            now = self.state.now
            taken = False
            try:
                if act.split == S_XOR:
                    for trans in outs:
                        cond = trans.condition
                        if cond is None or cond(scope, now):
                            self.take(frame, trans)
                            taken = True
                            break
                else:
                    for trans in outs:
                        cond = trans.condition
                        if cond is None or cond(scope, now):
                            self.take(frame, trans)
                            taken = True
            except OpspecError as error:
                self.abort(inst, act, f"a transition condition failed: {error.message}")
                return
            if not taken and not act.otherwise and act.path_may_end:
                pass                                # no condition holds: this path ends
            elif not taken:
                if not act.otherwise:
                    self.abort(inst, act, "no outgoing transition can be taken (no condition "
                               "holds and there is no OTHERWISE transition)")
                    return
                self.take(frame, act.otherwise[0])
        self.token_gone(frame)

    def take(self, frame: Frame, trans: CTransition, performed: bool = False) -> None:
        if trans.assignments:
            inst = frame.inst
            now = self.state.now
            for target, fn in trans.assignments:
                self.set_field(inst, None, target, fn(inst.scope, now))
        frame.live += 1
        performs = self.performs            # (empty compiled: its size, no look-up)
        if performed and performs and trans in performs:
            self.state.ready.append((performs[trans], frame, self.activities, trans))
        else:
            self.state.ready.append((self.performed_q if performed else self.arrive_q, frame,
                                     trans.target, trans))
        if trans.tokens > 1:                # a thread split (WCP-42): one token each
            for _ in range(trans.tokens - 1):
                frame.live += 1
                self.state.ready.append((self.arrive_q, frame, trans.target, trans))

    def performed(self, frame: Frame, index: int, trans: CTransition | None) -> None:
        """A branch of a deferred choice: the performer's choice (or the caught event) *is*
        the chosen activity, which completes at once."""
        inst = frame.inst
        if inst.state != RUNNING or (frame.owner is not None and frame.owner.state != RUNNING):
            self._dropped(frame, self.performed, index, trans)
            return
        act = frame.graph.activities[index]
        state = self.state                    # RunState.emit_act, by the cached bits
        cached = act.flag_cache
        if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 1:
            state.emit(EK.ACTIVITY_STARTED, act.process, inst.id, act.id, act.lane,
                       act.participant)
        if act.start_assign and not self.assign(inst, act, act.start_assign):
            return
        self.finish(frame, act)

    def set_field(self, inst: ProcessInstance, act: CompiledActivity | None, target: str,
             value: Any) -> None:
        state = self.state
        if ((data := inst.data) and target in data) or target not in state.package_data:
            data[target] = value
        else:
            state.package_data[target] = value
        if act is None:
            wanted = state.wants_all or (EK.DATA_CHANGED, inst.process.id, None) in state.wanted
        else:
            cached = act.flag_cache           # RunState.act_bits's cached case, in line
            wanted = ((cached.bits if cached.key is state.flag_key
                       else state.act_bits(act)) & 8) != 0
        if wanted:
            state.emit(EK.DATA_CHANGED, inst.process.id, inst.id,
                       act.id if act is not None else None, inst.process.lane, None,
                       {target: value})
        if state.rules:
            self.triggers.check_rules()

    def assign(self, inst: ProcessInstance, act: CompiledActivity,
                assignments: tuple[tuple[str, Any], ...],
                scope: Mapping[str, Any] | None = None) -> bool:
        """Run ``assignments`` (reading ``scope``, by default the instance's data); ``False``
        when the instance ended meanwhile (a failed assignment aborts it; a data change can
        fire its end trigger): the caller stops."""
        now = self.state.now
        reads = inst.scope if scope is None else scope
        try:
            for target, fn in assignments:      # (a Constant's value without its call)
                value = fn.value if COMPILED and isinstance(fn, Constant) else fn(reads, now)
                self.set_field(inst, act, target, value)
                if inst.state != RUNNING:
                    return False
        except OpspecError as error:
            self.abort(inst, act, f"an assignment failed: {error.message}")
            return False
        return True

    def exception_flow(self, frame: Frame, act: CompiledActivity, exception: str,
                        message: str, beside: bool) -> None:
        """Follow the EXCEPTION (or DEFAULTEXCEPTION) transition for ``exception``; without
        one, abort the instance (unless the exception path was to start ``beside``)."""
        # the transition named for the exception, else one for every exception
        trans = next((t for t in act.exceptions if t.exception == exception),
                     next((t for t in act.exceptions if t.exception is None),
                          act.default_exception))
        inst = frame.inst
        if trans is None:
            if not beside:
                self.abort(inst, act, message or f"exception {exception!r}")
            return
        self.state.emit_act(EK.EXCEPTION_RAISED, inst, act,
                       {"exception": exception, "transition": trans.id, "message": message})
        self.take(frame, trans)
        if not beside:
            self.token_gone(frame)
