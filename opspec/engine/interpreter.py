"""The workflow manager and processor: tokens through compiled graphs on a SimPy clock.

Design (for speed, see ``benchmarks/engine_profile.py``):

* Zero-time work never becomes a SimPy event. A token moving to an activity is a tuple in
  the interpreter's *ready queue*; :meth:`Interpreter._drain` runs them in FIFO order until
  none is left (a trampoline: no recursion however long a chain of instant activities is,
  and performers may call back into the session from inside ``offer``).
* SimPy events exist only where simulated time passes: a timer, a deadline, a duration, a
  worker's CPU time, a performer's ``call_later``. They are bare events with a callback
  (:class:`~opspec.engine.wakeup.Wakeups`), never a generator process per activity. SimPy
  cannot cancel a scheduled event, so a timer carries the *generation* of its activity
  instance and does nothing when the instance has moved on.
* Instantaneous activities (routes, events, tasks without a bound callable, activities with
  no implementation) run without an :class:`~opspec.engine.instances.ActivityInstance`;
  only activities that wait get one.
* Trace events are built only when some listener wants that (kind, process, activity);
  a listener with a ``raw`` method (the metrics) gets the fields without any event object.
* The hot paths read ``env._now`` rather than the ``env.now`` property: same value, one
  function call less, several times per activity.

Semantics (XPDL / SISARL, see ``docs/trace-format.md`` for what each step records):

* Joins: XOR (or none) starts the activity for every arriving token; AND waits for one token
  on *each* incoming transition and consumes one from each (per loop iteration, so cycles
  work; the last arriving branch performs the merge); OR waits for the tokens that can still
  arrive: it fires when no running activity and no parked token upstream of it is left.
* Splits: XOR takes the first CONDITION that holds (or unconditional transition) in declared
  order, else the OTHERWISE transition; AND takes every unconditional transition and every
  condition that holds; OR takes every condition that holds, else OTHERWISE. No split and
  several unconditional transitions means AND. Nothing to take while transitions exist is
  an error that aborts the instance.
* Exceptions (implementation raised, performer ``fail``, deadline): the EXCEPTION transition
  naming the exception (or naming none), else DEFAULTEXCEPTION, else the instance aborts.
"""

from __future__ import annotations

import dataclasses
import itertools
from collections import ChainMap, deque
from collections.abc import Callable, Iterable, Mapping, MutableMapping
from types import MappingProxyType
from typing import Any

import simpy

from opspec.engine import coordination as coord
from opspec.engine.compiled import (
    J_AND,
    J_COMPLEX,
    K_ASYNC,
    K_BLOCK,
    K_CATCH,
    K_COORD,
    K_GATEWAY,
    K_MANUAL,
    K_SUBFLOW,
    K_TASK,
    K_THROW,
    MI_ALL,
    MI_NONE,
    MI_ONE,
    S_XOR,
    CompiledActivity,
    CompiledPackage,
    CompiledProcess,
    CTransition,
    CTrigger,
)
from opspec.engine.config import EngineConfig
from opspec.engine.instances import ActivityInstance, Frame, MultiInstance, ProcessInstance
from opspec.engine.lifecycle import (
    ABORTED,
    COMPLETED,
    LIFECYCLE,
    RUNNING,
    STATE_NAMES,
    SUSPENDED,
    TERMINATED,
)
from opspec.engine.performers import Performer, WorkItem
from opspec.engine.processors import DedicatedProcessor, PooledProcessor, PreemptiveProcessor
from opspec.engine.random import Streams
from opspec.engine.registry import PerformerRegistry
from opspec.engine.trace import EventKind as EK
from opspec.engine.trace import TraceEvent, TraceListener
from opspec.engine.wakeup import Wakeups
from opspec.engine.zero_time import ZeroTimeSampler
from opspec.engine.zero_time import max_instant_steps as _max_instant_steps
from opspec.errors import ExecutionError, OpspecError
from opspec.model import CoordinationKind, Package, ParameterMode

__all__ = ["Interpreter"]

_EMPTY: Mapping[str, Any] = MappingProxyType({})
_NEXT = LIFECYCLE.table
_CHOICE_DONE = object()
#: Messages of one name kept with nobody waiting (per receiving instance, or for anyone).
MESSAGE_BUFFER = 100
#: Synchronous subflow calls nested deeper than this end the run's root instance with a
#: located fault: bounded recursion (a base case) runs, runaway recursion is reported.
MAX_CALL_DEPTH = 100


