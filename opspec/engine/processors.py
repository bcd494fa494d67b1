"""The pooled processor model: N workers, one FIFO queue per priority level.

The source design's Windows CE engine: a leader thread runs built-ins inline and puts ready
*general* activities into one FIFO queue per priority (workflow priority + activity priority
increment); workers take the head of the highest non-empty queue; every transition into a
general activity costs a context switch. Here a worker is held for ``switch_cost`` plus the
activity's ``cpu_demand`` simulated seconds, then the activity goes on (its declared duration,
if any, elapses without holding a worker).

The queues are plain deques indexed by level, not ``simpy.PriorityResource``, which re-sorts
its whole queue on every request (12 us with 20 waiting, 360 us with 5,000; issue 3).

The dedicated model needs no object: every instance has its own worker, so an activity only
waits for its own ``cpu_demand``.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import Any

import simpy

__all__ = ["PooledProcessor"]


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
