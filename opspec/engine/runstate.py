"""The state of one run: what the interpreter's parts share.

Everything a run holds lives in one :class:`RunState` (the :class:`~opspec.engine.interpreter.
Interpreter` is one, and :class:`~opspec.engine.simulation.Simulation` subclasses it): the
workflow instances, the ready queue of zero-time work and the clock, the waiters for
triggers, the work items offered, the kept messages and mailboxes, the trace listeners and the
counters of the summary. The parts (:mod:`~opspec.engine.flow`, :mod:`~opspec.engine.activities`,
:mod:`~opspec.engine.triggers`, :mod:`~opspec.engine.offers`) hold no state of their own, only
a reference to this object and to each other.

It also owns the two primitives every part uses: the trace (:meth:`RunState.emit`, built only
when a listener wants the event) and the clock (:meth:`RunState.drain` runs the ready queue,
:meth:`RunState.later` and :meth:`RunState.call_at` schedule timed callbacks on the run's
clock, ``env``, by default a :class:`~opspec.engine.clock.Clock`, through its base
:class:`~opspec.engine.timers.Timers`: its own heap, or a SimPy timeout each).
"""

from __future__ import annotations

import itertools
from collections import deque
from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Final

import simpy

from opspec.engine.compiled import (
    CompiledActivity,
    CompiledPackage,
    CompiledProcess,
    FlagCache,
)
from opspec.engine.config import EngineConfig
from opspec.engine.instances import ActivityInstance, Frame, ProcessInstance
from opspec.engine.lifecycle import RUNNING, SUSPENDED
from opspec.engine.metrics import (
    COUNT,
    START,
    flag_key,
    listener_tables,
    metrics_only,
    own_metrics,
)
from opspec.engine.performers import Performer
from opspec.engine.processors import DedicatedProcessor, PooledProcessor
from opspec.engine.random import Streams
from opspec.engine.registry import PerformerRegistry
from opspec.engine.timed_calls import CallAt as _CallAt
from opspec.engine.timed_calls import CallWith as _CallWith
from opspec.engine.timed_calls import Later as _Later
from opspec.engine.timers import TUPLES, Timed, Timers
from opspec.engine.trace import EventKind as EK
from opspec.engine.trace import TraceEvent, TraceListener
from opspec.engine.zero_time import (
    MAX_INSTANT_STARTS,
    MAX_INSTANT_STEPS,
    SAMPLE_STARTS,
    ZeroTimeSampler,
)
from opspec.engine.zero_time import max_instant_steps as _max_instant_steps
from opspec.model import Package

if TYPE_CHECKING:
    # (a native 64-bit integer compiled; from source only an annotation: no import)
    from mypy_extensions import i64

    from opspec.engine.flow import Flow

__all__ = ["RunState", "discard"]

_EMPTY: Mapping[str, Any] = MappingProxyType({})