class Interpreter:
    """Run state of one simulation and the token-flow machinery (see the module docstring).

    The public face is :class:`opspec.engine.simulation.Simulation`, which adds running,
    stepping and results; this class owns instances, triggers, offers and the trace.
    """

    def __init__(self, compiled: CompiledPackage, config: EngineConfig, *,
                 performers: PerformerRegistry, seed: int, listeners: list[TraceListener],
                 params: Mapping[str, Any] | None, env: simpy.Environment | None,
                 scope: tuple[int, ...], mode_loader: Callable[[str], CompiledPackage | Package] | None
                 ) -> None:
        self.compiled = compiled
        self.config = config
        self.env = env if env is not None else simpy.Environment()
        self._wakeups = Wakeups(self.env)
        self.registry = performers
        self.streams = Streams(seed, scope)
        self.mode_loader = mode_loader
        self.processes: dict[str, CompiledProcess] = compiled.processes
        self.package_data: dict[str, Any] = dict(compiled.data)
        if params:
            self.package_data.update(params)
        self._ready: deque[tuple[Any, Any, Any, Any]] = deque()
        self._draining = False
        self._pending: dict[Frame, None] = {}
        self._ids = itertools.count(1)
        self._keys = itertools.count(1)
        self.live: dict[int, ProcessInstance] = {}
        self.counts = {"started": 0, "completed": 0, "terminated": 0, "aborted": 0}
        self.faults: list[dict[str, Any]] = []
        self.deadlocks: list[dict[str, Any]] = []
        self.stale_completions = 0
        self._waiters: dict[tuple[str, str], dict[int, tuple[ActivityInstance, Any, Any]]] = {}
        self._starts: dict[tuple[str, str], list[CompiledProcess]] = {}
        self._ends: dict[tuple[str, str], list[CompiledProcess]] = {}
        self._rules: dict[int, tuple[Any, Any, Any]] = {}       # key -> (cond, handler, arg)
        self._rule_keys = itertools.count(1)
        self._offers: dict[int, ActivityInstance] = {}
        self._mailboxes: dict[str, deque[Any]] = {}
        # messages kept until caught: (receiving root instance id or 0, (kind, name)) ->
        # (data, simulated time it was kept)
        self._kept: dict[tuple[int, tuple[str, str]],
                         deque[tuple[Mapping[str, Any] | None, float]]] = {}
        self.lost_messages = 0
        # the zero-time cycle guard (see _drain)
        self._instant = -1.0
        self._instant_steps = 0
        self.max_instant_steps = _max_instant_steps()
        self._sampler: ZeroTimeSampler | None = None
        self._start_limit = self.max_instant_steps    # 0 while a sampler names the cycle
        self._pullers: dict[str, deque[ActivityInstance]] = {}
        self._perf_cache: dict[CompiledActivity, Performer | None] = {}
        self._apps = performers.applications
        self._tool_at: dict[int, int] = {}    # activity instance key -> tool offered
        self._pooled = config.pooled
        self._switch = config.switch_cost if config.pooled else 0.0
        self._resolution = config.timer_resolution
        self._pool: PooledProcessor | None = None
        if config.processor_model == "preemptive":
            self._pool = PreemptiveProcessor(self.env, config.workers, config.priorities,
                                             self._after_cpu, _alive, config.switch_cost)
        elif config.pooled:
            self._pool = PooledProcessor(self.env, config.workers, config.priorities,
                                         self._after_cpu, _alive)
        self._dedicated = DedicatedProcessor()
        self.raised_names: set[str] = set()
        self.mode = compiled.initial_mode
        # trace: listeners with a ``raw`` method get the fields without a TraceEvent object
        self._listeners = [lst for lst in listeners if getattr(lst, "raw", None) is None]
        self._raw = [lst.raw for lst in listeners  # type: ignore[attr-defined]
                     if getattr(lst, "raw", None) is not None]
        self._seq = 0
        self._pkg = compiled.id
        self._all = False
        selectors: set[tuple[str, str | None, str | None]] = set()
        for listener in listeners:
            wanted = getattr(listener, "selects", None)
            if wanted is None:
                self._all = True
                break
            selectors.update(wanted)
        self._selectors = frozenset(selectors)
        self._want = (frozenset() if self._all or not selectors
                      else compiled.expand_selectors(self._selectors))
        # each full listener only receives what it selects (None: everything)
        self._full = [(lst, None if getattr(lst, "selects", None) is None
                       else compiled.expand_selectors(frozenset(lst.selects)))  # type: ignore[attr-defined]
                      for lst in self._listeners]
        self._aflags = _Flags(self, _ACT_KINDS)      # CompiledActivity -> wanted-kind bits
        self._pflags = _Flags(self, _PROC_KINDS)     # process id -> wanted-kind bits

    # ------------------------------------------------------------------ trace
    def wants(self, kind: str, process: str | None, activity: str | None) -> bool:
        return self._all or (kind, process, activity) in self._want

    def emit(self, kind: str, process: str | None = None, instance: int | None = None,
             activity: str | None = None, lane: str | None = None,
             participant: str | None = None, data: Mapping[str, Any] | None = None) -> None:
        """Send one trace event to every listener (callers check :meth:`wants` first)."""
        self._seq += 1
        now = self.env._now
        for raw in self._raw:
            raw(now, kind, process, instance, activity, data)
        if self._full:
            event = TraceEvent(now, kind, process, instance, activity, lane, participant,
                               self._pkg, data if data is not None else _EMPTY, self._seq)
            for listener, selects in self._full:
                if selects is None or (kind, process, activity) in selects:
                    listener(event)

    def _emit_act(self, kind: str, inst: ProcessInstance, act: CompiledActivity,
                  data: Mapping[str, Any] | None = None) -> None:
        if self._all or (kind, act.process, act.id) in self._want:
            self.emit(kind, act.process, inst.id, act.id, act.lane, act.participant, data)

    # ------------------------------------------------------------------ queue
    def _drain(self) -> None:
        """Run queued zero-time work until none is left (re-entrant calls just return).

        Zero-time work at one simulated instant is counted across drains: each item run and
        each drain (a SimPy event at this instant, so a storm of zero-delay wakeups that queue
        nothing counts too). Past ``max_instant_steps`` the run stops with a
        :class:`~opspec.errors.ZeroTimeCycleError` naming the activities that keep coming
        back (:mod:`opspec.engine.zero_time`)."""
        if self._draining:
            return
        self._draining = True
        ready = self._ready
        pop = ready.popleft
        # Steps are counted without looking at the clock (reading it costs a dictionary
        # lookup per drain); only past the limit does _past_limit ask whether the clock
        # moved since the count began (then it starts again) or not (a zero-time cycle).
        steps = self._instant_steps + 1
        limit = self.max_instant_steps
        try:
            if steps > limit:
                steps = self._past_limit(steps, None, None)
            while True:
                while ready:
                    fn, a, b, c = pop()
                    steps += 1
                    if steps > limit:
                        steps = self._past_limit(steps, a, b)
                    fn(a, b, c)
                if not self._pending:
                    break
                self._resolve_frames()
                if not ready:
                    break
        finally:
            self._draining = False
            self._instant_steps = steps

    def _past_limit(self, steps: int, a: Any, b: Any) -> int:
        """The step count passed the limit: a new count if the clock moved since the count
        began, else a step of a zero-time cycle (see :meth:`_zero_time`)."""
        now = self.env._now
        if now != self._instant:
            self._instant = now
            if self._sampler is not None:         # the clock moved on: no cycle after all
                self._sampler = None
                self._start_limit = self.max_instant_steps
            return 1
        self._zero_time(a, b)
        return steps

    def _zero_time(self, a: Any, b: Any) -> None:
        """A step past the limit at this instant: note what it moves (``a``, ``b`` as in a
        ready-queue item, or a frame and an activity); stop the run once enough are seen."""
        now = self.env._now
        sampler = self._sampler
        if sampler is None or sampler.at != now:
            sampler = self._sampler = ZeroTimeSampler(now, self.max_instant_steps)
            self._start_limit = 0                 # _start notes every activity it carries
        if sampler.record(a, b):
            raise sampler.error()

    def _later(self, delay: float, fn: Callable[[ActivityInstance, Any], None],
               ai: ActivityInstance, arg: Any = None) -> None:
        """Call ``fn(ai, arg)`` after ``delay`` simulated seconds if ``ai`` is still waiting."""
        if self._resolution > 0.0:
            delay = self._align(delay)
        gen = ai.gen
        self._wakeups.after(max(0.0, delay), lambda _e: self._fire(fn, ai, arg, gen))

    def _fire(self, fn: Callable[[ActivityInstance, Any], None], ai: ActivityInstance,
              arg: Any, gen: int) -> None:
        if ai.gen == gen and ai.state == RUNNING:
            inst = ai.frame.inst
            if inst.state == SUSPENDED:
                inst.deferred.append((self._refire, fn, ai, (arg, gen)))
                return
            fn(ai, arg)
            self._drain()

    def _refire(self, fn: Callable[[ActivityInstance, Any], None], ai: ActivityInstance,
                arg_gen: tuple[Any, int]) -> None:
        arg, gen = arg_gen
        if ai.gen == gen and ai.state == RUNNING:
            fn(ai, arg)

    def _align(self, delay: float) -> float:
        res = self._resolution
        now = self.env._now
        target = -(-(now + delay) // res) * res
        return max(0.0, target - now)

    def call_at(self, delay: float, callback: Callable[[], None]) -> None:
        """Run ``callback`` after ``delay`` simulated seconds, then drain.

        A zero delay asked for while zero-time work is being drained (a performer answering
        an offer at once) goes to the ready queue, after the work queued now, instead of
        becoming a SimPy event (saves an event per instant answer; the user model answers
        two or three offers per dose cycle that way)."""
        if delay <= 0.0 and self._draining:
            self._ready.append((_call, callback, None, None))
            return
        self._wakeups.after(max(0.0, delay), lambda _e: self._callback(callback))

    def _callback(self, callback: Callable[[], None]) -> None:
        callback()
        self._drain()

    # ------------------------------------------------------------------ instances
    def start_process(self, proc: CompiledProcess, data: Mapping[str, Any] | None = None, *,
                      parent: ActivityInstance | None = None, trigger: str | None = None
                      ) -> ProcessInstance:
        """Create and start an instance of ``proc`` (its start activities are queued)."""
        local = proc.data.copy()
        if data:
            local.update(data)
        scope: MutableMapping[str, Any] = (
            ChainMap(local, self.package_data) if self.package_data else local)
        iid = next(self._ids)
        priority = proc.priority
        root = iid
        if parent is not None:
            root = parent.frame.inst.root
            priority = max(priority, parent.frame.inst.priority)
        inst = ProcessInstance(iid, proc, local, scope, priority, parent, root, self.env._now)
        inst.state = RUNNING
        inst.trigger = trigger
        if parent is not None:
            inst.depth = parent.frame.inst.depth + 1
            inst.partner = parent.frame.inst.partner
        self.live[iid] = inst
        self.counts["started"] += 1
        if self._pflags[proc.id] & 1:
            self.emit(EK.PROCESS_STARTED, proc.id, iid, None, proc.lane, None,
                      {"trigger": trigger, "parent": parent.frame.inst.id if parent else None})
        frame = Frame(proc.graph, inst, None)
        inst.frames.append(frame)
        for index in proc.graph.starts:
            frame.live += 1
            self._ready.append((self._start_at, frame, index, None))
        if not proc.graph.starts:
            self._pending[frame] = None
        if proc.deadline is not None:
            self.call_at(proc.deadline, lambda: self._process_deadline(inst))
        return inst

    def _process_deadline(self, inst: ProcessInstance) -> None:
        if inst.state in (RUNNING, SUSPENDED):
            proc = inst.process
            if self.wants(EK.DEADLINE_EXPIRED, proc.id, None):
                self.emit(EK.DEADLINE_EXPIRED, proc.id, inst.id, None, proc.lane, None,
                          {"deadline": proc.deadline, "scope": "process"})

    def _frame_done(self, frame: Frame) -> None:
        inst = frame.inst
        owner = frame.owner
        if owner is not None:                       # an activity set finished
            if frame.queue and inst.state == RUNNING:   # a sequential ad-hoc set: the next
                frame.live += 1
                self._ready.append((self._start_at, frame, frame.queue.pop(0), None))
                return
            if frame in inst.frames:
                inst.frames.remove(frame)
            owner.child = None
            self._body_done(owner, None)
            return
        if inst.state != RUNNING:
            return
        inst.state = _NEXT[(RUNNING, "complete")]
        inst.frames.clear()          # breaks the instance <-> frame cycle: freed by refcount
        self.live.pop(inst.id, None)
        if self._kept and inst.parent is None:
            self._drop_kept(inst)
        self.counts["completed"] += 1
        proc = inst.process
        if self._pflags[proc.id] & 2:
            self.emit(EK.PROCESS_COMPLETED, proc.id, inst.id, None, proc.lane, None,
                      {"duration": self.env._now - inst.started_at})
        parent = inst.parent
        if parent is not None and parent.state == RUNNING:
            parent.child = None
            out = {}
            for mode, formal, _fn, target in parent.act.params:
                if mode is not ParameterMode.IN and target is not None:
                    out[target] = inst.data.get(formal)
            self._body_done(parent, out or None)

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
                self._stop(ai, TERMINATED, reason)
        inst.frames.clear()
        self.live.pop(inst.id, None)
        if self._kept and inst.parent is None:
            self._drop_kept(inst)
        proc = inst.process
        self.counts["terminated" if state == TERMINATED else "aborted"] += 1
        kind = EK.PROCESS_TERMINATED if state == TERMINATED else EK.PROCESS_ABORTED
        if self.wants(kind, proc.id, None):
            self.emit(kind, proc.id, inst.id, None, proc.lane, None, {"reason": reason})
        parent = inst.parent
        if notify_parent and parent is not None and parent.state == RUNNING:
            parent.child = None
            self._fail(parent, STATE_NAMES[state], f"subflow {proc.id!r}: {reason}")

    def abort(self, inst: ProcessInstance, act: CompiledActivity | None, message: str) -> None:
        """Abort ``inst`` with a located message (recorded as a fault); the run goes on."""
        where = act.where() if act is not None else (
            str(inst.process.location) if inst.process.location else "<built in Python>")
        what = f"activity {act.id!r} of " if act is not None else ""
        text = (f"{where}: {what}process {inst.process.id!r} (instance {inst.id}) aborted at "
                f"t={self.env._now:.3f} s: {message}")
        self.faults.append({"time": self.env._now, "process": inst.process.id,
                            "instance": inst.id, "activity": act.id if act else None,
                            "message": text})
        self.end_instance(inst, ABORTED, text)

    # ------------------------------------------------------------------ tokens
    def _start_at(self, frame: Frame, index: int, _unused: Any) -> None:
        inst = frame.inst
        if inst.state != RUNNING:
            self._dropped(frame, self._start_at, index, None)
            return
        self._start(frame, frame.graph.activities[index])

    def _dropped(self, frame: Frame, fn: Any, a: Any, b: Any) -> None:
        if frame.inst.state == SUSPENDED:
            frame.inst.deferred.append((fn, frame, a, b))
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
                counts = frame.joins.get(index)
                if counts is None:
                    counts = frame.joins[index] = [0] * len(act.in_slots)
                counts[act.in_slots[trans.index]] += 1
                if 0 in counts:
                    frame.parked += 1
                    self._token_gone(frame)
                    return
                for slot in range(len(counts)):
                    counts[slot] -= 1
                frame.parked -= len(counts) - 1
            elif join == J_COMPLEX:
                frame.parked += 1
                frame.live -= 1
                if self._complex_arrival(frame, act, act.in_slots[trans.index]):
                    frame.live += 1
                    self._start(frame, act)
                elif frame.live <= 0:
                    self._pending[frame] = None
                return
            else:                                   # OR join: resolved when the queue is dry
                frame.ors[index] = frame.ors.get(index, 0) + 1
                frame.parked += 1
                frame.live -= 1
                self._pending[frame] = None
                return
        self._start(frame, act)

    def _complex_arrival(self, frame: Frame, act: CompiledActivity, slot: int) -> bool:
        """A token (already counted as parked) reaches complex join ``act`` on ``slot``;
        whether the join fires now (BPMN 2.0 §13.4.4: fire when the activation condition
        holds, consuming a token of each incoming transition that has one; then ignore one
        token on each of the others before firing again)."""
        index = act.index
        if frame.cjoins is None:
            frame.cjoins = {}
            frame.owed = {}
        assert frame.owed is not None
        counts = frame.cjoins.get(index)
        if counts is None:
            counts = frame.cjoins[index] = [0] * len(act.in_slots)
        owed = frame.owed.get(index)
        if owed is not None and slot in owed:       # waiting for reset: this one is ignored
            owed.discard(slot)
            frame.parked -= 1
            if owed:
                return False
            del frame.owed[index]
            return self._complex_fires(frame, act, counts) if any(counts) else False
        counts[slot] += 1
        if owed is not None:
            return False
        return self._complex_fires(frame, act, counts)

    def _complex_fires(self, frame: Frame, act: CompiledActivity, counts: list[int]) -> bool:
        inst = frame.inst
        active = sum(1 for c in counts if c)
        condition = act.join_condition
        assert condition is not None
        try:
            holds = condition(ChainMap({"activationCount": active}, inst.scope), self.env._now)
        except OpspecError as error:
            self.abort(inst, act, f"the IncomingCondition failed: {error.message}")
            return False
        if not holds:
            return False
        owed = set()
        for slot, count in enumerate(counts):
            if count:
                counts[slot] -= 1
                frame.parked -= 1
            else:
                owed.add(slot)
        if owed and frame.owed is not None:
            frame.owed[act.index] = owed
        return True

    def _token_gone(self, frame: Frame) -> None:
        frame.live -= 1
        if frame.graph.completion is not None and self._ad_hoc_complete(frame):
            return
        if frame.live <= 0 or frame.ors:
            if frame.live <= 0 and not frame.parked:
                self._frame_done(frame)
            else:
                self._pending[frame] = None

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
            holds = condition(inst.scope, self.env._now)
        except OpspecError as error:
            self.abort(inst, owner.act, f"the AdHocCompletionCondition failed: {error.message}")
            return True
        if not holds:
            return False
        if frame.queue:
            frame.queue.clear()
        for ai in list(frame.running.values()):
            self._stop(ai, TERMINATED, "the ad-hoc set's completion condition holds")
        frame.live = 0
        frame.parked = 0
        self._frame_done(frame)
        return True

    def _resolve_frames(self) -> None:
        """OR joins that nothing can reach any more fire; a frame with only parked tokens
        left is deadlocked (an AND join that cannot fire)."""
        frames = list(self._pending)
        self._pending.clear()
        for frame in frames:
            if frame.inst.state != RUNNING:
                continue
            fired = False
            for join, count in list(frame.ors.items()):
                if self._or_ready(frame, join):
                    del frame.ors[join]
                    frame.parked -= count
                    frame.live += 1
                    fired = True
                    self._ready.append((self._start_at, frame, join, None))
            if frame.owed and frame.live <= 0 and not fired:     # (only complex joins)
                # nothing can deliver the tokens a fired complex join waits for: it resets,
                # and the tokens that came meanwhile may fire it again at once
                frame.owed.clear()
                acts = frame.graph.activities
                for join, counts in list((frame.cjoins or {}).items()):
                    if any(counts) and self._complex_fires(frame, acts[join], counts):
                        frame.live += 1
                        fired = True
                        self._ready.append((self._start_at, frame, join, None))
            if not fired and frame.live <= 0:
                if frame.parked:
                    waiting = [frame.graph.activities[i].id
                               for i, c in (list(frame.joins.items()) + list(frame.ors.items())
                                            + list((frame.cjoins or {}).items()))
                               if (c if isinstance(c, int) else any(c))]
                    self.report_deadlock(frame.inst, waiting, "a join waits for branches "
                                         "that can no longer arrive")
                else:
                    self._frame_done(frame)

    def _or_ready(self, frame: Frame, join: int) -> bool:
        upstream = frame.graph.activities[join].upstream
        for ai in frame.running.values():
            if ai.act.index in upstream:
                return False
        for other, count in frame.ors.items():
            if other != join and count and other in upstream:
                return False
        for other, counts in frame.joins.items():
            if other in upstream and any(counts):
                return False
        if frame.cjoins:
            for other, counts in frame.cjoins.items():
                if other in upstream and any(counts):
                    return False
        return True

    def _too_deep(self, ai: ActivityInstance, target: CompiledProcess) -> None:
        """Runaway recursion: abort the outermost caller (which ends every nested call)."""
        root = ai.frame.inst
        while root.parent is not None:
            root = root.parent.frame.inst
        act = ai.act
        text = (f"{act.where()}: activity {act.id!r} of process {act.process!r} calls "
                f"{target.id!r} {MAX_CALL_DEPTH + 1} synchronous subflow calls deep at "
                f"t={self.env._now:.3f} s: the recursion does not reach its base case")
        self.faults.append({"time": self.env._now, "process": act.process,
                            "instance": ai.frame.inst.id, "activity": act.id, "message": text})
        self.end_instance(root, ABORTED, text)

    def report_deadlock(self, inst: ProcessInstance, waiting: list[str], why: str) -> None:
        """Record a deadlock of ``inst`` (trace + summary) and abort it."""
        proc = inst.process
        text = (f"deadlock in process {proc.id!r} (instance {inst.id}) at "
                f"t={self.env._now:.3f} s: {why}; waiting: {', '.join(waiting) or '-'}")
        self.deadlocks.append({"time": self.env._now, "process": proc.id, "instance": inst.id,
                               "waiting": waiting, "message": text})
        if self.wants(EK.DEADLOCK, proc.id, None):
            self.emit(EK.DEADLOCK, proc.id, inst.id, None, proc.lane, None,
                      {"waiting": list(waiting), "message": text})
        self.end_instance(inst, ABORTED, text)

    # ------------------------------------------------------------------ activities
    def _start(self, frame: Frame, act: CompiledActivity | None) -> None:
        """Start ``act``. Instantaneous activities run here, in a loop that carries the
        token straight on to the next activity (no queue round trip) as long as the next
        one has no AND/OR join to synchronise at."""
        pooled = self._pooled
        apps = self._apps
        steps = 0
        limit = self._start_limit
        while act is not None:
            if not act.fast or (act.general and pooled) or (
                    act.kind == K_TASK and act.application in apps):
                self._start_slow(frame, act)
                return
            inst = frame.inst
            steps += 1
            if steps > limit:                   # a zero-time cycle (see _drain)
                self._zero_time(frame, act)
            if self._aflags[act] & 1:
                self.emit(EK.ACTIVITY_STARTED, act.process, inst.id, act.id, act.lane,
                          act.participant)
            if act.start_assign and not self._assign(inst, act, act.start_assign):
                return
            if act.kind == K_ASYNC:
                data = self._params_in(inst, act)
                if data is None:
                    return
                self.start_process(self.processes[act.subflow],  # type: ignore[index]
                                   data, trigger=f"subflow:{act.id}")
            act = self._done_next(frame, act)

    def _params_in(self, inst: ProcessInstance, act: CompiledActivity
                   ) -> dict[str, Any] | None:
        now = self.env._now
        try:
            return {formal: fn(inst.scope, now)
                    for _mode, formal, fn, _target in act.params if fn is not None}
        except OpspecError as error:
            self.abort(inst, act, f"an actual parameter failed: {error.message}")
            return None

    def _start_slow(self, frame: Frame, act: CompiledActivity) -> None:
        ai = ActivityInstance(next(self._keys), act, frame, self.env._now)
        ai.state = RUNNING
        frame.running[ai.key] = ai
        if act.plain and not (act.general and self._pooled):
            inst = frame.inst
            if self._aflags[act] & 1:
                self.emit(EK.ACTIVITY_STARTED, act.process, inst.id, act.id, act.lane,
                          act.participant)
            if act.start_assign and not self._assign(inst, act, act.start_assign):
                return
            if act.kind == K_MANUAL and not act.params:
                performer = self._performer_for(act)
                if performer is not None:
                    self._offer(ai, performer, (), None, None)
                    return
            self._body(ai)
            return
        if act.start_trigger is not None:
            ai.waiting = f"start trigger {act.start_trigger.kind}:{act.start_trigger.name}"
            self._wait_trigger(ai, act.start_trigger, self._activate_cb, None)
            return
        self._activate(ai)

    def _activate_cb(self, ai: ActivityInstance, _arg: Any, _data: Any = None) -> None:
        self._ready.append((self._activate, ai, None, None))

    def _activate(self, ai: ActivityInstance, _a: Any = None, _b: Any = None) -> None:
        if ai.state != RUNNING:
            return
        act = ai.act
        inst = ai.frame.inst
        if act.mi is not None and ai.mi is None and not self._mi_begin(ai):
            return
        self._emit_act(EK.ACTIVITY_STARTED, inst, act)
        if act.start_assign and not self._assign(inst, act, act.start_assign):
            return
        now = self.env._now
        for seconds, synchronous, exception in act.deadlines:
            try:
                delay = float(seconds(inst.scope, now))
            except OpspecError as error:
                self.abort(inst, act, f"deadline cannot be computed: {error.message}")
                return
            self._later(delay, self._deadline, ai, (synchronous, exception, delay))
        for index in act.boundary:
            event = ai.frame.graph.activities[index]
            if event.trigger is not None:
                self._wait_trigger(ai, event.trigger, self._boundary, index, persistent=True)
        if act.loop is not None and act.loop[2] and not self._loop_again(ai):
            self._complete(ai)
            return
        self._run_body(ai)

    # ------------------------------------------------------------------ multi-instance
    def _mi_begin(self, ai: ActivityInstance) -> bool:
        """Start the instances of multi-instance activity ``ai.act``; ``ai`` becomes the
        first. Each instance holds a token of the frame; the flow condition decides which
        of them move on (see :meth:`_mi_done`). Returns whether ``ai`` runs now."""
        act = ai.act
        frame = ai.frame
        inst = frame.inst
        count_fn, parallel, _flow, _cond = act.mi  # type: ignore[misc]
        try:
            raw = count_fn(inst.scope, self.env._now)
        except OpspecError as error:
            self.abort(inst, act, f"the MI_Condition failed: {error.message}")
            return False
        count = raw if isinstance(raw, int) and not isinstance(raw, bool) else (
            int(raw) if isinstance(raw, float) and raw.is_integer() else -1)
        if count < 0:
            self.abort(inst, act, f"the MI_Condition gave {raw!r}, not a number of instances "
                       "(an integer >= 0)")
            return False
        if count == 0:                      # no instance: the activity is done at once
            self._emit_act(EK.ACTIVITY_STARTED, inst, act)
            ai.state = COMPLETED
            ai.gen += 1
            frame.running.pop(ai.key, None)
            self._finish(frame, act)
            return False
        group = MultiInstance(count)
        frame.live += count - 1
        self._mi_join(ai, group)
        if parallel:
            for _ in range(count - 1):
                self._mi_next(frame, act, group)
        return True

    def _mi_join(self, ai: ActivityInstance, group: MultiInstance) -> None:
        ai.mi = group
        ai.iteration = group.started            # the instance's loopCounter
        group.started += 1
        group.members.append(ai)

    def _mi_next(self, frame: Frame, act: CompiledActivity, group: MultiInstance) -> None:
        ai = ActivityInstance(next(self._keys), act, frame, self.env._now)
        ai.state = RUNNING
        frame.running[ai.key] = ai
        self._mi_join(ai, group)
        self._ready.append((self._activate, ai, None, None))

    def _mi_done(self, ai: ActivityInstance, group: MultiInstance) -> None:
        """One instance completed: its token moves on or is consumed, per MI_FlowCondition."""
        act = ai.act
        frame = ai.frame
        inst = frame.inst
        group.completed += 1
        group.members.remove(ai)
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
                    moves = bool(cond(ChainMap(counters, inst.scope), self.env._now))
                except OpspecError as error:
                    self.abort(inst, act, f"the ComplexMI_FlowCondition failed: "
                               f"{error.message}")
                    return
        if not parallel and group.started < group.count and inst.state == RUNNING:
            self._mi_next(frame, act, group)
        if moves:
            group.passed = True
            self._finish(frame, act)
            return
        if act.end_assign and not self._assign(inst, act, act.end_assign):
            return
        self._emit_act(EK.ACTIVITY_COMPLETED, inst, act, {"instance": ai.iteration})
        self._token_gone(frame)

    def _mi_cancel(self, group: MultiInstance, frame: Frame, reason: str) -> None:
        """An interrupting event ends every instance of the group (the interrupted one
        included); their tokens, and those of instances not started yet, are consumed."""
        for member in list(group.members):
            self._stop(member, TERMINATED, reason)
        frame.live -= len(group.members) + (group.count - group.started)
        group.members.clear()
        group.started = group.count

    def _loop_again(self, ai: ActivityInstance) -> bool:
        cond, maximum, _before = ai.act.loop  # type: ignore[misc]
        if maximum is not None and ai.iteration >= maximum:
            return False
        if cond is None:
            return maximum is not None
        inst = ai.frame.inst
        return bool(cond(inst.scope, self.env._now))

    def _run_body(self, ai: ActivityInstance, _a: Any = None, _b: Any = None) -> None:
        if ai.state != RUNNING:
            return
        act = ai.act
        if act.general or act.cpu:
            if self._pool is not None:
                level = (ai.frame.inst.priority if act.priority is None
                         else act.priority) + act.priority_increment
                cost = self._switch + act.cpu if act.general else act.cpu
                ai.waiting = "worker"
                if self._pool.submit(ai, level, cost):
                    self._emit_act(EK.QUEUED, ai.frame.inst, act,
                                   {"waiting": self._pool.waiting, "priority": level})
                return
            if act.cpu > 0.0:
                self._dedicated.burst(self.env._now, act.cpu)
                ai.waiting = "cpu"
                self._later(act.cpu, self._after_cpu_cb, ai)
                return
        self._after_cpu(ai)

    def _after_cpu_cb(self, ai: ActivityInstance, _arg: Any) -> None:
        self._after_cpu(ai)

    def _after_cpu(self, ai: ActivityInstance) -> None:
        if ai.state != RUNNING:
            return
        act = ai.act
        if act.sampler is not None and act.kind != K_MANUAL:
            delay = act.sampler(self.streams.stream(f"{act.process}/{act.id}"))
            if delay > 0.0:
                ai.waiting = "duration"
                self._later(delay, self._body_cb, ai)
                return
        self._body(ai)
        if not self._draining:
            self._drain()

    def _body_cb(self, ai: ActivityInstance, _arg: Any) -> None:
        self._body(ai)

    def _body(self, ai: ActivityInstance) -> None:
        """What the activity does, by kind; ends with :meth:`_body_done` (maybe later)."""
        act = ai.act
        kind = act.kind
        inst = ai.frame.inst
        if kind == K_TASK and act.toolchain:
            self._run_tools(ai, 0)
        elif kind == K_MANUAL or (kind == K_TASK and act.application in self._apps):
            performer = (self._apps[act.application or ""] if kind == K_TASK
                         else self._performer_for(act))
            if performer is None:
                ai.waiting = (f"performer for participant {act.participant!r}"
                              f" / lanes {', '.join(act.lanes) or '-'}")
                self._emit_act(EK.ACTIVITY_OFFERED, inst, act, {"performer": None})
                return
            data: Mapping[str, Any] | None = None
            if act.params:
                data = self._inputs(ai)
                if data is None:
                    return
            duration = None
            if act.sampler is not None:
                duration = act.sampler(self.streams.stream(f"{act.process}/{act.id}"))
            self._offer(ai, performer, (), data, duration)
        elif kind == K_SUBFLOW or kind == K_ASYNC:
            data = self._inputs(ai)
            if data is None:
                return
            target = self.processes[act.subflow]  # type: ignore[index]
            if kind == K_SUBFLOW:
                if inst.depth >= MAX_CALL_DEPTH:
                    self._too_deep(ai, target)
                    return
                ai.waiting = f"subflow {target.id}"
                ai.child = self.start_process(target, data, parent=ai)
            else:
                self.start_process(target, data, trigger=f"subflow:{act.id}")
                self._body_done(ai, None)
        elif kind == K_CATCH:
            trig = act.trigger
            assert trig is not None
            ai.waiting = f"{trig.kind}:{trig.name}" if trig.name else trig.kind
            self._wait_trigger(ai, trig, self._caught, None)
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
                self._ready.append((self._start_at, frame, index, None))
            if not act.block.starts:
                self._body_done(ai, None)
        elif kind == K_COORD:
            self._coordinate(ai)
        elif kind == K_GATEWAY:
            self._offer_choice(ai, act.out)
        else:                                       # noop, throw, task without a callable
            # queued, not called: a chain of such activities must not grow the stack
            self._ready.append((self._body_done, ai, None, None))

    def _body_done(self, ai: ActivityInstance, data: Mapping[str, Any] | None,
                   _unused: Any = None) -> None:
        """One execution of the body finished: loop again or complete."""
        if ai.state != RUNNING:
            return
        if ai.frame.inst.state == SUSPENDED:
            ai.frame.inst.deferred.append((self._body_done, ai, data, None))
            return
        if data:
            inst = ai.frame.inst
            act = ai.act
            for key, value in data.items():
                self._set(inst, act, key, value)
        act = ai.act
        if act.loop is not None:
            # each iteration is one execution of the activity: its assignments apply each time
            inst = ai.frame.inst
            if act.end_assign and not self._assign(inst, act, act.end_assign):
                return
            ai.iteration += 1
            if ai.iteration > 1_000_000:
                self.abort(inst, act, "loop ran 1,000,000 times; add a maximum")
                return
            if self._loop_again(ai):
                if act.start_assign and not self._assign(inst, act, act.start_assign):
                    return
                self._ready.append((self._run_body, ai, None, None))
                return
        self._complete(ai)

    def _complete(self, ai: ActivityInstance) -> None:
        ai.state = COMPLETED
        ai.gen += 1
        frame = ai.frame
        del frame.running[ai.key]
        if ai.cleanup:
            for undo in ai.cleanup:
                undo()
            ai.cleanup.clear()
        if ai.mi is not None:
            self._mi_done(ai, ai.mi)
            return
        self._finish(frame, ai.act)

    def _finish(self, frame: Frame, act: CompiledActivity) -> None:
        """Completion of ``act``, then on to what follows it."""
        nxt = self._done_next(frame, act)
        if nxt is not None:
            self._start(frame, nxt)

    def _done_next(self, frame: Frame, act: CompiledActivity) -> CompiledActivity | None:
        """Complete ``act`` (end assignments, throw/raise, trace) and take its split.

        Returns the activity the token moves on to when it can be started right away (an
        XOR split or a single transition into an activity without AND/OR join); otherwise
        the token has been queued, parked or has ended, and ``None`` is returned.
        """
        inst = frame.inst
        if act.simple_end:
            if self._aflags[act] & 2:
                self.emit(EK.ACTIVITY_COMPLETED, act.process, inst.id, act.id, act.lane,
                          act.participant)
            nxt = act.next
            if nxt >= 0:
                target = frame.graph.activities[nxt]
                if not target.join:
                    return target
            return self._split(frame, act, inst)
        if act.end_assign and act.loop is None and not self._assign(inst, act, act.end_assign):
            return None
        if act.kind == K_THROW and act.trigger is not None:
            self.broadcast(act.trigger.kind, act.trigger.name or "", None, inst, act)
        if self._aflags[act] & 2:
            self.emit(EK.ACTIVITY_COMPLETED, act.process, inst.id, act.id, act.lane,
                      act.participant)
        if act.raises is not None and inst.state == RUNNING:
            self.broadcast(act.raises.kind, act.raises.name or "", None, inst, act)
        if act.terminate:
            self.end_instance(inst, TERMINATED, f"end event {act.id!r}", notify_parent=False)
            parent = inst.parent
            if parent is not None and parent.state == RUNNING:
                parent.child = None
                self._body_done(parent, None)
            return None
        if inst.state != RUNNING:
            return None
        return self._split(frame, act, inst)

    def _split(self, frame: Frame, act: CompiledActivity, inst: ProcessInstance
               ) -> CompiledActivity | None:
        """The split of a completed activity (see :meth:`_done_next`)."""
        acts = frame.graph.activities
        nxt = act.next
        if nxt >= 0:
            target = acts[nxt]
            if not target.join:
                return target
            trans = act.out[0]
        elif act.split == S_XOR and not act.choice and (act.out or act.otherwise):
            scope = inst.scope
            now = self.env._now
            try:
                for trans in act.out:
                    cond = trans.condition
                    if cond is None or cond(scope, now):
                        break
                else:
                    if not act.otherwise and act.path_may_end:
                        self._token_gone(frame)     # no condition holds: this path ends
                        return None
                    if not act.otherwise:
                        self.abort(inst, act, "no outgoing transition can be taken (no "
                                   "condition holds and there is no OTHERWISE transition)")
                        return None
                    trans = act.otherwise[0]
            except OpspecError as error:
                self.abort(inst, act, f"a transition condition failed: {error.message}")
                return None
            target = acts[trans.target]
            if not target.join:
                if trans.assignments:
                    for target_name, fn in trans.assignments:
                        self._set(inst, None, target_name, fn(scope, now))
                return target
        else:
            self._leave(frame, act)
            return None
        self._take(frame, trans)
        self._token_gone(frame)
        return None

    def _leave(self, frame: Frame, act: CompiledActivity) -> None:
        if act.choice:
            ai = ActivityInstance(next(self._keys), act, frame, self.env._now)
            ai.state = RUNNING
            frame.running[ai.key] = ai
            self._offer_choice(ai, act.choice)
            return
        outs = act.out
        if outs or act.otherwise:
            inst = frame.inst
            scope = inst.scope
            now = self.env._now
            taken = False
            try:
                if act.split == S_XOR:
                    for trans in outs:
                        cond = trans.condition
                        if cond is None or cond(scope, now):
                            self._take(frame, trans)
                            taken = True
                            break
                else:
                    for trans in outs:
                        cond = trans.condition
                        if cond is None or cond(scope, now):
                            self._take(frame, trans)
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
                self._take(frame, act.otherwise[0])
        self._token_gone(frame)

    def _take(self, frame: Frame, trans: CTransition, performed: bool = False) -> None:
        if trans.assignments:
            inst = frame.inst
            now = self.env._now
            for target, fn in trans.assignments:
                self._set(inst, None, target, fn(inst.scope, now))
        frame.live += 1
        self._ready.append((self._performed if performed else self._arrive, frame,
                            trans.target, trans))

    def _performed(self, frame: Frame, index: int, trans: CTransition | None) -> None:
        """A branch of a deferred choice: the performer's choice (or the caught event) *is*
        the chosen activity, which completes at once."""
        inst = frame.inst
        if inst.state != RUNNING:
            self._dropped(frame, self._performed, index, trans)
            return
        act = frame.graph.activities[index]
        self._emit_act(EK.ACTIVITY_STARTED, inst, act)
        if act.start_assign and not self._assign(inst, act, act.start_assign):
            return
        self._finish(frame, act)

    # ------------------------------------------------------------------ data
    def _set(self, inst: ProcessInstance, act: CompiledActivity | None, target: str,
             value: Any) -> None:
        if target in inst.data or target not in self.package_data:
            inst.data[target] = value
        else:
            self.package_data[target] = value
        if (self._aflags[act] & 8 if act is not None
                else self._all or (EK.DATA_CHANGED, inst.process.id, None) in self._want):
            self.emit(EK.DATA_CHANGED, inst.process.id, inst.id,
                      act.id if act is not None else None, inst.process.lane, None,
                      {target: value})
        if self._rules:
            self._check_rules()

    def _assign(self, inst: ProcessInstance, act: CompiledActivity,
                assignments: tuple[tuple[str, Any], ...]) -> bool:
        """Run ``assignments``; ``False`` when the instance ended meanwhile (a failed
        assignment aborts it; a data change can fire its end trigger): the caller stops."""
        now = self.env._now
        try:
            for target, fn in assignments:
                self._set(inst, act, target, fn(inst.scope, now))
                if inst.state != RUNNING:
                    return False
        except OpspecError as error:
            self.abort(inst, act, f"an assignment failed: {error.message}")
            return False
        return True

    def _inputs(self, ai: ActivityInstance) -> dict[str, Any] | None:
        inst = ai.frame.inst
        now = self.env._now
        out: dict[str, Any] = {}
        try:
            for _mode, formal, fn, _target in ai.act.params:
                if fn is not None:                  # OUT parameters carry nothing in
                    out[formal] = fn(inst.scope, now)
        except OpspecError as error:
            self._fail(ai, "parameter", f"an actual parameter failed: {error.message}")
            return None
        return out

    # ------------------------------------------------------------------ tools
    def _run_tools(self, ai: ActivityInstance, index: int) -> None:
        """Run the task's tools from ``index`` on, in order (XPDL: every ``Tool`` of the
        activity). A tool whose application is bound to a performer is offered to it as a
        work item, and the next tool runs when that completes; a script tool runs its
        statements; any other tool completes at once. The body is done after the last."""
        act = ai.act
        tools = act.tools
        while index < len(tools):
            tool = tools[index]
            performer = self._apps.get(tool.application)
            if performer is not None:
                data = self._tool_inputs(ai, tool.params)
                if data is None:
                    return
                key = ai.key
                if key not in self._tool_at:
                    table = self._tool_at
                    ai.cleanup.append(lambda: _discard(table, key))  # noqa: B023 - returns below
                self._tool_at[key] = index
                self._offer(ai, performer, (), data, None, tool.application)
                return
            if tool.script is not None and not self._run_script(ai, tool.application,
                                                                tool.params, tool.script):
                return
            index += 1
        self._ready.append((self._body_done, ai, None, None))

    def _tool_done(self, ai: ActivityInstance, data: Mapping[str, Any] | None,
                   _unused: Any = None) -> None:
        """The performer of one tool completed: its outputs, then the next tool."""
        if ai.state != RUNNING:
            return
        inst = ai.frame.inst
        if inst.state == SUSPENDED:
            inst.deferred.append((self._tool_done, ai, data, None))
            return
        index = self._tool_at.pop(ai.key, 0)
        if data:
            for key, value in self._outputs(ai, data, ai.act.tools[index].params).items():
                self._set(inst, ai.act, key, value)
        self._run_tools(ai, index + 1)

    def _tool_inputs(self, ai: ActivityInstance,
                     params: tuple[tuple[ParameterMode, str, Any, str | None], ...]
                     ) -> dict[str, Any] | None:
        inst = ai.frame.inst
        now = self.env._now
        out: dict[str, Any] = {}
        try:
            for _mode, formal, fn, _target in params:
                if fn is not None:
                    out[formal] = fn(inst.scope, now)
        except OpspecError as error:
            self._fail(ai, "parameter", f"an actual parameter failed: {error.message}")
            return None
        return out

    def _run_script(self, ai: ActivityInstance, application: str,
                    params: tuple[tuple[ParameterMode, str, Any, str | None], ...],
                    script: tuple[tuple[str, Any], ...]) -> bool:
        """A script tool agent's application, run as a built-in: IN/INOUT formals take the
        actual parameters' values (OUT formals start unset), the statements run in order,
        OUT/INOUT formals are written back to the actual parameters' data fields."""
        inst = ai.frame.inst
        now = self.env._now
        local: dict[str, Any] = {}
        try:
            for _mode, formal, fn, _target in params:
                local[formal] = fn(inst.scope, now) if fn is not None else None
            for variable, fn in script:
                local[variable] = fn(local, now)
        except OpspecError as error:
            self._fail(ai, "script", f"the script of application {application!r} failed: "
                       f"{error.message}")
            return False
        for mode, formal, _fn, target in params:
            if mode is not ParameterMode.IN and target is not None:
                self._set(inst, ai.act, target, local.get(formal))
        return True

    # ------------------------------------------------------------------ waits and triggers
    def _wait_trigger(self, ai: ActivityInstance, trig: CTrigger, handler: Any, arg: Any,
                      persistent: bool = False) -> None:
        """Arrange ``handler(ai, arg, data)`` when ``trig`` happens while ``ai`` waits."""
        kind = trig.kind
        if kind in ("message", "signal"):
            key = (kind, trig.name or "")
            if kind == "message" and not persistent and self._kept:
                kept = self._take_kept(ai.frame.inst, key)
                if kept is not None:                # it came before we waited: caught now
                    handler(ai, arg, kept[0])
                    return
            table = self._waiters.get(key)
            if table is None:
                table = self._waiters[key] = {}
            token = next(self._keys)
            table[token] = (ai, handler, (arg, persistent, key, token))
            ai.cleanup.append(lambda: _discard(table, token))
        elif kind in ("timer", "period"):
            inst = ai.frame.inst
            if trig.seconds is not None:
                delay = float(trig.seconds(inst.scope, self.env._now))
            else:
                delay = trig.offset or (trig.every or 0.0)
            self._later(delay, lambda a, _x: handler(a, arg, None), ai)
        elif kind == "rule":
            assert trig.condition is not None
            inst = ai.frame.inst
            if trig.condition(inst.scope, self.env._now):
                handler(ai, arg, None)
                return
            rkey = next(self._rule_keys)
            condition = trig.condition
            self._rules[rkey] = (lambda: condition(inst.scope, self.env._now),
                                 lambda: handler(ai, arg, None), ai)
            ai.cleanup.append(lambda: _discard(self._rules, rkey))

    def _check_rules(self) -> None:
        for rkey, (cond, fire, ai) in list(self._rules.items()):
            if ai is not None and ai.state != RUNNING:
                self._rules.pop(rkey, None)
                continue
            try:
                holds = cond()
            except OpspecError:
                continue
            if holds and rkey in self._rules:
                if ai is not None:
                    self._rules.pop(rkey, None)
                fire()

    def _caught(self, ai: ActivityInstance, _arg: Any, data: Mapping[str, Any] | None) -> None:
        self._ready.append((self._body_done, ai, self._known(ai, data), None))

    def _known(self, ai: ActivityInstance, data: Mapping[str, Any] | None
               ) -> Mapping[str, Any] | None:
        if not data:
            return None
        fields = ai.frame.inst.data
        return {k: v for k, v in data.items() if k in fields} or None

    def broadcast(self, kind: str, name: str, data: Mapping[str, Any] | None,
                  inst: ProcessInstance | None = None, act: CompiledActivity | None = None
                  ) -> None:
        """Raise a signal or send a message (see :meth:`_send`).

        A *signal* reaches everything waiting for it now and is not kept: catch events,
        event-gateway branches, boundary events, start and end triggers.
        """
        self.raised_names.add(name)
        proc = inst.process.id if inst is not None else None
        aid = act.id if act is not None else None
        if (self._aflags[act] & 16 if act is not None
                else self._all or (EK.TRIGGER_RAISED, proc, aid) in self._want):
            self.emit(EK.TRIGGER_RAISED, proc, inst.id if inst else None, aid,
                      act.lane if act else None, act.participant if act else None,
                      {"trigger": kind, "name": name, **(dict(data) if data else {})})
        key = (kind, name)
        if kind == "message":
            self._send(key, data, inst, act)
            return
        table = self._waiters.get(key)
        if table:
            waiting = list(table.values())
            for ai, handler, (arg, persistent, _k, token) in waiting:
                if not persistent:
                    table.pop(token, None)
                if ai.state == RUNNING:
                    handler(ai, arg, data)
        for target in self._starts.get(key, ()):
            if self.is_active(target.id):
                self.start_process(target, self._fields(target, data), trigger=f"{kind}:{name}")
        for target in self._ends.get(key, ()):
            self.terminate_all(target.id, f"end trigger {kind}:{name}")

    # ------------------------------------------------------------------ messages
    def _send(self, key: tuple[str, str], data: Mapping[str, Any] | None,
              inst: ProcessInstance | None, act: CompiledActivity | None) -> None:
        """A message goes to exactly one receiver (BPMN 2.0 §9.3, message flow):

        * a *reply* — thrown by an instance that a message started, named like a message
          the starting workflow catches — goes to that starting instance only: to the
          activity of it that waits for it, else it is kept until one does, and it is lost
          (``trigger.lost``) if that instance has ended;
        * any other message goes to the activity that has waited longest for it, else it
          starts the workflows whose start trigger it is, else ends those whose end
          trigger it is, else it is kept (``trigger.kept``, at most :data:`MESSAGE_BUFFER`
          per name, the oldest lost first) for the next activity that waits for it.
        """
        table = self._waiters.get(key)
        partner = inst.partner if inst is not None else None
        if partner is not None and partner.process.id in self.compiled.catchers.get(key, ()):
            if table:
                for token, entry in list(table.items()):
                    ai = entry[0]
                    if ai.state == RUNNING and ai.frame.inst.root == partner.id:
                        self._hand(table, token, entry, data)
                        return
            if partner.state in (RUNNING, SUSPENDED):
                self._keep(key, data, inst, act, partner)
            else:
                self._lose(key, inst, act, f"the instance it answers ({partner.process.id} "
                           f"#{partner.id}) has ended")
            return
        if table:
            for token, entry in list(table.items()):
                if entry[0].state == RUNNING:
                    self._hand(table, token, entry, data)
                    return
        kind, name = key
        started = False
        for target in self._starts.get(key, ()):
            if self.is_active(target.id):
                child = self.start_process(target, self._fields(target, data),
                                           trigger=f"{kind}:{name}")
                child.partner = _root(inst) if inst is not None else None
                started = True
        if started:
            return
        ended = False
        for target in self._ends.get(key, ()):
            if any(i.process.id == target.id for i in self.live.values()):
                self.terminate_all(target.id, f"end trigger {kind}:{name}")
                ended = True
        if not ended:
            self._keep(key, data, inst, act, None)

    def _hand(self, table: dict[int, tuple[ActivityInstance, Any, Any]], token: int,
              entry: tuple[ActivityInstance, Any, Any], data: Mapping[str, Any] | None
              ) -> None:
        ai, handler, (arg, persistent, _key, _token) = entry
        if not persistent:
            table.pop(token, None)
        handler(ai, arg, data)

    def _keep(self, key: tuple[str, str], data: Mapping[str, Any] | None,
              inst: ProcessInstance | None, act: CompiledActivity | None,
              partner: ProcessInstance | None) -> None:
        box_key = (partner.id if partner is not None else 0, key)
        box = self._kept.get(box_key)
        if box is None:
            box = self._kept[box_key] = deque()
        if len(box) >= MESSAGE_BUFFER:
            box.popleft()
            self._lose(key, inst, act, f"more than {MESSAGE_BUFFER} {key[1]!r} messages were "
                       "kept with nobody waiting; the oldest is dropped")
        box.append((data, self.env._now))
        self._trigger_event(EK.TRIGGER_KEPT, key, inst, act, {
            "for": None if partner is None else partner.id, "kept": len(box)})

    def _take_kept(self, waiter: ProcessInstance, key: tuple[str, str]
                   ) -> tuple[Mapping[str, Any] | None, float] | None:
        """The oldest message kept for ``waiter``'s root instance, else for anyone; messages
        kept longer than the configured ``message_ttl`` are lost on the way (a button pressed
        hours before anyone asked is not an answer to the next question)."""
        now = self.env._now
        ttl = self.config.message_ttl
        for box_key in ((waiter.root, key), (0, key)):
            box = self._kept.get(box_key)
            while box:
                message = box.popleft()
                if not box:
                    del self._kept[box_key]
                if now - message[1] <= ttl:
                    return message
                self._lose(key, None, None, f"kept {now - message[1]:g} s with nobody "
                           f"catching it (message_ttl {ttl:g} s)")
        return None

    def _lose(self, key: tuple[str, str], inst: ProcessInstance | None,
              act: CompiledActivity | None, why: str) -> None:
        self.lost_messages += 1
        self._trigger_event(EK.TRIGGER_LOST, key, inst, act, {"reason": why})

    def _drop_kept(self, root: ProcessInstance) -> None:
        """``root`` ended: the replies kept for it can never be caught."""
        for box_key in [k for k in self._kept if k[0] == root.id]:
            for _message in self._kept.pop(box_key):
                self._lose(box_key[1], None, None, f"the instance it answers "
                           f"({root.process.id} #{root.id}) ended before catching it")

    def _trigger_event(self, kind: str, key: tuple[str, str], inst: ProcessInstance | None,
                       act: CompiledActivity | None, extra: dict[str, Any]) -> None:
        proc = inst.process.id if inst is not None else None
        aid = act.id if act is not None else None
        if self.wants(kind, proc, aid):
            self.emit(kind, proc, inst.id if inst is not None else None, aid,
                      act.lane if act else None, act.participant if act else None,
                      {"trigger": key[0], "name": key[1], **extra})

    def _fields(self, proc: CompiledProcess, data: Mapping[str, Any] | None
                ) -> dict[str, Any] | None:
        if not data:
            return None
        return {k: v for k, v in data.items() if k in proc.data} or None

    def terminate_all(self, process_id: str, reason: str) -> None:
        for inst in [i for i in self.live.values() if i.process.id == process_id]:
            self.end_instance(inst, TERMINATED, reason)

    def is_active(self, process_id: str) -> bool:
        """Whether ``process_id`` belongs to no mode or to the current mode."""
        modes = self.compiled.modes
        if not modes:
            return True
        member = [m for m, procs in modes.items() if process_id in procs]
        return not member or self.mode in member

    def _boundary(self, ai: ActivityInstance, index: int, data: Mapping[str, Any] | None) -> None:
        event = ai.frame.graph.activities[index]
        frame = ai.frame
        if event.interrupting:
            # the interrupted activity's token moves on to the boundary path (below)
            group = ai.mi
            self._stop(ai, TERMINATED, f"boundary event {event.id!r}")
            if group is not None:
                group.members.remove(ai)
                self._mi_cancel(group, frame, f"boundary event {event.id!r}")
        else:
            frame.live += 1                         # a new token beside the activity
        self._ready.append((self._performed, frame, index, None))

    def _deadline(self, ai: ActivityInstance, arg: tuple[bool, str, float]) -> None:
        synchronous, exception, delay = arg
        act = ai.act
        frame = ai.frame
        inst = frame.inst
        self._emit_act(EK.DEADLINE_EXPIRED, inst, act,
                       {"exception": exception, "synchronous": synchronous, "deadline": delay})
        if synchronous:
            self._stop(ai, TERMINATED, f"deadline {exception!r}")
            self._exception_flow(frame, act, exception,
                                 f"deadline of {delay:g} s expired ({exception!r})", False)
        else:
            self._exception_flow(frame, act, exception, "", True)

    # ------------------------------------------------------------------ failures
    def _fail(self, ai: ActivityInstance, exception: str, message: str) -> None:
        act = ai.act
        frame = ai.frame
        self._stop(ai, ABORTED, exception)
        self._emit_act(EK.ACTIVITY_FAILED, frame.inst, act,
                       {"exception": exception, "message": message})
        self._exception_flow(frame, act, exception, message, False)

    def _exception_flow(self, frame: Frame, act: CompiledActivity, exception: str,
                        message: str, beside: bool) -> None:
        """Follow the EXCEPTION (or DEFAULTEXCEPTION) transition for ``exception``; without
        one, abort the instance (unless the exception path was to start ``beside``)."""
        trans = next((t for t in act.exceptions if t.exception in (None, exception)),
                     act.default_exception)
        inst = frame.inst
        if trans is None:
            if not beside:
                self.abort(inst, act, message or f"exception {exception!r}")
            return
        self._emit_act(EK.EXCEPTION_RAISED, inst, act,
                       {"exception": exception, "transition": trans.id, "message": message})
        self._take(frame, trans)
        if not beside:
            self._token_gone(frame)

    def _stop(self, ai: ActivityInstance, state: int, reason: str) -> None:
        """Cancel ``ai``: it stops waiting, its offer is withdrawn, its children end."""
        if ai.state != RUNNING and ai.state != SUSPENDED:
            return
        ai.state = state
        ai.gen += 1
        frame = ai.frame
        frame.running.pop(ai.key, None)
        for undo in ai.cleanup:
            undo()
        ai.cleanup.clear()
        item = ai.item
        if item is not None:
            ai.item = None
            self._offers.pop(item.key, None)
            self._emit_act(EK.ACTIVITY_WITHDRAWN, frame.inst, ai.act, {"reason": reason})
            performer = ai.performer
            if performer is not None:
                performer.withdraw(item, reason)
        child = ai.child
        ai.child = None
        if isinstance(child, ProcessInstance):
            child.parent = None
            self.end_instance(child, TERMINATED, f"caller stopped: {reason}")
        elif isinstance(child, Frame):
            for sub in list(child.running.values()):
                self._stop(sub, TERMINATED, reason)
            if child in frame.inst.frames:
                frame.inst.frames.remove(child)
        for queue in self._pullers.values():
            if ai in queue:
                queue.remove(ai)

    # ------------------------------------------------------------------ performers
    def _performer_for(self, act: CompiledActivity) -> Performer | None:
        if act in self._perf_cache:
            return self._perf_cache[act]
        else:
            performer = self.registry.lookup(act.participant, act.lanes)
            if performer is None and not act.user_lane:
                performer = self.registry.default_device
            self._perf_cache[act] = performer
            return performer

    def _offer(self, ai: ActivityInstance, performer: Performer, choices: tuple[str, ...],
               data: Mapping[str, Any] | None, duration: float | None,
               application: str | None = None) -> None:
        act = ai.act
        inst = ai.frame.inst
        item = WorkItem(ai.key, act.process, inst.id, act.id, act.label, act.participant,
                        act.lane, self.env._now,
                        application if application is not None else act.application,
                        data if data is not None else MappingProxyType(inst.data), choices,
                        inst.root, duration)
        ai.item = item
        ai.performer = performer
        ai.waiting = "performer"
        self._offers[ai.key] = ai
        if self._aflags[act] & 4:
            self.emit(EK.ACTIVITY_OFFERED, act.process, inst.id, act.id, act.lane,
                      act.participant, {"choices": list(choices)} if choices else None)
        performer.offer(item)

    def _offer_choice(self, ai: ActivityInstance, branches: tuple[CTransition, ...]) -> None:
        """A deferred choice: manual branches are offered as one work item with ``choices``;
        catch-event branches race it; the first to happen wins."""
        acts = ai.frame.graph.activities
        ai.choice = branches
        ai.waiting = "choice"
        manual = [t for t in branches if acts[t.target].kind == K_MANUAL]
        for trans in branches:
            target = acts[trans.target]
            if target.kind == K_CATCH and target.trigger is not None:
                self._wait_trigger(ai, target.trigger, self._choice_event, trans)
        if ai.act.labelled:
            self._labelled_choice(ai, branches)
        elif manual:
            performer = self._performer_for(acts[manual[0].target])
            if performer is None:
                ai.waiting = f"performer for the choice {[acts[t.target].id for t in manual]}"
                return
            self._offer(ai, performer, tuple(acts[t.target].id for t in manual), None, None)

    def _labelled_choice(self, ai: ActivityInstance, branches: tuple[CTransition, ...]) -> None:
        """A split between labelled branches: the performer bound to the deciding activity
        (a person, a script, a user model) picks one; with nobody bound, the branch is drawn
        uniformly from the activity's random stream (reproducible for a seed)."""
        act = ai.act
        acts = ai.frame.graph.activities
        performer = self.registry.lookup(act.participant, act.lanes)
        if performer is not None:
            self._offer(ai, performer, tuple(acts[t.target].id for t in branches), None, None)
            return
        rng = self.streams.stream(f"{act.process}/{act.id}")
        self._ready.append((self._choose, ai, branches[int(rng.integers(len(branches)))],
                            None))

    def _choice_event(self, ai: ActivityInstance, trans: CTransition,
                      data: Mapping[str, Any] | None) -> None:
        self._ready.append((self._choose, ai, trans, data))

    def _choose(self, ai: ActivityInstance, trans: CTransition,
                data: Mapping[str, Any] | None) -> None:
        if ai.state != RUNNING:
            return
        if data:
            self._body_done_data(ai, data)
        item = ai.item
        if item is not None:
            ai.item = None
            self._offers.pop(item.key, None)
            if ai.performer is not None:
                ai.performer.withdraw(item, "another branch of the choice happened")
        ai.state = COMPLETED
        ai.gen += 1
        frame = ai.frame
        frame.running.pop(ai.key, None)
        for undo in ai.cleanup:
            undo()
        ai.cleanup.clear()
        act = ai.act
        if act.kind == K_GATEWAY and not act.choice:
            # the gateway itself completes now (its own split is the choice)
            inst = frame.inst
            if act.end_assign and not self._assign(inst, act, act.end_assign):
                return
            self._emit_act(EK.ACTIVITY_COMPLETED, inst, act, {"choice": frame.graph.activities[
                trans.target].id})
        # a chosen manual branch *is* performed by the choice; a labelled one then runs
        self._take(frame, trans, performed=not act.labelled)
        self._token_gone(frame)

    def _body_done_data(self, ai: ActivityInstance, data: Mapping[str, Any]) -> None:
        inst = ai.frame.inst
        for key, value in data.items():
            self._set(inst, ai.act, key, value)

    def performer_complete(self, item: WorkItem, data: Mapping[str, Any] | None,
                           choice: str | None) -> None:
        ai = self._offers.pop(item.key, None)
        if ai is None or ai.state != RUNNING:
            self.stale_completions += 1
            return
        ai.item = None
        if ai.choice:
            acts = ai.frame.graph.activities
            trans = next((t for t in ai.choice if acts[t.target].id == choice), None)
            if trans is None:
                if choice is None and len(item.choices) == 1:
                    trans = next(t for t in ai.choice if acts[t.target].id == item.choices[0])
                else:
                    self._offers[item.key] = ai
                    ai.item = item
                    raise ExecutionError(
                        f"work item {item.key} ({item.activity}) needs a choice among "
                        f"{', '.join(item.choices)}, got {choice!r}",
                        hint="call complete(item, choice=ACTIVITY_ID)", sim_time=self.env._now)
            self._ready.append((self._choose, ai, trans, data))
        elif ai.act.toolchain and ai.key in self._tool_at:
            self._ready.append((self._tool_done, ai, data, None))
        elif data:
            if ai.act.params:
                data = self._outputs(ai, data)
            self._ready.append((self._body_done, ai, data, None))
        else:
            self._ready.append((self._body_done, ai, None, None))
        if not self._draining:
            self._drain()

    def _outputs(self, ai: ActivityInstance, data: Mapping[str, Any],
                 params: tuple[tuple[ParameterMode, str, Any, str | None], ...] | None = None
                 ) -> dict[str, Any]:
        """Map a performer's results (by formal parameter id) onto the actual data fields;
        keys that are not formal parameters are taken as data field names."""
        out: dict[str, Any] = {}
        if params is None:
            params = ai.act.params
        formal_to_target = {f: t for mode, f, _fn, t in params
                            if mode is not ParameterMode.IN and t is not None}
        inputs_only = {f for mode, f, _fn, _t in params if mode is ParameterMode.IN}
        for key, value in data.items():
            if key in formal_to_target:
                out[formal_to_target[key]] = value
            elif key not in inputs_only:
                out[key] = value
        return out

    def performer_omit(self, item: WorkItem, reason: str) -> None:
        ai = self._offers.pop(item.key, None)
        if ai is None or ai.state != RUNNING:
            self.stale_completions += 1
            return
        ai.item = None
        frame = ai.frame
        self._stop(ai, TERMINATED, reason or "omitted")
        self._emit_act(EK.ACTIVITY_OMITTED, frame.inst, ai.act, {"reason": reason})
        self._token_gone(frame)
        self._drain()

    def performer_fail(self, item: WorkItem, exception: str, message: str) -> None:
        ai = self._offers.pop(item.key, None)
        if ai is None or ai.state != RUNNING:
            self.stale_completions += 1
            return
        ai.item = None
        self._fail(ai, exception, message)
        self._drain()

    # ------------------------------------------------------------------ coordination
    def _coordinate(self, ai: ActivityInstance) -> None:
        act = ai.act
        spec = act.coordination
        assert spec is not None
        inst = ai.frame.inst
        scope = inst.scope
        try:
            values = [scope[name] for name in spec.inputs]
        except KeyError as error:
            self._fail(ai, "coordination", f"data field {error.args[0]!r} does not exist")
            return
        kind = spec.kind
        try:
            if kind is CoordinationKind.ARBITER:
                result: Any = coord.arbiter(values)
            elif kind is CoordinationKind.VOTER:
                result = coord.voter(values, spec.options)
            elif kind is CoordinationKind.SUPERPOSITION:
                result = coord.superposition(values, spec.weights)
            elif kind is CoordinationKind.PUSH_DATA:
                self.push_data(spec.channel or act.id, values[0] if len(values) == 1
                               else tuple(values))
                self._body_done(ai, None)
                return
            elif kind is CoordinationKind.PULL_DATA:
                channel = spec.channel or act.id
                box = self._mailboxes.get(channel)
                if box:
                    self._body_done(ai, {spec.output: box.popleft()} if spec.output else None)
                else:
                    ai.waiting = f"pull from mailbox {channel!r}"
                    self._pullers.setdefault(channel, deque()).append(ai)
                return
            else:
                # at once: if the new mode ends this very instance, nothing after the mode
                # change may run (its completion included)
                self._mode_change(spec.target_mode, act, inst)
                self._body_done(ai, None)
                return
        except (TypeError, ValueError) as error:
            self._fail(ai, "coordination", f"{kind.value} failed: {error}")
            return
        self._body_done(ai, {spec.output: result} if spec.output else None)

    def push_data(self, channel: str, value: Any) -> None:
        """Put ``value`` into supervisor mailbox ``channel``; a waiting pull gets it."""
        pullers = self._pullers.get(channel)
        while pullers:
            ai = pullers.popleft()
            if ai.state == RUNNING:
                output = ai.act.coordination.output if ai.act.coordination else None
                self._ready.append((self._body_done, ai,
                                    {output: value} if output else None, None))
                return
        self._mailboxes.setdefault(channel, deque()).append(value)

    def _mode_change(self, mode: str | None, act: CompiledActivity | None,
                     inst: ProcessInstance | None) -> None:
        self.change_mode(mode or "", act, inst)

    def change_mode(self, mode: str, act: CompiledActivity | None = None,
                    inst: ProcessInstance | None = None) -> None:
        """Switch the active workflow set: instances of workflows outside the new mode are
        terminated, their triggers ignored; workflows of the new mode are armed (loaded
        through ``mode_loader`` first when the mode names a source)."""
        source = self.compiled.mode_sources.get(mode)
        if source is not None and self.mode_loader is not None:
            loaded = self.mode_loader(source)
            if not isinstance(loaded, CompiledPackage):      # a Package: compile it here
                from opspec.engine.compiled import compile_package

                loaded = compile_package(loaded)
            new = {pid: p for pid, p in loaded.processes.items() if pid not in self.processes}
            if new:
                self.processes = {**self.processes, **new}
                # the loaded workflows belong to the mode that loaded them (on a copy: the
                # compiled package may be shared with other runs)
                self.compiled = dataclasses.replace(self.compiled, modes={
                    **self.compiled.modes,
                    mode: self.compiled.modes.get(mode, frozenset()) | frozenset(new)})
                self._select_loaded(new.values())
                for proc in new.values():
                    self.arm_process(proc)
        old = self.mode
        self.mode = mode
        for live in list(self.live.values()):
            if not self.is_active(live.process.id):
                self.end_instance(live, TERMINATED, f"mode change {old!r} -> {mode!r}")
        if self.wants(EK.MODE_CHANGED, act.process if act else None, act.id if act else None):
            self.emit(EK.MODE_CHANGED, act.process if act else None, inst.id if inst else None,
                      act.id if act else None, act.lane if act else None, None,
                      {"from": old, "to": mode})
        for proc in self.processes.values():
            members = [m for m, procs in self.compiled.modes.items() if proc.id in procs]
            if mode in members and proc.auto_start:
                self.start_process(proc, trigger=f"mode:{mode}")

    def _select_loaded(self, procs: Iterable[CompiledProcess]) -> None:
        """Extend the listeners' expanded selectors over workflows loaded at run time (the
        boot expansion only saw the boot package), so metrics, --timing and traces see their
        events. Runs once per loaded source, never on the per-event path."""
        from opspec.engine.compiled import expand_selectors_over

        procs = tuple(procs)
        if not self._all and self._selectors:
            self._want = self._want | expand_selectors_over(
                procs, self._selectors, package_level=False)
        self._full = [(lst, None if selects is None else selects | expand_selectors_over(
            procs, frozenset(lst.selects), package_level=False))  # type: ignore[attr-defined]
            for lst, selects in self._full]
        self._aflags.clear()                 # cached "nobody wants this" bits may be stale
        self._pflags.clear()

    def arm_process(self, proc: CompiledProcess) -> None:   # pragma: no cover - overridden
        raise NotImplementedError


_ACT_KINDS = (EK.ACTIVITY_STARTED, EK.ACTIVITY_COMPLETED, EK.ACTIVITY_OFFERED,
              EK.DATA_CHANGED, EK.TRIGGER_RAISED)
_PROC_KINDS = (EK.PROCESS_STARTED, EK.PROCESS_COMPLETED)


class _Flags(dict[Any, int]):
    """Which of ``kinds`` some listener wants, as bits, per activity or process id;
    computed on first use (a hit is a plain dict lookup: cheaper than building a key)."""

    def __init__(self, interp: Interpreter, kinds: tuple[str, ...]) -> None:
        super().__init__()
        self._interp = interp
        self._kinds = kinds

    def __missing__(self, key: Any) -> int:
        interp = self._interp
        if isinstance(key, str):
            process, activity = key, None
        else:
            process, activity = key.process, key.id
        bits = 0
        for n, kind in enumerate(self._kinds):
            if interp.wants(kind, process, activity):
                bits |= 1 << n
        self[key] = bits
        return bits


def _call(callback: Callable[[], None], _a: Any, _b: Any) -> None:
    callback()


def _root(inst: ProcessInstance) -> ProcessInstance:
    while inst.parent is not None:
        inst = inst.parent.frame.inst
    return inst


def _discard(table: dict[Any, Any], key: Any) -> None:
    table.pop(key, None)


def _alive(ai: ActivityInstance) -> bool:
    return ai.state == RUNNING
