"""The public face of the engine: build a :class:`Simulation`, run it, read its result.

::

    compiled = compile_package(package)              # once per package
    sim = Simulation(compiled, EngineConfig(), performers={"user": ScriptedUser(...)}, seed=1)
    result = sim.run(until=86_400)
    result.metrics["doses_taken"]                    # {"kind": "count", "total": 4}

Constructing a Simulation from a compiled package is cheap (no graph work: about 40 us), so
evaluations build one per simulated household and run them one after another: measured on
the dispenser (300 households x 30 days), that is about 10 % faster than all households on one
shared environment, whose event heap grows with the number of households. Sharing is still
possible (``env=``): each simulation keeps its own messages, data and performers, so they are
independent households on one clock.

Start triggers (armed when the run starts, for workflows of the active mode):

* none — the workflow starts at time 0 if it has no start trigger, is no subflow target and
  its start event catches nothing (or its ``auto_start`` directive says so);
* ``timer`` — at each time of day in ``at`` (seconds since midnight) plus ``offset``,
  repeated every ``every`` seconds (one day by default); ``timer:after D`` fires once;
* ``period`` — at ``offset``, ``offset + every``, … (``count`` times when ``count >= 0``):
  ``opspec:Period`` has offset 0; a start event's TimeCycle ``P`` or ``R/P`` has offset ``P``
  (BPMN: first one interval after the start), ``Rn/START/P`` has offset START, a TimeDate is
  one firing at its time (docs/sisarl-xpdl.md, "Timers");
* ``message``/``signal`` — each time one is raised (never buffered);
* ``rule`` — each time the condition over package-wide data becomes true.

End triggers of a workflow terminate its running instances.
"""

from __future__ import annotations

import math
import operator
import queue
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, SupportsFloat, SupportsIndex

import simpy

from opspec.engine.clock import EmptySchedule, events_scheduled
from opspec.engine.compiled import CompiledPackage, compile_package
from opspec.engine.config import EngineConfig
from opspec.engine.interpreter import Interpreter
from opspec.engine.lifecycle import LIFECYCLE, RUNNING, SUSPENDED, TERMINATED
from opspec.engine.metrics import MetricsListener
from opspec.engine.performers import Performer, WorkItem
from opspec.engine.registry import PerformerRegistry
from opspec.engine.trace import EventKind as EK
from opspec.engine.trace import TraceEvent, TraceListener
from opspec.engine.trace_sinks import MemorySink
from opspec.errors import ExecutionError
from opspec.model import Package

__all__ = ["RunResult", "Simulation"]


@dataclass(frozen=True, slots=True)
class RunResult:
    """What a run produced: the trace (if kept), the declared metrics and a summary.

    ``summary`` keys: ``time`` (simulated end), ``seed``, ``events`` (trace events emitted),
    ``sim_events`` (SimPy events scheduled on the clock; ``None`` on a caller's plain
    :class:`simpy.Environment`), ``instances`` (started/completed/terminated/
    aborted/open), ``deadlocks`` and ``faults`` (lists of dicts with a ``message``),
    ``stale_completions``, ``drift`` (wall-clock mode) and ``pool`` (pooled model) or
    ``dedicated`` (CPU bursts, busy time and most bursts at once; dedicated model).
    """

    trace: tuple[TraceEvent, ...] | None
    metrics: dict[str, dict[str, Any]]
    summary: dict[str, Any] = field(default_factory=dict)

    def deadlock_error(self) -> ExecutionError | None:
        """An :class:`ExecutionError` describing the deadlocks, or ``None``."""
        deadlocks = self.summary.get("deadlocks") or []
        if not deadlocks:
            return None
        first = deadlocks[0]
        more = f" (and {len(deadlocks) - 1} more)" if len(deadlocks) > 1 else ""
        return ExecutionError(first["message"] + more, sim_time=first["time"],
                              hint="check the joins, triggers and performers named")


