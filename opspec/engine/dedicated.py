"""The dedicated processor model's counts: :class:`DedicatedProcessor`.

A module of its own so that the compiled build (``opspec._native``) compiles it with the
engine: the dedicated model is the default, and every activity with a CPU demand records a
burst here (a robot spec: 54,000 an hour), which from :mod:`opspec.engine.processors`
(interpreted) cost a Python call each. The bursts under way are kept on a heap by the functions
of the run's timer heap (:mod:`opspec.engine.timers`). The processor models are described
in :mod:`opspec.engine.processors`.
"""

from __future__ import annotations

import heapq

from opspec.engine.timers import TUPLES, Timed, heap_pop, heap_push

__all__ = ["DedicatedProcessor"]


class DedicatedProcessor:
    """Counts of the dedicated model's CPU use (it schedules nothing).

    ``burst(now, cost)`` records one activity holding its own worker from ``now`` for
    ``cost`` simulated seconds; ``bursts``, ``busy_time`` and ``max_busy`` (most bursts
    overlapping at one time) summarise them. Called only for activities with a CPU demand.
    """

    def __init__(self) -> None:
        # the end times of the bursts under way, a heap: from source floats under heapq;
        # compiled, timed entries on the run's own heap functions (comparing their native
        # fields, where heapq is a call through Python's protocol per burst)
        self._ends: list[float] = []
        self._marks: list[Timed] = []
        self.bursts = 0
        self.busy_time = 0.0
        self.max_busy = 0

    def burst(self, now: float, cost: float) -> None:
        if not TUPLES:          # compiled (as the timers' heap)
            marks = self._marks
            while marks and marks[0].at <= now:
                heap_pop(marks)
            mark = Timed()
            mark.at = now + cost
            mark.seq = 0            # (bursts that end together: any order will do)
            heap_push(marks, mark)
            busy = len(marks)
        else:
            ends = self._ends
            while ends and ends[0] <= now:
                heapq.heappop(ends)
            heapq.heappush(ends, now + cost)
            busy = len(ends)
        self.bursts += 1
        self.busy_time += cost
        if busy > self.max_busy:  # noqa: PLR1730 - max() is a builtin call per burst
            self.max_busy = busy

    def summary(self) -> dict[str, float | int]:
        return {"bursts": self.bursts, "busy_time": self.busy_time, "max_busy": self.max_busy}