class RunState(Timers):
    """The state of one simulation run (see the module docstring)."""

    flow: Flow      # resolves the joins the ready queue leaves pending (set by the Interpreter)

    def __init__(self, compiled: CompiledPackage, config: EngineConfig, *,
                 performers: PerformerRegistry, seed: int, listeners: list[TraceListener],
                 params: Mapping[str, Any] | None, env: simpy.Environment | None,
                 scope: tuple[int, ...], mode_loader: Callable[[str], CompiledPackage | Package] | None
                 ) -> None:
        super().__init__(env)
        self.compiled = compiled
        self.config = config
        self.sim_events = 0         # timeouts scheduled (the summary's sim_events)
        self.registry = performers
        self.streams = Streams(seed, scope)
        self.mode_loader = mode_loader
        self.processes: dict[str, CompiledProcess] = compiled.processes
        self.package_data: dict[str, Any] = dict(compiled.data)
        if params:
            self.package_data.update(params)
        # The ready queue, FIFO: a list read from the front by drain (a list's append is a
        # primitive in the compiled engine, a deque's a Python method call).
        self.ready: list[tuple[Any, Any, Any, Any]] = []
        self.draining = False
        self.pending: dict[Frame, None] = {}
        # the last workflow instance id (Flow.start_process counts on) and the last key of an
        # activity instance or a wait (next_key): native fields, not an itertools.count
        self.last_id = 0
        self.last_key = 0
        self.live: dict[int, ProcessInstance] = {}
        # workflow instances started, completed, terminated, aborted (see :attr:`counts`)
        self.started = 0
        self.completed = 0
        self.terminated = 0
        self.aborted = 0
        self.faults: list[dict[str, Any]] = []
        self.deadlocks: list[dict[str, Any]] = []
        self.stale_completions = 0
        self.waiters: dict[tuple[str, str], dict[int, tuple[ActivityInstance, Any, Any]]] = {}
        # message/signal -> the workflows it starts, each with its start event (-1: all)
        self.starts: dict[tuple[str, str], list[tuple[CompiledProcess, int]]] = {}
        self.ends: dict[tuple[str, str], list[CompiledProcess]] = {}
        self.rules: dict[int, tuple[Any, Any, Any]] = {}       # key -> (cond, handler, arg)
        self.rule_keys = itertools.count(1)
        self.offered: dict[int, ActivityInstance] = {}
        self.mailboxes: dict[str, deque[Any]] = {}
        # messages kept until caught: (receiving root instance id or 0, (kind, name)) ->
        # (data, simulated time it was kept)
        self.kept: dict[tuple[int, tuple[str, str]],
                         deque[tuple[Mapping[str, Any] | None, float]]] = {}
        self.lost_messages = 0
        # the zero-time cycle guard (see drain; its counts i64: machine integers compiled)
        self.instant = -1.0
        self.instant_steps: i64 = 0
        self.max_instant_steps: i64 = _max_instant_steps()
        self.sampler: ZeroTimeSampler | None = None
        self.start_limit = self.max_instant_steps    # 0 while a sampler names the cycle
        # workflow instances started at one instant (each holds memory until it ends: a
        # workflow that starts itself asynchronously must be stopped long before the step
        # limit; see start_counted)
        self.starts_at = -1.0
        self.instant_starts = 0
        # (OPSPEC_MAX_INSTANT_STEPS scales both limits)
        self.max_instant_starts = max(
            1, self.max_instant_steps * MAX_INSTANT_STARTS // MAX_INSTANT_STEPS)
        self.pullers: dict[str, deque[ActivityInstance]] = {}
        self.performers_of: dict[CompiledActivity, Performer | None] = {}
        self.apps = performers.applications
        self.tool_at: dict[int, int] = {}    # activity instance key -> tool offered
        self.pooled = config.pooled
        self.switch = config.switch_cost if config.pooled else 0.0
        self.resolution = config.timer_resolution
        self.pool: PooledProcessor | None = None     # set by the Interpreter
        self.dedicated = DedicatedProcessor()
        self.raised_names: set[str] = set()
        self.mode = compiled.initial_mode
        self.seq = 0
        self.pkg = compiled.id
        (self.listeners, self.raw, self.wants_all, self.selectors, self.wanted,
         self.full) = listener_tables(listeners, compiled)
        self.raw_metrics = metrics_only(self.raw)
        self.one_metric = own_metrics(self.raw_metrics)     # (emit takes its steps in line)
        # (which selection the bits cached on activities and processes are of)
        self.flag_key = flag_key(self.wants_all, self.wanted)

    def idle(self) -> bool:
        """Whether a drain now would only count a step: nothing queued, no frame pending
        (the timer heap asks before it drops a deadline nobody needs any more)."""
        return not self.ready and not self.pending

    def gone(self, iid: int) -> None:
        """Workflow instance ``iid`` ended (``del`` in a ``try``, not ``pop(key, None)``:
        compiled, a dict's pop is a Python method call, a deletion is a primitive and its
        ``try`` costs nothing until it catches)."""
        try:
            del self.live[iid]
        except KeyError:
            pass

    @property
    def counts(self) -> dict[str, int]:
        """The workflow instances started, completed, terminated and aborted so far."""
        return {"started": self.started, "completed": self.completed,
                "terminated": self.terminated, "aborted": self.aborted}

    def wants(self, kind: str, process: str | None, activity: str | None) -> bool:
        return self.wants_all or (kind, process, activity) in self.wanted

    def act_bits(self, act: CompiledActivity) -> int:
        """Which of ``_ACT_KINDS`` some listener wants of ``act``, as bits (computed once per
        listener selection and kept on the activity)."""
        cached = act.flag_cache
        if cached.key is self.flag_key:
            return cached.bits
        bits = self._bits(_ACT_KINDS, act.process, act.id)
        act.flag_cache = FlagCache(self.flag_key, bits)
        return bits

    def proc_bits(self, proc: CompiledProcess) -> int:
        """Which of ``_PROC_KINDS`` some listener wants of ``proc``, as bits."""
        cached = proc.flag_cache
        if cached.key is self.flag_key:
            return cached.bits
        bits = self._bits(_PROC_KINDS, proc.id, None)
        proc.flag_cache = FlagCache(self.flag_key, bits)
        return bits

    def _bits(self, kinds: tuple[str, ...], process: str, activity: str | None) -> int:
        bits = 0
        for n, kind in enumerate(kinds):
            if self.wants(kind, process, activity):
                bits |= 1 << n
        return bits

    def reselect(self) -> None:
        """The listeners' selection changed (workflows loaded at run time)."""
        self.flag_key = flag_key(self.wants_all, self.wanted)

    def emit(self, kind: str, process: str | None = None, instance: int | None = None,
             activity: str | None = None, lane: str | None = None,
             participant: str | None = None, data: Mapping[str, Any] | None = None) -> None:
        """Send one trace event to every listener (callers check :meth:`wants` first)."""
        self.seq += 1
        now = self.now
        metric = self.one_metric
        if metric is not None:
            # MetricsListener.raw in line (the run's own metrics, as a rule its one raw
            # listener: five events a dose cycle, a Python frame each from source)
            try:
                chosen = metric.matching[kind][process][activity]
            except KeyError:
                chosen = metric.chosen(kind, process, activity)
            for name, role, last in chosen:
                if role == COUNT:
                    metric.counts[name] += 1
                    if metric.keep_times:
                        metric.count_times.setdefault(name, []).append(now)
                    continue
                which = instance or 0
                pending = metric.opened[name]
                if role == START:
                    if last or which not in pending:
                        pending[which] = now
                elif which in pending:
                    started = pending[which]
                    del pending[which]
                    metric.samples[name].append(now - started)
                    if metric.keep_times:
                        metric.sample_times.setdefault(name, []).append(now)
        elif self.raw_metrics is not None:
            for each in self.raw_metrics:
                each.raw(now, kind, process, instance, activity, data)
        else:
            for raw in self.raw:
                raw(now, kind, process, instance, activity, data)
        if self.full:
            event = TraceEvent(now, kind, process, instance, activity, lane, participant,
                               self.pkg, data if data is not None else _EMPTY, self.seq)
            for listener, selects in self.full:
                if selects is None or (kind, process, activity) in selects:
                    listener(event)

    def emit_act(self, kind: str, inst: ProcessInstance, act: CompiledActivity,
                  data: Mapping[str, Any] | None = None) -> None:
        if self.wants_all or (kind, act.process, act.id) in self.wanted:
            self.emit(kind, act.process, inst.id, act.id, act.lane, act.participant, data)

    def drain(self) -> None:
        """Run queued zero-time work until none is left (re-entrant calls just return).

        Each item run and each drain counts as a step of this simulated instant (a storm of
        zero-delay wakeups that queue nothing counts too); past ``max_instant_steps`` the
        run stops with a :class:`~opspec.errors.ZeroTimeCycleError` naming the activities
        that keep coming back (:mod:`opspec.engine.zero_time`)."""
        if self.draining:
            return
        now = self.now
        instant = self.instant
        if now != instant:
            # _same_instant in line (a Python frame per drain from source; the time is never
            # negative): a new instant starts its count at 0, a creep of no real time does not
            moved = now - instant if now > instant else instant - now
            if moved > 1e-9 * (now if now > 1.0 else 1.0):
                self.instant = now
                self.instant_steps = 0
                if self.sampler is not None:     # the clock moved on: no cycle after all
                    self.sampler = None
                    self.start_limit = self.max_instant_steps
        ready = self.ready
        if not ready and not self.pending:      # nothing queued: a step of this instant
            steps = self.instant_steps + 1
            if steps > self.max_instant_steps:
                self.instant_steps = steps      # (as the finally below, if this raises)
                steps = self._past_limit(steps, None, None)
            self.instant_steps = steps
            return
        self.draining = True
        done: i64 = 0               # the items of ``ready`` run so far
        steps = self.instant_steps + 1
        limit = self.max_instant_steps
        base = steps                # (the step count is base + done while items run)
        try:
            if steps > limit:
                steps = self._past_limit(steps, None, None)
            while True:
                # (a list's iterator sees what is appended meanwhile) ``check``: the first
                # ``done`` at which the count passes the limit or the burst is long
                base = steps
                check: i64 = _COMPACT + 1   # (a statement: compiled, a conditional expression
                if limit - base < _COMPACT:     # boxed its value as an int, then unboxed it)
                    check = limit - base + 1
                for fn, a, b, c in ready:
                    done += 1
                    if done >= check:
                        if done > _COMPACT:     # a long burst: this item in the next pass
                            done -= 1
                            break
                        base, check = self._past_check(base, done, a, b)
                    # (the commonest items' native methods, see DIRECT: read where used,
                    # compiled without a reference held, as a drain runs about one item)
                    if not DIRECT:
                        fn(a, b, c)
                    elif fn is self.flow.start_lone_q:
                        self.flow.start_lone_at(a, b, c)
                    elif fn is self.flow.activities.body_done_q:
                        self.flow.activities.body_done(a, b, c)
                    else:
                        fn(a, b, c)
                steps = base + done
                if done == len(ready):          # (compiled, a slice's delete boxes its
                    ready.clear()               # bounds into a slice object: 0.3k an instance)
                else:
                    del ready[:done]
                done = 0
                if ready:                       # the burst broke off: go on with the rest
                    continue
                if not self.pending:
                    break
                self.flow.resolve_frames()
                if not ready:
                    break
        finally:
            if done:                            # what ran before an exception
                del ready[:done]
                steps = base + done
            self.draining = False
            self.instant_steps = steps

    def _past_check(self, base: i64, done: i64, a: Any, b: Any) -> tuple[i64, i64]:
        """:meth:`drain`'s count passed the limit at its item ``done`` (``a``, ``b``): the
        count's new base and the next ``done`` to look at (:meth:`_past_limit`)."""
        steps = self._past_limit(base + done, a, b)
        base = steps - done
        limit = self.max_instant_steps
        check: i64 = _COMPACT + 1       # (as in drain)
        if limit - base < _COMPACT:
            check = limit - base + 1
        return base, check

    def _past_limit(self, steps: i64, a: Any, b: Any) -> i64:
        """The step count passed the limit: a new count if the clock moved since the count
        began, else a step of a zero-time cycle (see :meth:`zero_time`)."""
        now = self.now
        if not _same_instant(now, self.instant):
            self.instant = now
            if self.sampler is not None:         # the clock moved on: no cycle after all
                self.sampler = None
                self.start_limit = self.max_instant_steps
            return 1
        self.zero_time(a, b)
        return steps

    def zero_time(self, a: Any, b: Any, starts: int = 0) -> None:
        """A step past the limit at this instant: note what it moves (``a``, ``b`` as in a
        ready-queue item, or a frame and an activity); stop the run once enough are seen.
        ``starts``: the instances started at this instant, when they are what passed a limit."""
        now = self.now
        sampler = self.sampler
        if sampler is None or not _same_instant(now, sampler.at):
            sampler = self.sampler = ZeroTimeSampler(now, self.max_instant_steps)
            self.start_limit = 0                 # _start notes every activity it carries
        if sampler.record(a, b) or starts >= self.max_instant_starts + SAMPLE_STARTS:
            raise sampler.error(starts)

    def later(self, delay: float, fn: Callable[[ActivityInstance, Any], None],
               ai: ActivityInstance, arg: Any = None) -> None:
        """Call ``fn(ai, arg)`` after ``delay`` simulated seconds if ``ai`` is still waiting."""
        if self.resolution > 0.0:
            delay = self._align(delay)
        self.sim_events += 1
        if TUPLES:      # from source, made without a Python frame for its __init__
            entry: Any = _NEW(_Later)
            entry.state, entry.fn, entry.ai, entry.arg, entry.gen = self, fn, ai, arg, ai.gen
        else:
            entry = _Later(self, fn, ai, arg)
        self.schedule_timed(delay if delay > 0.0 else 0.0, entry)  # noqa: FURB136

    def later_entry(self, delay: float, entry: Timed) -> None:
        """:meth:`later` for a timed callback of the caller's own (one that calls its method
        as the native method it is, not a bound method made per call)."""
        if self.resolution > 0.0:
            delay = self._align(delay)
        self.sim_events += 1
        self.schedule_timed(delay if delay > 0.0 else 0.0,  # noqa: FURB136 - no builtin call
                           entry)

    def fire(self, fn: Callable[[ActivityInstance, Any], None], ai: ActivityInstance,
             arg: Any, gen: int) -> None:
        """A :meth:`later` callback is due as a SimPy timeout's (nothing to do, not even a
        look at the clock, when ``ai`` has moved on: a deadline that lost its race)."""
        if ai.gen == gen and ai.state == RUNNING:
            outer = self.enter()
            try:
                self.fired(fn, ai, arg, gen)
            finally:
                self.inside = outer

    def fired(self, fn: Callable[[ActivityInstance, Any], None], ai: ActivityInstance,
              arg: Any, gen: int) -> None:
        """A :meth:`later` callback is due, the time set."""
        if ai.gen == gen and ai.state == RUNNING:
            inst = ai.frame.inst
            if inst.state == SUSPENDED:
                inst.defer((self._refire, fn, ai, (arg, gen)))
                return
            fn(ai, arg)
            self.drain()

    def _refire(self, fn: Callable[[ActivityInstance, Any], None], ai: ActivityInstance,
                arg_gen: tuple[Any, int]) -> None:
        arg, gen = arg_gen
        if ai.gen == gen and ai.state == RUNNING:
            fn(ai, arg)

    def _align(self, delay: float) -> float:
        res = self.resolution
        now = self.now
        target = -(-(now + delay) // res) * res
        return max(0.0, target - now)

    def call_at(self, delay: float, callback: Callable[[], None]) -> None:
        """Run ``callback`` after ``delay`` simulated seconds, then drain. A zero delay while
        draining (a performer answering at once) is queued behind the work queued now, not a
        clock event (an event less per instant answer)."""
        if delay <= 0.0 and self.draining:
            self.ready.append((_CALL, callback, None, None))
            return
        self.sim_events += 1
        self.schedule_timed(delay if delay > 0.0 else 0.0,  # noqa: FURB136
                           _CallAt(self, callback, True))

    def call_at_with(self, delay: float, fn: Callable[[Any, Any, Any], None],
                     a: Any, b: Any, c: Any) -> None:
        """:meth:`call_at` for ``fn(a, b, c)``, no ``functools.partial`` of it: at once while
        draining, the call itself queued (no ``_call``); else a timed entry calls it, then
        drains. The session's ``call_later_with`` (the stochastic user's, from source)."""
        if delay <= 0.0 and self.draining:
            self.ready.append((fn, a, b, c))
            return
        self.sim_events += 1
        if TUPLES:      # from source, made without a Python frame for its __init__
            entry: Any = _NEW(_CallWith)
            entry.state, entry.fn, entry.a, entry.b, entry.c = self, fn, a, b, c
        else:
            entry = _CallWith(self, fn, a, b, c)
        self.schedule_timed(delay if delay > 0.0 else 0.0, entry)  # noqa: FURB136

    def timer(self, delay: float, callback: Callable[[], None]) -> None:
        """Run ``callback`` after ``delay`` simulated seconds (it drains itself, if it
        must: the processors' and the start timers' callbacks)."""
        self.sim_events += 1
        self.schedule_timed(delay if delay > 0.0 else 0.0,  # noqa: FURB136
                           _CallAt(self, callback, False))

    def called(self, callback: Callable[[], None], drain: bool) -> None:
        outer = self.enter()
        try:
            callback()
            if drain:
                self.drain()
        finally:
            self.inside = outer

    def next_key(self) -> int:
        """A new key of an activity instance or a wait (1, 2, …)."""
        self.last_key += 1
        return self.last_key

    def start_counted(self, inst: ProcessInstance) -> None:
        """A workflow instance was started: past
        ``max_instant_starts`` instances at one instant, a zero-time cycle that piles up
        instances (a workflow starting itself asynchronously), stopped and named like any
        zero-time cycle, within seconds and some tens of megabytes."""
        now = self.now
        if now != self.starts_at:
            # _same_instant in line (from source it is three calls): the clock moved
            # unless by a Zeno step
            moved = now - self.starts_at
            scale = now if now >= 0.0 else -now
            if not ((moved if moved >= 0.0 else -moved)
                    <= 1e-9 * (scale if scale > 1.0 else 1.0)):
                self.starts_at = now
                self.instant_starts = 1
                return
        self.instant_starts += 1
        if self.instant_starts > self.max_instant_starts:
            starts = inst.process.graph.starts
            self.zero_time(inst, starts[0] if starts else None, self.instant_starts)


#: how many run items of the ready queue drain keeps before dropping them from its front
_COMPACT: Final = 4096

#: Whether drain calls the two items every instance queues (its first token, a body's end)
#: as native methods (compiled, Python's protocol cost ~180 instructions more a call).
DIRECT: Final = not TUPLES


def _same_instant(now: float, then: float) -> bool:
    """Whether the clock has not really moved: a Zeno creep of 1e-17 s a step (a fuzzed
    spec's) is one instant, stopped by the zero-time guard as a cycle of no time at all."""
    return abs(now - then) <= 1e-9 * max(1.0, abs(now))


_ACT_KINDS = (EK.ACTIVITY_STARTED, EK.ACTIVITY_COMPLETED, EK.ACTIVITY_OFFERED,
              EK.DATA_CHANGED, EK.TRIGGER_RAISED)
_PROC_KINDS = (EK.PROCESS_STARTED, EK.PROCESS_COMPLETED)


def _call(callback: Callable[[], None], _a: Any, _b: Any) -> None:
    callback()


_CALL: Final = _call        # a module static compiled (a global is a dictionary lookup)
#: from source, a timed entry made without calling its class (see RunState.later)
_NEW: Final[Callable[[type], Any]] = object.__new__


def discard(table: dict[Any, Any], key: Any) -> None:
    """Remove ``key`` from ``table`` if it is there (an activity's cleanup)."""
    table.pop(key, None)
