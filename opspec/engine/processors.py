"""The processor models: who runs a ready general activity, when, and at what cost.

``make_processor`` builds the one a configuration names (docs/processor-models.md):

- ``pooled`` (:class:`PooledProcessor`): N shared non-preemptive workers take the head of the
  highest non-empty FIFO queue per priority (workflow priority + activity priority
  increment); a worker is held for ``switch_cost`` plus the activity's ``cpu_demand``
  simulated seconds, then the activity goes on (its declared duration, if any, elapses
  without holding a worker). A simplification of the source's Windows CE engine: no leader,
  no worker per queue, no preemption.
- ``preemptive`` (:class:`PreemptiveProcessor`): K processors, fixed-priority preemptive
  scheduling (the source's Linux engine: a thread per workflow at its priority).
- ``priority-queues`` (:class:`PriorityQueueProcessor`): the source's Windows CE engine as
  EMWF TR-IIS-08-005 §4.2.2 describes it: a FIFO queue per priority served by its own worker
  thread(s) at the queue's priority, a leader thread above them that queues work and handles
  completions, all on K processors with fixed-priority preemption and a cost per context
  switch.
- ``dedicated`` (no processor object; :class:`DedicatedProcessor` only counts).

The queues are plain deques indexed by level, not ``simpy.PriorityResource``, which re-sorts
its whole queue on every request (12 us with 20 waiting, 360 us with 5,000; issue 3).

The dedicated model (the source's Linux engine) gives every workflow instance its own worker
thread, so processors are unlimited by design: an activity only waits for its own
``cpu_demand``, and priorities and switch costs do not apply. :class:`DedicatedProcessor`
does not schedule anything; it only counts what that design assumes: how many CPU bursts ran
(each a thread waking for its instance's activity; no switch cost is charged) and how many
ran at once at most (the processors a real device would need to match the dedicated model,
the fair ``--workers`` to compare the pooled model against).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import simpy

from opspec.engine.dedicated import DedicatedProcessor

if TYPE_CHECKING:
    from opspec.engine.config import EngineConfig

#: schedules ``callback()`` after a delay in simulated seconds
Timer = Callable[[float, Callable[[], None]], None]


class _SimpyTimer:
    """A timer on a bare SimPy environment (a processor built outside a run)."""

    __slots__ = ("env",)

    def __init__(self, env: simpy.Environment) -> None:
        self.env = env

    def __call__(self, delay: float, callback: Callable[[], None]) -> None:
        self.env.timeout(delay).callbacks.append(lambda _e: callback())


__all__ = ["DedicatedProcessor", "PooledProcessor", "PreemptiveProcessor",
           "PriorityQueueProcessor", "make_processor"]


def make_processor(env: simpy.Environment, config: EngineConfig,
                   on_done: Callable[[Any], None], is_alive: Callable[[Any], bool],
                   timer: Timer | None = None) -> PooledProcessor | None:
    """The shared processors ``config`` asks for (``None``: the dedicated model). Its
    ``activity_switch`` is the switch cost the engine adds to each general activity's
    demand (the models that charge their own switches say 0). ``timer(delay, callback)``
    schedules the processors' timeouts (the run's :meth:`RunState.timer
    <opspec.engine.runstate.RunState.timer>`, which counts them and tells the engine the
    time; by default a plain SimPy timeout on ``env``)."""
    model = config.processor_model
    pool: PooledProcessor
    if model == "preemptive":
        pool = PreemptiveProcessor(env, config.workers, config.priorities, on_done, is_alive,
                                   config.switch_cost)
    elif model == "priority-queues":
        pool = PriorityQueueProcessor(env, config.workers, config.priorities, on_done,
                                      is_alive, config.switch_cost, config.queue_workers)
    elif model == "pooled":
        pool = PooledProcessor(env, config.workers, config.priorities, on_done, is_alive)
    else:
        return None
    if timer is not None:
        pool.timer = timer
    if model != "priority-queues":
        pool.activity_switch = config.switch_cost
    return pool


class PooledProcessor:
    """Workers and per-priority FIFO queues.

    ``submit(job, level, cost)`` runs ``on_done(job)`` once a worker has been free for the job
    and ``cost`` simulated seconds have passed; it returns ``True`` when the job had to queue.
    ``is_alive(job)`` lets the pool skip jobs cancelled while they waited.
    """

    __slots__ = (
        "activity_switch",
        "busy_time",
        "env",
        "free",
        "is_alive",
        "max_waiting",
        "on_done",
        "queues",
        "switches",
        "timer",
        "waiting",
    )

    def __init__(self, env: simpy.Environment, workers: int, priorities: int,
                 on_done: Callable[[Any], None], is_alive: Callable[[Any], bool]) -> None:
        self.env = env
        self.timer: Timer = _SimpyTimer(env)
        self.free = workers
        self.queues: list[deque[tuple[Any, float]]] = [deque() for _ in range(priorities)]
        self.waiting = 0
        self.on_done = on_done
        self.is_alive = is_alive
        self.busy_time = 0.0
        self.max_waiting = 0
        self.switches = 0            # activities dispatched to a worker (one switch each)
        self.activity_switch = 0.0   # what the engine adds to a general activity's demand

    def summary(self) -> dict[str, Any]:
        """What the run summary reports under ``pool``."""
        return {"busy_time": self.busy_time, "max_waiting": self.max_waiting,
                "switches": self.switches}

    def submit(self, job: Any, level: int, cost: float) -> bool:
        top = len(self.queues) - 1
        level = 0 if level < 0 else (min(level, top))
        if self.free > 0:
            self.free -= 1
            self._run(job, cost)
            return False
        self.queues[level].append((job, cost))
        self.waiting += 1
        self.max_waiting = max(self.max_waiting, self.waiting)
        return True

    def _run(self, job: Any, cost: float) -> None:
        self.switches += 1
        self.busy_time += cost
        if cost > 0.0:
            self.timer(cost, lambda: self._finished(job))
        else:
            self._finished(job)

    def _finished(self, job: Any) -> None:
        self.free += 1
        self._dispatch()
        self.on_done(job)

    def _dispatch(self) -> None:
        while self.free > 0 and self.waiting:
            for queue in reversed(self.queues):       # highest level first
                if queue:
                    job, cost = queue.popleft()
                    self.waiting -= 1
                    if self.is_alive(job):
                        self.free -= 1
                        self._run(job, cost)
                    break


class PreemptiveProcessor(PooledProcessor):
    """``workers`` processors under fixed-priority preemptive scheduling.

    The source design's Linux engine runs a thread per workflow at the workflow's priority;
    on K processors the K highest-level ready jobs run. A job submitted at a level above the
    lowest-level running job takes that job's processor at once: the preempted job keeps its
    remaining demand and waits at the *head* of its level's queue (it came first), and pays
    ``switch_cost`` again when it resumes. Jobs of equal level never preempt each other.

    Same interface as :class:`PooledProcessor` (``submit`` returns ``True`` when the job had
    to wait); ``preemptions`` counts the jobs taken off a processor. With one processor and
    periodic workflows released together, the worst response times equal fixed-priority
    response-time analysis (tests/processors/test_preemptive.py).
    """

    __slots__ = ("preemptions", "running", "switch_cost")

    def __init__(self, env: simpy.Environment, workers: int, priorities: int,
                 on_done: Callable[[Any], None], is_alive: Callable[[Any], bool],
                 switch_cost: float = 0.0) -> None:
        super().__init__(env, workers, priorities, on_done, is_alive)
        self.switch_cost = switch_cost
        self.preemptions = 0
        # per running job: [job, level, remaining cost, started at, generation]
        self.running: list[list[Any]] = []

    def submit(self, job: Any, level: int, cost: float) -> bool:
        top = len(self.queues) - 1
        level = 0 if level < 0 else (min(level, top))
        if self.free > 0:
            self.free -= 1
            self._start(job, level, cost)
            return False
        now = self.env.now
        # a job whose demand ends at this very instant completes rather than being preempted
        # (its completion is an event at the same time, processed right after this one)
        candidates = [entry for entry in self.running if entry[2] - (now - entry[3]) > 1e-12]
        victim = min(candidates, key=lambda entry: (entry[1], -entry[3]), default=None)
        if victim is not None and victim[1] < level:
            self._preempt(victim)
            self._start(job, level, cost)
            return False
        self.queues[level].append((job, cost))
        self.waiting += 1
        self.max_waiting = max(self.max_waiting, self.waiting)
        return True

    def summary(self) -> dict[str, Any]:
        return {**super().summary(), "preemptions": self.preemptions}

    def _start(self, job: Any, level: int, cost: float) -> None:
        self.switches += 1
        entry = [job, level, cost, self.env.now, 0]
        self.running.append(entry)
        self._arm(entry)

    def _arm(self, entry: list[Any]) -> None:
        generation = entry[4]
        self.timer(max(0.0, entry[2]), lambda: self._done(entry, generation))

    def _preempt(self, entry: list[Any]) -> None:
        ran = self.env.now - entry[3]
        self.busy_time += ran
        self.running.remove(entry)
        entry[4] += 1                           # its pending completion is stale now
        self.preemptions += 1
        self.free += 1
        # at the head of its level: it was ready before anything waiting there
        self.queues[entry[1]].appendleft((entry[0], entry[2] - ran + self.switch_cost))
        self.waiting += 1
        self.max_waiting = max(self.max_waiting, self.waiting)
        self.free -= 1                          # its processor goes to the preempting job

    def _done(self, entry: list[Any], generation: int) -> None:
        if entry[4] != generation or entry not in self.running:
            return
        self.running.remove(entry)
        self.busy_time += self.env.now - entry[3]
        self.free += 1
        self._dispatch_levels()
        self.on_done(entry[0])

    def _dispatch_levels(self) -> None:
        while self.free > 0 and self.waiting:
            for level in range(len(self.queues) - 1, -1, -1):     # highest level first
                queue = self.queues[level]
                if queue:
                    job, cost = queue.popleft()
                    self.waiting -= 1
                    if self.is_alive(job):
                        self.free -= 1
                        self._start(job, level, cost)
                    break


class _Thread:
    """A thread of the priority-queues model: the leader, or a worker holding one work item.

    ``remaining`` is the item's processor demand still to run (the leader has none: its pass
    is the switch into it); ``order`` breaks ties between threads of one level (the one ready
    first runs first); ``generation`` makes a segment's completion stale once preempted."""

    __slots__ = ("generation", "job", "level", "order", "remaining", "started")

    def __init__(self, level: int, job: Any, remaining: float, order: int) -> None:
        self.level = level
        self.job = job
        self.remaining = remaining
        self.order = order
        self.started = 0.0
        self.generation = 0


