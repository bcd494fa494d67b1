"""An activity's life: start, implementation, time, loops and multi-instance, completion.

Instantaneous activities (routes, events, tasks without a bound callable) run in the loop of
:meth:`Activities.start` without an :class:`~opspec.engine.instances.ActivityInstance`; the
others get one and go through: start trigger, multi-instance (``MI_Condition`` instances,
``MI_FlowCondition`` deciding which move on), start assignments, deadlines and boundary
events armed, loop test (``TestTime`` before), CPU time on a worker, the sampled duration,
the body by kind (offer to a performer, tools and scripts, subflow call, activity set, catch
event, coordination), then :meth:`Activities.body_done` (loop again or complete). Failures
(:meth:`Activities.fail`) and cancellation (:meth:`Activities.stop`) end an instance early."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any, Final, final

from opspec.engine import call_depth, coordinating, multi_instance, plans, tools
from opspec.engine.compiled import (
    K_ASYNC,
    K_BLOCK,
    K_CATCH,
    K_COORD,
    K_GATEWAY,
    K_MANUAL,
    K_SUBFLOW,
    K_TASK,
    CompiledActivity,
    CompiledProcess,
)
from opspec.engine.instances import ActivityInstance, Frame, MultiInstance, ProcessInstance
from opspec.engine.lifecycle import ABORTED, COMPLETED, RUNNING, SUSPENDED, TERMINATED
from opspec.engine.part import Part
from opspec.engine.timers import TUPLES, Timed
from opspec.engine.trace import EventKind as EK
from opspec.errors import OpspecError
from opspec.model import ParameterMode

if TYPE_CHECKING:
    from opspec.engine.runstate import RunState

#: Whether ``body_done`` reads a dict of answers as one (compiled: the dict's own iteration;
#: a Mapping's is an ``items`` method call through Python's protocol and an iterator, 0.7k a
#: workflow instance on the periodic path, where a world's answer carries its readings).
#: From source the test alone would cost more than it saves.
DICTS: Final = not TUPLES

MAX_CALL_DEPTH: Final = call_depth.MAX_CALL_DEPTH      # (call_depth's, for its importers)



class Activities(Part):
    """An activity's life from start to completion (see the module docstring)."""

    def __init__(self, state: RunState) -> None:
        super().__init__(state)
        # Bound once, for the ready queue (see Flow.__init__).
        self.activate_q: Callable[[ActivityInstance, Any, Any], None] = self.activate
        self.body_done_q: Callable[[ActivityInstance, Any, Any], None] = self.body_done
        self.run_body_q: Callable[[ActivityInstance, Any, Any], None] = self._run_body
        # from source, the resume plans of the package's workflows (opspec.engine.plans):
        # by the activity whose completion (body_done's) they carry on from; empty compiled
        self.resumes: dict[CompiledActivity, Callable[[Activities, ActivityInstance], None]] = (
            {} if plans.COMPILED else plans.resumes(state.compiled))
        # ... and for the activities without a loop, their done plans, body_done's own steps
        # written out before the resume (Offers.performer_complete queues them itself)
        self.dones: dict[CompiledActivity, Callable[[ActivityInstance, Activities, Any], None]] = (
            {} if plans.COMPILED else plans.dones(state.compiled))
        # the free ends of CPU demands (_CpuDone), each holding the next (not a list: one
        # that empties and fills again reallocates its array each time)
        self.cpu_ends: _CpuDone | None = None

    def _too_deep(self, ai: ActivityInstance, target: CompiledProcess) -> None:
        call_depth.too_deep(self, ai, target)       # (runaway recursion: a rare path)

    def start(self, frame: Frame, act: CompiledActivity | None, steps: int = 0,
              limit: int = -1) -> None:
        """Start ``act``. Instantaneous activities run here, in a loop that carries the
        token straight on to the next activity (no queue round trip) as long as the next
        one has no AND/OR join to synchronise at. (``steps`` and ``limit``: where
        :func:`opspec.engine.lone.run`, which hands its token over, had got to.)"""
        state = self.state
        pooled = state.pooled
        apps = state.apps
        if limit < 0:
            limit = state.start_limit
        flow = self.flow
        while act is not None:
            if not act.fast or (act.general and pooled) or (
                    act.kind == K_TASK and act.application in apps):
                self.start_slow(frame, act)
                return
            inst = frame.inst
            steps += 1
            if steps > limit:                   # a zero-time cycle (see RunState.drain)
                state.zero_time(frame, act)
            # RunState.act_bits, its cached case read here: this loop is the path of every
            # instantaneous activity, and from source each call is a Python frame
            cached = act.flag_cache
            bits = (cached.bits if cached.key is state.flag_key else state.act_bits(act))
            if bits & 1:
                state.emit(EK.ACTIVITY_STARTED, act.process, inst.id, act.id, act.lane,
                           act.participant)
            if act.simple_end and not act.start_assign and act.kind != K_ASYNC:
                # Flow.done_next's first case, in line: a straight run of instantaneous
                # activities (route, event, no-op) is this one loop, one pass per activity
                if bits & 2:
                    state.emit(EK.ACTIVITY_COMPLETED, act.process, inst.id, act.id, act.lane,
                               act.participant)
                nxt = act.next
                if nxt >= 0:
                    target = frame.graph.activities[nxt]
                    if not target.join:
                        act = target
                        continue
                act = flow.split(frame, act, inst)
                continue
            if act.start_assign and not flow.assign(inst, act, act.start_assign):
                return
            if act.kind == K_ASYNC:
                data = self.params_in(inst, act)
                if data is None:
                    return
                flow.start_process(state.processes[act.subflow],  # type: ignore[index]
                                   data, trigger=f"subflow:{act.id}")
            act = flow.done_next(frame, act)

    def params_in(self, inst: ProcessInstance, act: CompiledActivity
                   ) -> dict[str, Any] | None:
        now = self.state.now
        try:
            return {formal: fn(inst.scope, now)
                    for _mode, formal, fn, _target in act.params if fn is not None}
        except OpspecError as error:
            self.flow.abort(inst, act, f"an actual parameter failed: {error.message}")
            return None

    def start_slow(self, frame: Frame, act: CompiledActivity) -> None:
        """Start ``act``, which waits or takes time: as an activity instance (a coordination
        built-in done at once without one: :func:`coordinating.at_once`)."""
        if act.kind == K_COORD and act.plain and coordinating.at_once(self, frame, act):
            return
        state = self.state
        state.last_key += 1                   # RunState.next_key, in line
        ai = ActivityInstance(state.last_key, act, frame, state.now, RUNNING)
        frame.running[ai.key] = ai
        if act.plain and not (act.general and state.pooled):
            inst = frame.inst
            cached = act.flag_cache           # RunState.act_bits's cached case, in line
            if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 1:
                state.emit(EK.ACTIVITY_STARTED, act.process, inst.id, act.id, act.lane,
                           act.participant)
            if act.start_assign and not self.flow.assign(inst, act, act.start_assign):
                return
            if act.kind == K_MANUAL and not act.params:
                known = state.performers_of     # Offers.performer_for's cached case
                performer = known[act] if act in known else self.offers.performer_for(act)
                if performer is not None:
                    self.offers.offer(ai, performer, (), None, None)
                    return
            self._body(ai)
            return
        if act.start_trigger is not None:
            ai.waiting = f"start trigger {act.start_trigger.kind}:{act.start_trigger.name}"
            self.triggers.wait_trigger(ai, act.start_trigger, self._activate_cb, None)
            return
        self.activate(ai)

    def _activate_cb(self, ai: ActivityInstance, _arg: Any, _data: Any = None) -> None:
        self.state.ready.append((self.activate_q, ai, None, None))

    def activate(self, ai: ActivityInstance, _a: Any = None, _b: Any = None) -> None:
        if ai.state != RUNNING:
            return
        act = ai.act
        inst = ai.frame.inst
        if act.mi is not None and ai.mi is None and not multi_instance.begin(self, ai):
            return
        state = self.state                    # RunState.emit_act, by the cached bits
        cached = act.flag_cache
        if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 1:
            state.emit(EK.ACTIVITY_STARTED, act.process, inst.id, act.id, act.lane,
                       act.participant)
        if act.start_assign and not self.flow.assign(inst, act, act.start_assign, ai.scope()):
            return
        now = self.state.now
        # a multi-instance activity's deadlines and boundary events are the whole activity's:
        # armed once, on the group's holder, when its first instance starts
        armed = ai if ai.mi is None else (ai.mi.holder if ai.iteration == 0 else None)
        if armed is not None:
            for seconds, synchronous, exception in act.deadlines:
                try:
                    delay = float(seconds(inst.scope, now))
                except OpspecError as error:
                    self.flow.abort(inst, act, f"deadline cannot be computed: {error.message}")
                    return
                self.state.later(delay, self.triggers.deadline_q, armed,
                                 (synchronous, exception, delay))
            for index in act.boundary:
                event = ai.frame.graph.activities[index]
                if event.trigger is not None:
                    self.triggers.wait_trigger(armed, event.trigger, self.triggers.boundary,
                                               index, persistent=True)
        if act.loop is not None and act.loop[2] and not self._loop_again(ai):
            self._complete(ai)
            return
        if (act.cpu == 0.0 and act.cpu_sampler is None and act.sampler is None
                and not act.general):
            # _run_body and after_cpu with nothing to wait for (no CPU, no duration), in
            # line: the body at once (an event caught with a deadline, a subflow call)
            if ai.state == RUNNING:
                self._body(ai)
                if not state.draining:
                    state.drain()
            return
        self._run_body(ai)

    def mi_cancel(self, group: MultiInstance, frame: Frame, reason: str) -> None:
        """An interrupting event ends every instance of a multi-instance group
        (:func:`opspec.engine.multi_instance.cancel`)."""
        multi_instance.cancel(self, group, frame, reason)

    def _loop_again(self, ai: ActivityInstance) -> bool:
        cond, maximum, _before = ai.act.loop  # type: ignore[misc]
        if maximum is not None and ai.iteration >= maximum:
            return False
        if cond is None:
            return maximum is not None
        inst = ai.frame.inst
        return bool(cond(inst.scope, self.state.now))

    def _run_body(self, ai: ActivityInstance, _a: Any = None, _b: Any = None) -> None:
        if ai.state != RUNNING:
            return
        act = ai.act
        cpu = act.cpu
        if act.cpu_sampler is not None:       # CpuDemand as a distribution: its own stream
            cpu = act.cpu_sampler(self.state.streams.stream(f"{act.process}/{act.id}/cpu"))
        if act.general or cpu:
            if self.state.pool is not None:
                level = (ai.frame.inst.priority if act.priority is None
                         else act.priority) + act.priority_increment
                cost = self.state.switch + cpu if act.general else cpu
                ai.waiting = "worker"
                if self.state.pool.submit(ai, level, cost):
                    self.state.emit_act(EK.QUEUED, ai.frame.inst, act,
                                   {"waiting": self.state.pool.waiting, "priority": level})
                return
            if cpu > 0.0:
                self.state.dedicated.burst(self.state.now, cpu)
                ai.waiting = "cpu"
                end = self.cpu_ends
                if end is None:
                    end = _CpuDone(self)
                else:
                    self.cpu_ends = end.spare
                end.ai = ai
                end.gen = ai.gen
                self.state.later_entry(cpu, end)
                return
        self.after_cpu(ai)

    def _after_cpu_cb(self, ai: ActivityInstance, _arg: Any) -> None:
        self.after_cpu(ai)

    def after_cpu(self, ai: ActivityInstance) -> None:
        if ai.state != RUNNING:
            return
        act = ai.act
        if act.sampler is not None and act.kind != K_MANUAL:
            delay = act.sampler(self.state.streams.stream(f"{act.process}/{act.id}"))
            if delay > 0.0:
                ai.waiting = "duration"
                self.state.later(delay, self._body_cb, ai)
                return
        self._body(ai)
        if not self.state.draining:
            self.state.drain()

    def _body_cb(self, ai: ActivityInstance, _arg: Any) -> None:
        self._body(ai)

    def _body(self, ai: ActivityInstance) -> None:
        """What the activity does, by kind; ends with :meth:`body_done` (maybe later)."""
        act = ai.act
        kind = act.kind
        inst = ai.frame.inst
        app = act.application
        apps = self.state.apps
        # a task's performer, looked up once: the application's name is equal to the
        # registry's key but not the same string, so each look-up compares the text
        performer = (apps.get(app) if kind == K_TASK and app is not None
                     and not act.toolchain else None)
        if kind == K_TASK and act.toolchain:
            tools.run(self, ai, 0)
        elif kind == K_MANUAL or performer is not None or (kind == K_TASK and app in apps):
            if kind == K_MANUAL:
                performer = self.offers.performer_for(act)
            if performer is None:
                ai.waiting = (f"performer for participant {act.participant!r}"
                              f" / lanes {', '.join(act.lanes) or '-'}")
                self.state.emit_act(EK.ACTIVITY_OFFERED, inst, act, {"performer": None})
                return
            if (kind == K_TASK and isinstance(performer, AnswersAtOnce) and not act.params
                    and act.sampler is None and ai.local is None and act.application
                    and performer.answers_at_once(act.application)):
                self._answered(ai, performer)
                return
            data: Mapping[str, Any] | None = None
            if act.params:
                data = self.inputs(ai)
                if data is None:
                    return
            duration = None
            if act.sampler is not None:
                duration = act.sampler(self.state.streams.stream(f"{act.process}/{act.id}"))
            self.offers.offer(ai, performer, (), data, duration)
        elif kind == K_SUBFLOW or kind == K_ASYNC:
            data = self.inputs(ai)
            if data is None:
                return
            target = self.state.processes[act.subflow]  # type: ignore[index]
            if kind == K_SUBFLOW:
                if inst.depth >= MAX_CALL_DEPTH:
                    self._too_deep(ai, target)
                    return
                ai.waiting = f"subflow {target.id}"
                ai.child = self.flow.start_process(target, data, parent=ai)
            else:
                self.flow.start_process(target, data, trigger=f"subflow:{act.id}")
                self.body_done(ai, None)
        elif kind == K_CATCH:
            trig = act.trigger
            assert trig is not None
            ai.waiting = f"{trig.kind}:{trig.name}" if trig.name else trig.kind
            self.triggers.wait_trigger(ai, trig, self.triggers.caught_q, None)
        elif kind == K_BLOCK:
            assert act.block is not None
            frame = Frame(act.block, inst, ai)
            inst.frames.append(frame)
            ai.child = frame
            ai.waiting = f"activity set {act.block.name}"
            starts = act.block.starts
            if act.block.sequential and starts:       # one at a time, in declared order
                frame.queue = list(starts[1:])
                starts = starts[:1]
            for index in starts:
                frame.live += 1
                self.state.ready.append((self.flow.start_at_q, frame, index, None))
            if not act.block.starts:
                self.body_done(ai, None)
        elif kind == K_COORD:
            self._coordinate(ai)
        elif kind == K_GATEWAY:
            self.offers.offer_choice(ai, act.out)
        else:                                       # noop, throw, task without a callable
            # queued, not called: a chain of such activities must not grow the stack
            self.state.ready.append((self.body_done_q, ai, None, None))

    def _answered(self, ai: ActivityInstance, performer: AnswersAtOnce) -> None:
        """What ``Offers.offer``, the performer's ``offer`` and ``complete`` do for a task
        answered at once, without the work item nobody else sees."""
        act = ai.act
        inst = ai.frame.inst
        state = self.state
        ai.performer = performer
        ai.waiting = "performer"
        cached = act.flag_cache
        if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 4:
            state.emit(EK.ACTIVITY_OFFERED, act.process, inst.id, act.id, act.lane,
                       act.participant, None)
        if not state.inside:                # (the session's clock, read from outside)
            state.sync()
        result = performer.answer(act.application or "", inst.data, state.now)
        if ai.state != RUNNING:
            state.stale_completions += 1
            return
        state.ready.append((self.body_done_q, ai, result or None, None))
        if not state.draining:
            state.drain()

    def body_done(self, ai: ActivityInstance, data: Mapping[str, Any] | None,
                   _unused: Any = None) -> None:
        """One execution of the body finished: loop again or complete."""
        dones = self.dones                  # (empty compiled: its size, no look-up)
        if dones and ai.act in dones:       # from source: these steps and on, written out
            dones[ai.act](ai, self, data)
            return
        if ai.state != RUNNING:
            return
        if ai.frame.inst.state == SUSPENDED:
            ai.frame.inst.defer((self.body_done, ai, data, None))
            return
        if data:
            inst = ai.frame.inst
            act = ai.act
            if DICTS and type(data) is dict:
                for key, value in data.items():
                    self.flow.set_field(inst, act, key, value)
            else:
                for key, value in data.items():
                    self.flow.set_field(inst, act, key, value)
        act = ai.act
        if act.loop is not None:
            # each iteration is one execution of the activity: its assignments apply each time
            inst = ai.frame.inst
            if act.end_assign and not self.flow.assign(inst, act, act.end_assign):
                return
            ai.iteration += 1
            if ai.iteration > 1_000_000:
                self.flow.abort(inst, act, "loop ran 1,000,000 times; add a maximum")
                return
            if self._loop_again(ai):
                if act.start_assign and not self.flow.assign(inst, act, act.start_assign):
                    return
                self.state.ready.append((self.run_body_q, ai, None, None))
                return
        resumes = self.resumes              # (empty compiled: its size, no look-up)
        if resumes and act in resumes:      # from source: _complete and on, written out
            resumes[act](self, ai)
            return
        self._complete(ai)

    def _complete(self, ai: ActivityInstance) -> None:
        ai.state = COMPLETED    # every activity's completion: ActivityInstance.leave in line
        ai.gen += 1
        frame = ai.frame
        key: object = ai.key                # (boxed once: see ActivityInstance.leave)
        try:                                # (one look-up where a test and a del took two;
            del frame.running[key]          # compiled, a try costs nothing until it catches)
        except KeyError:
            pass
        if ai.cleanup:
            ai.undo_waits()
        if ai.mi is not None:
            multi_instance.done(self, ai, ai.mi)
            return
        # Flow.finish's steps, Flow.done_next's first case, a waiting target's start: in line
        act = ai.act
        if act.simple_end:
            state = self.state
            inst = frame.inst
            cached = act.flag_cache           # RunState.act_bits's cached case, in line
            if (cached.bits if cached.key is state.flag_key else state.act_bits(act)) & 2:
                state.emit(EK.ACTIVITY_COMPLETED, act.process, inst.id, act.id, act.lane,
                           act.participant)
            nxt = act.next
            target = frame.graph.activities[nxt] if nxt >= 0 else None
            if target is None or target.join:
                target = self.flow.split(frame, act, inst)
        else:
            target = self.flow.done_next(frame, act)
        if target is not None:
            if target.fast:
                self.start(frame, target)
            else:
                self.start_slow(frame, target)

    def inputs(self, ai: ActivityInstance,
                params: tuple[tuple[ParameterMode, str, Any, str | None], ...] | None = None
                ) -> dict[str, Any] | None:
        """The actual parameters' values by formal (``params``: a tool's; by default the
        activity's); ``None`` when one failed (the activity failed)."""
        reads = ai.scope()
        now = self.state.now
        out: dict[str, Any] = {}
        try:
            for _mode, formal, fn, _target in (ai.act.params if params is None else params):
                if fn is not None:                  # OUT parameters carry nothing in
                    out[formal] = fn(reads, now)
        except OpspecError as error:
            self.fail(ai, "parameter", f"an actual parameter failed: {error.message}")
            return None
        return out

    def tool_done(self, ai: ActivityInstance, data: Mapping[str, Any] | None,
                   _unused: Any = None) -> None:
        """The performer of one tool completed (a ready-queue item): :func:`tools.done`."""
        tools.done(self, ai, data)

    def fail(self, ai: ActivityInstance, exception: str, message: str) -> None:
        act = ai.act
        frame = ai.frame
        self.stop(ai, ABORTED, exception)
        self.state.emit_act(EK.ACTIVITY_FAILED, frame.inst, act,
                       {"exception": exception, "message": message})
        self.flow.exception_flow(frame, act, exception, message, False)

    def stop(self, ai: ActivityInstance, state: int, reason: str) -> None:
        """Cancel ``ai``: it stops waiting, its offer is withdrawn, its children end."""
        if ai.state != RUNNING and ai.state != SUSPENDED:
            return
        ai.leave(state)
        frame = ai.frame
        group = ai.mi
        if (group is not None and group.holder is not None and ai is not group.holder
                and not any(m.state == RUNNING for m in group.members)):
            multi_instance.release(group)
        item = ai.item
        if item is not None:
            ai.item = None
            offered = self.state.offered
            if item.key in offered:
                del offered[item.key]
            self.state.emit_act(EK.ACTIVITY_WITHDRAWN, frame.inst, ai.act, {"reason": reason})
            performer = ai.performer
            if performer is not None:
                performer.withdraw(item, reason)
        child = ai.child
        ai.child = None
        if isinstance(child, ProcessInstance):
            child.parent = None
            self.flow.end_instance(child, TERMINATED, f"caller stopped: {reason}")
        elif isinstance(child, Frame):
            for sub in list(child.running.values()):
                self.stop(sub, TERMINATED, reason)
            if child in frame.inst.frames:
                frame.inst.frames.remove(child)
        for queue in self.state.pullers.values():
            if ai in queue:
                queue.remove(ai)

    def _coordinate(self, ai: ActivityInstance) -> None:
        coordinating.coordinate(self, ai)

    def push_data(self, channel: str, value: Any) -> None:
        """Put ``value`` into supervisor mailbox ``channel``; a waiting pull gets it."""
        coordinating.push(self, channel, value)


