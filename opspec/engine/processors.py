"""The pooled processor model: N workers, one FIFO queue per priority level.

The source design's Windows CE engine: a leader thread runs built-ins inline and puts ready
*general* activities into one FIFO queue per priority (workflow priority + activity priority
increment); workers take the head of the highest non-empty queue; every transition into a
general activity costs a context switch. Here a worker is held for ``switch_cost`` plus the
activity's ``cpu_demand`` simulated seconds, then the activity goes on (its declared duration,
if any, elapses without holding a worker).

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

import heapq
from collections import deque
from collections.abc import Callable
from typing import Any

import simpy

__all__ = ["DedicatedProcessor", "PooledProcessor", "PreemptiveProcessor"]


class PooledProcessor:
    """Workers and per-priority FIFO queues.

    ``submit(job, level, cost)`` runs ``on_done(job)`` once a worker has been free for the job
    and ``cost`` simulated seconds have passed; it returns ``True`` when the job had to queue.
    ``is_alive(job)`` lets the pool skip jobs cancelled while they waited.
    """

    __slots__ = (
        "busy_time",
        "env",
        "free",
        "is_alive",
        "max_waiting",
        "on_done",
        "queues",
        "switches",
        "waiting",
    )

    def __init__(self, env: simpy.Environment, workers: int, priorities: int,
                 on_done: Callable[[Any], None], is_alive: Callable[[Any], bool]) -> None:
        self.env = env
        self.free = workers
        self.queues: list[deque[tuple[Any, float]]] = [deque() for _ in range(priorities)]
        self.waiting = 0
        self.on_done = on_done
        self.is_alive = is_alive
        self.busy_time = 0.0
        self.max_waiting = 0
        self.switches = 0            # activities dispatched to a worker (one switch each)

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
            timeout = self.env.timeout(cost)
            timeout.callbacks.append(lambda _event: self._finished(job))
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


class DedicatedProcessor:
    """Counts of the dedicated model's CPU use (it schedules nothing).

    ``burst(now, cost)`` records one activity holding its own worker from ``now`` for
    ``cost`` simulated seconds; ``bursts``, ``busy_time`` and ``max_busy`` (most bursts
    overlapping at one time) summarise them. Called only for activities with a CPU demand.
    """

    __slots__ = ("_ends", "bursts", "busy_time", "max_busy")

    def __init__(self) -> None:
        self._ends: list[float] = []      # end times of the bursts under way (a heap)
        self.bursts = 0
        self.busy_time = 0.0
        self.max_busy = 0

    def burst(self, now: float, cost: float) -> None:
        ends = self._ends
        while ends and ends[0] <= now:
            heapq.heappop(ends)
        heapq.heappush(ends, now + cost)
        self.bursts += 1
        self.busy_time += cost
        self.max_busy = max(self.max_busy, len(ends))

    def summary(self) -> dict[str, float | int]:
        return {"bursts": self.bursts, "busy_time": self.busy_time, "max_busy": self.max_busy}


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

    def _start(self, job: Any, level: int, cost: float) -> None:
        self.switches += 1
        entry = [job, level, cost, self.env.now, 0]
        self.running.append(entry)
        self._arm(entry)

    def _arm(self, entry: list[Any]) -> None:
        generation = entry[4]
        timeout = self.env.timeout(max(0.0, entry[2]))
        timeout.callbacks.append(lambda _event: self._done(entry, generation))

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