class PriorityQueueProcessor(PooledProcessor):
    """The source's Windows CE engine (EMWF TR-IIS-08-005 §4.2.2) on ``cpus`` processors.

    - A ready general activity becomes a work item in the FIFO queue of its level (workflow
      priority + priority increment, clamped to ``0 .. priorities-1``).
    - Each queue has ``queue_workers`` worker threads of its own, at the queue's priority; a
      free worker takes its queue's head, so one worker per queue runs that level's items
      one after the other even when a processor is idle.
    - A leader thread, above every queue, queues the work and handles completions: a worker
      that finishes an item signals the leader, which — once it has a processor — looks at
      the completed items in priority order (highest first), carries each one's workflow on
      (the engine's inline built-ins: no processor time) and queues what that readies. Work
      readied outside the leader (a timer, a device's answer: the source's helper threads)
      also wakes the leader, which queues it in the order it arrived, after the completions.
    - The threads share ``cpus`` processors by fixed priority with preemption (the leader
      first; equal levels in the order they became ready, never preempting each other).
      Every time a processor starts or resumes a thread it spends ``switch_cost`` first: so
      a general activity costs at least two switches (into its worker, back into the leader),
      a release one more (into the leader), and a preempted item one more when it resumes.

    ``submit`` returns ``True`` when the item found no free worker of its level; ``summary``
    adds the leader's passes, the preemptions and the processors' count to the pool's.
    """

    __slots__ = ("_completed", "_in_leader", "_leader", "_leader_busy", "_order",
                 "_ready", "_released", "_running", "cpus", "idle", "leader_passes",
                 "preemptions", "queue_workers", "switch_cost")

    def __init__(self, env: simpy.Environment, cpus: int, priorities: int,
                 on_done: Callable[[Any], None], is_alive: Callable[[Any], bool],
                 switch_cost: float = 0.0, queue_workers: int = 1) -> None:
        super().__init__(env, cpus, priorities, on_done, is_alive)
        self.cpus = cpus
        self.switch_cost = switch_cost
        self.queue_workers = queue_workers
        self.idle = [queue_workers] * priorities       # free workers per level
        self.preemptions = 0
        self.leader_passes = 0
        self._order = 0
        self._leader = _Thread(priorities, None, 0.0, 0)  # above every queue
        self._leader_busy = False        # runnable or running
        self._in_leader = False          # inside the leader's handling (submits queue at once)
        self._completed: list[tuple[int, int, Any]] = []   # (level, order, job)
        self._released: list[tuple[Any, int, float]] = []  # (job, level, cost)
        self._ready: list[_Thread] = []
        self._running: list[_Thread] = []

    # ---------------------------------------------------------------- the engine's side
    def submit(self, job: Any, level: int, cost: float) -> bool:
        top = len(self.queues) - 1
        level = 0 if level < 0 else (min(level, top))
        queued = self.idle[level] == 0
        if self._in_leader:
            self._enqueue(job, level, cost)
        else:                             # a helper thread wakes the leader, which queues it
            self._released.append((job, level, cost))
            self._wake_leader()
            self._schedule()
        return queued

    def summary(self) -> dict[str, Any]:
        return {**super().summary(), "cpus": self.cpus, "queue_workers": self.queue_workers,
                "leader_passes": self.leader_passes, "preemptions": self.preemptions}

    # ---------------------------------------------------------------- queues and workers
    def _next_order(self) -> int:
        self._order += 1
        return self._order

    def _enqueue(self, job: Any, level: int, cost: float) -> None:
        if self.idle[level] > 0:
            self.idle[level] -= 1
            self._ready.append(_Thread(level, job, cost, self._next_order()))
        else:
            self.queues[level].append((job, cost))
            self.waiting += 1
            self.max_waiting = max(self.max_waiting, self.waiting)

    def _worker_free(self, level: int) -> None:
        """A worker of ``level`` finished its item: it takes the head of its queue."""
        queue = self.queues[level]
        while queue:
            job, cost = queue.popleft()
            self.waiting -= 1
            if self.is_alive(job):
                self._ready.append(_Thread(level, job, cost, self._next_order()))
                return
        self.idle[level] += 1

    def _wake_leader(self) -> None:
        if not self._leader_busy:
            self._leader_busy = True
            self._leader.order = self._next_order()
            self._ready.append(self._leader)

    # ---------------------------------------------------------------- the processors
    def _schedule(self) -> None:
        """Give the processors to the highest-priority ready threads, preempting lower ones."""
        ready = self._ready
        while ready:
            best = max(ready, key=lambda t: (t.level, -t.order))
            if self.free <= 0:
                now = self.env.now
                # a thread whose segment ends at this instant completes, it is not preempted
                victims = [t for t in self._running if t.level < best.level
                           and t.started + self.switch_cost + t.remaining - now > 1e-12]
                if not victims:
                    return
                self._preempt(min(victims, key=lambda t: (t.level, -t.order)))
            ready.remove(best)
            self._start(best)

    def _start(self, thread: _Thread) -> None:
        self.free -= 1
        self.switches += 1
        self._running.append(thread)
        thread.started = self.env.now
        thread.generation += 1
        generation = thread.generation
        self.timer(self.switch_cost + thread.remaining,
                   lambda: self._segment_end(thread, generation))

    def _preempt(self, thread: _Thread) -> None:
        now = self.env.now
        ran = now - thread.started
        thread.remaining = max(0.0, thread.remaining - max(0.0, ran - self.switch_cost))
        self.busy_time += ran
        thread.generation += 1                   # its pending segment end is stale now
        self._running.remove(thread)
        self.free += 1
        self.preemptions += 1
        self._ready.append(thread)               # keeps its order: first among its level

    def _segment_end(self, thread: _Thread, generation: int) -> None:
        if thread.generation != generation:
            return
        self.busy_time += self.env.now - thread.started
        self._running.remove(thread)
        self.free += 1
        if thread is self._leader:
            self._leader_pass()
        else:
            self._completed.append((thread.level, thread.order, thread.job))
            self._worker_free(thread.level)
            self._wake_leader()
        self._schedule()

    def _leader_pass(self) -> None:
        """The leader has its processor: completions in priority order, then releases."""
        self.leader_passes += 1
        completed = sorted(self._completed, key=lambda c: (-c[0], c[1]))
        released, self._completed, self._released = self._released, [], []
        self._in_leader = True
        try:
            for _level, _order, job in completed:
                self.on_done(job)
            for job, level, cost in released:
                if self.is_alive(job):
                    self._enqueue(job, level, cost)
        finally:
            self._in_leader = False
            self._leader_busy = False
        if self._completed or self._released:    # cannot happen within zero time; be safe
            self._wake_leader()