class _Session:
    """The :class:`~opspec.engine.performers.PerformerSession` of one simulation."""

    __slots__ = ("_sim", "call_later", "call_later_with", "complete")

    def __init__(self, sim: Simulation) -> None:
        self._sim = sim
        # The two calls on the path of every work item (the answer, and the performer's
        # callback that gives it) are the engine's own methods, bound once: a method here
        # that forwarded them would be a Python frame more per call from source (two or
        # three per dose cycle each). ``complete`` reads the clock itself when called from
        # outside the run's callbacks (Offers.performer_complete), ``call_later`` is
        # RunState.call_at.
        self.complete: Callable[..., None] = sim.offers.performer_complete
        self.call_later: Callable[..., None] = sim.call_at
        # not part of the PerformerSession protocol: ``call_later(delay, partial(fn, a, b,
        # c))`` without the partial (RunState.call_at_with), for a performer that looks for
        # it (the stochastic user, from source)
        self.call_later_with: Callable[..., None] = sim.call_at_with

    @property
    def now(self) -> float:
        sim = self._sim
        if not sim.inside:          # (inside the run's own callback the clock is read already)
            sim.sync()
        return sim.now

    def omit(self, item: WorkItem, reason: str = "") -> None:
        self._sim.performer_omit(item, reason)

    def fail(self, item: WorkItem, exception: str, message: str = "") -> None:
        self._sim.performer_fail(item, exception, message)

    def raise_trigger(self, name: str, data: Mapping[str, Any] | None = None) -> None:
        self._sim.raise_trigger(name, data)

    def trace(self, kind: str, data: Mapping[str, Any] | None = None) -> None:
        sim = self._sim
        if sim.wants(kind, None, None):
            sim.sync()
            sim.emit(kind, data=dict(data) if data else None)