class AnswersAtOnce:
    """A performer whose operations answer as soon as asked (a simulated world's devices):
    such a task runs without a work item (:meth:`Activities._answered`), with the same
    trace, data and completion as through its ``offer`` and its session's ``complete``.

    It has the :class:`~opspec.engine.performers.Performer` protocol's methods, which a
    subclass implements: a performer found to be one (``isinstance``) is then known to be
    this class, and compiled code calls :meth:`answers_at_once` as its native method (for a
    class outside the protocol, the type is a mix of the two that compiled code calls
    through Python's protocol: 0.35k instructions a task)."""

    def attach(self, session: Any) -> None:
        """The run's session, before it starts (the performer protocol's)."""

    def offer(self, item: Any) -> None:
        """A work item for one of its operations (the performer protocol's)."""
        raise NotImplementedError

    def withdraw(self, item: Any, reason: str) -> None:
        """An offered item no longer wanted (the performer protocol's)."""

    def answers_at_once(self, application: str) -> bool:
        """Whether :meth:`answer` does ``application`` now (else it is offered)."""
        return False

    def answer(self, application: str, data: Mapping[str, Any], now: float) -> dict[str, Any]:
        """Do ``application`` at ``now`` with the instance's ``data`` (read, never changed:
        a work item's is a read-only view): the data it completes with."""
        raise NotImplementedError