class Simulation(Interpreter):
    """One run of a compiled package on a simulated clock.

    - ``performers``: a :class:`PerformerRegistry` or a mapping from participant ids / lane
      names to performers (a ``CallablePerformer`` also binds its Application ids).
      Activities outside the user lane with no performer complete by themselves.
    - ``listeners``: trace listeners; a listener with a ``selects`` attribute (a set of
      ``(kind, process, activity)`` with ``None`` wildcards) only receives those events, and
      events nobody selects are never built.
    - ``params``: overrides of package-wide data fields.
    - ``keep_trace``: keep every event in memory (``RunResult.trace``).
    - ``env``: a :class:`simpy.Environment` to run on, e.g. one shared with other simulations
      (independent households); by default a new :class:`~opspec.engine.clock.Clock` (a
      SimPy environment that counts its events: ``sim_events`` is ``None`` on any other).
    - ``scope``: the household index path, prefixed to every random stream.
    - ``mode_loader``: loads the package a mode's ``source`` names, for run-time mode loads.
    """

    def __init__(self, compiled: CompiledPackage | Package, config: EngineConfig | None = None,
                 *, performers: PerformerRegistry | Mapping[str, Performer] | None = None,
                 seed: SupportsIndex = 0, listeners: Iterable[TraceListener] = (),
                 params: Mapping[str, Any] | None = None, keep_trace: bool = False,
                 env: simpy.Environment | None = None, scope: Iterable[SupportsIndex] = (),
                 mode_loader: Callable[[str], CompiledPackage | Package] | None = None) -> None:
        if isinstance(compiled, Package):
            compiled = compile_package(compiled)
        # Plain ints from here on: the compiled engine accepts nothing else, and a caller's
        # numpy integers (a seed from an array) should work as they do from source.
        seed = operator.index(seed)
        self.seed = seed
        self.memory = MemorySink() if keep_trace else None
        self.metrics = MetricsListener(compiled.package.metrics) if (
            compiled.package.metrics) else None
        all_listeners: list[TraceListener] = list(listeners)
        if self.metrics is not None:
            all_listeners.append(self.metrics)
        if self.memory is not None:
            all_listeners.append(self.memory)
        super().__init__(compiled, config or _DEFAULT_CONFIG,
                         performers=PerformerRegistry.coerce(performers), seed=seed,
                         listeners=all_listeners, params=params, env=env,
                         scope=tuple(operator.index(k) for k in scope),
                         mode_loader=mode_loader)
        self.session = _Session(self)
        self._booted = False
        self._posted: queue.SimpleQueue[Callable[[], None]] = queue.SimpleQueue()
        self.wake: Callable[[], None] | None = None
        self.drift: dict[str, Any] | None = None

    # ------------------------------------------------------------------ boot
    def boot(self) -> None:
        """Attach performers and arm start triggers (done by the first run/step)."""
        if self._booted:
            return
        self._booted = True
        self.sync()
        self.registry.claim(self.compiled)
        for performer in self.registry.performers():
            performer.attach(self.session)
        if self.wants(EK.RUN_STARTED, None, None):
            self.emit(EK.RUN_STARTED, data={"seed": self.seed, "package": self.compiled.id,
                                            "processor_model": self.config.processor_model})
        for proc in self.processes.values():
            self.triggers.arm_process(proc)
        self.drain()

    # ------------------------------------------------------------------ control
    def start(self, process_id: str, data: Mapping[str, Any] | None = None) -> int:
        """Start an instance of ``process_id`` now; returns its instance id."""
        self.boot()
        proc = self.processes.get(process_id)
        if proc is None:
            raise ExecutionError(f"no process {process_id!r} in package {self.compiled.id!r}",
                                 hint="known: " + ", ".join(sorted(self.processes)))
        inst = self.start_process(proc, data, trigger="api")    # (reads the clock)
        self.drain()
        iid: int = inst.id
        return iid

    def raise_trigger(self, name: str, data: Mapping[str, Any] | None = None) -> None:
        """Raise ``message:NAME``, ``signal:NAME`` or a bare NAME (a message), now."""
        kind, sep, rest = name.partition(":")
        if sep and kind in ("message", "signal"):
            self.broadcast(kind, rest, data)
        else:
            self.broadcast("message", name, data)
        self.drain()

    def _instance(self, instance_id: int) -> Any:
        inst = self.live.get(instance_id)
        if inst is None:
            raise ExecutionError(f"instance {instance_id} is not running",
                                 hint="it may have finished; see the trace")
        return inst

    def suspend(self, instance_id: int) -> None:
        """Suspend an instance: nothing of it moves until :meth:`resume`."""
        inst = self._instance(instance_id)
        self.sync()
        inst.state = LIFECYCLE.next(inst.state, "suspend", f"instance {instance_id}")
        if self.wants(EK.PROCESS_SUSPENDED, inst.process.id, None):
            self.emit(EK.PROCESS_SUSPENDED, inst.process.id, inst.id, None, inst.process.lane)

    def resume(self, instance_id: int) -> None:
        inst = self._instance(instance_id)
        self.sync()
        inst.state = LIFECYCLE.next(inst.state, "resume", f"instance {instance_id}")
        if self.wants(EK.PROCESS_RESUMED, inst.process.id, None):
            self.emit(EK.PROCESS_RESUMED, inst.process.id, inst.id, None, inst.process.lane)
        deferred, inst.deferred = inst.deferred, None
        self.ready.extend(deferred or ())      # deferred tokens were still counted as live
        self.drain()

    def terminate(self, instance_id: int, reason: str = "terminated by request") -> None:
        self.end_instance(self._instance(instance_id), TERMINATED, reason)
        self.drain()

    def instance_state(self, instance_id: int) -> str:
        """WfMC state name of a live instance (``running``/``suspended``) or ``finished``."""
        inst = self.live.get(instance_id)
        return "finished" if inst is None else ("suspended" if inst.state == SUSPENDED
                                                else "running")

    # ------------------------------------------------------------------ stepping
    def post(self, callback: Callable[[], None]) -> None:
        """Thread-safe: run ``callback`` on the engine's thread before the next step."""
        self._posted.put(callback)
        wake = self.wake
        if wake is not None:
            wake()

    def drain_posts(self) -> int:
        self.sync()
        count = 0
        while True:
            try:
                callback = self._posted.get_nowait()
            except queue.Empty:
                break
            callback()
            count += 1
        if count:
            self.drain()
        return count

    def peek(self) -> float:
        """Time of the next scheduled event (``inf`` when there is none)."""
        self.boot()
        return float(self.env.peek())

    def step(self) -> bool:
        """Process posted input and one clock event; ``False`` when nothing was left."""
        self.boot()
        self.drain_posts()
        try:
            self.env.step()
        except EmptySchedule:
            return False
        return True

    def run(self, until: SupportsFloat | None = None) -> RunResult:
        """Run to simulated time ``until`` (or until nothing is scheduled) and summarise."""
        return self._run(None if until is None else float(until))

    def _run(self, until: float | None) -> RunResult:
        self.boot()
        if until is not None and until < self.env.now:
            raise ExecutionError(f"until ({until}) must not be before the current simulated "
                                 f"time ({self.env.now})")
        self.drain_posts()
        if self.config.realtime:
            from opspec.engine.wallclock import run_realtime

            self.drift = run_realtime(self, until, self.config.speed)
        elif until is None or until > self.env.now:
            # the run's own timers may go ahead of SimPy's clock (opspec/engine/timers.py),
            # not with a shared processor model (it reads env.now itself)
            self.ahead = self.heaped and self.pool is None
            try:
                self.env.run(until=until)
            finally:
                self.ahead = False
        self.sync()                      # run(until) stopped the clock at until
        self.check_waiting(horizon=until)
        if self.wants(EK.RUN_ENDED, None, None):
            self.emit(EK.RUN_ENDED, data={"open": len(self.live),
                                          "deadlocks": len(self.deadlocks)})
        return self.result()

    def check_waiting(self, horizon: float | None) -> None:
        """Report instances that wait for what can never come (see ``deadlock`` below).

        When nothing is scheduled any more, every instance still waiting is deadlocked. When
        the run stopped at its horizon, waiting is normal unless an activity waits for a
        performer that does not exist.
        """
        dry = self.env.peek() == math.inf
        for inst in list(self.live.values()):
            if inst.state != RUNNING:
                continue
            waiting = [(ai.act.id, ai.waiting) for frame in inst.frames
                       for ai in frame.running.values()]
            if dry:
                why = "nothing is scheduled any more"
            else:
                waiting = [w for w in waiting if w[1].startswith("performer for")]
                why = "no performer is bound"
            if waiting:
                self.report_deadlock(inst, [f"{a} ({w})" for a, w in waiting], why)

    def _sim_events(self) -> int | None:
        """SimPy events scheduled for this run: its timeouts and, on its own
        :class:`~opspec.engine.clock.Clock`, the clock's ``run(until)`` stop events (``None``
        on a caller's plain SimPy environment)."""
        stops = events_scheduled(self.env)
        return None if stops is None else self.sim_events + stops

    def result(self) -> RunResult:
        """The result so far (metrics are computed incrementally)."""
        counts = dict(self.counts)
        counts["open"] = len(self.live)
        summary: dict[str, Any] = {
            "time": self.env.now, "seed": self.seed, "events": self.seq,
            "sim_events": self._sim_events(), "instances": counts,
            "deadlocks": list(self.deadlocks), "faults": list(self.faults),
            "stale_completions": self.stale_completions, "drift": self.drift,
            "mode": self.mode,
        }
        if self.pool is not None:
            summary["pool"] = {"workers": self.config.workers, "preemptions": 0,
                               **self.pool.summary(),
                               "model": self.config.processor_model,
                               "preemptive": self.config.processor_model == "preemptive"}
        else:
            summary["dedicated"] = self.dedicated.summary()
        return RunResult(tuple(self.memory.events) if self.memory is not None else None,
                         self.metrics.values() if self.metrics is not None else {}, summary)


_DEFAULT_CONFIG = EngineConfig()