@final
class _CpuDone(Timed):
    """A CPU demand's end (:meth:`RunState.later` of :meth:`Activities.after_cpu`, and what
    :meth:`RunState.fired` does with it): compiled, ``after_cpu`` is called as the native
    method it is, not as a bound method made per demand and called through Python's protocol
    (once a workflow instance on the periodic path).

    Used again, not made and freed per demand: the run's heap (or SimPy) calls an entry once
    each time it was scheduled and then holds it no more (a CPU demand's end is never
    dropped, unlike a workflow's deadline), so at the end of that call it is free: back to
    :attr:`Activities.cpu_ends`, no longer holding its activity instance."""

    def __init__(self, acts: Activities) -> None:
        self.acts = acts
        self.ai: ActivityInstance | None = None
        self.gen = 0
        self.spare: _CpuDone | None = None     # the next free one, while this one is free

    def go(self) -> None:
        ai = self.ai
        acts = self.acts
        if ai is not None:
            self.ai = None
            if ai.gen == self.gen and ai.state == RUNNING:
                if ai.frame.inst.state == SUSPENDED:    # RunState.fired defers it
                    acts.state.fired(acts._after_cpu_cb, ai, None, self.gen)
                else:
                    acts.after_cpu(ai)
                    acts.state.drain()
        self.spare = acts.cpu_ends
        acts.cpu_ends = self

    def __call__(self, _event: Any) -> None:
        ai = self.ai
        acts = self.acts
        if ai is not None:
            self.ai = None
            acts.state.fire(acts._after_cpu_cb, ai, None, self.gen)
        self.spare = acts.cpu_ends
        acts.cpu_ends = self
