"""The dedicated processor model's counts: :class:`DedicatedProcessor`.

A module of its own so that the compiled build (``opspec._native``) compiles it with the
engine: the dedicated model is the default, and every activity with a CPU demand records a
burst here (a robot spec: 54,000 an hour), which from :mod:`opspec.engine.processors`
(interpreted) cost a Python call each. See that module for the processor models.
"""

from __future__ import annotations

import heapq
import types
from typing import Final

__all__ = ["DedicatedProcessor"]


class DedicatedProcessor:
    """Counts of the dedicated model's CPU use (it schedules nothing).

    ``burst(now, cost)`` records one activity holding its own worker from ``now`` for
    ``cost`` simulated seconds; ``bursts``, ``busy_time`` and ``max_busy`` (most bursts
    overlapping at one time) summarise them. Called only for activities with a CPU demand.
    """

    def __init__(self) -> None:
        self._ends: list[float] = []      # end times of the bursts under way (a heap)
        self.bursts = 0
        self.busy_time = 0.0
        self.max_busy = 0

    def burst(self, now: float, cost: float) -> None:
        ends = self._ends
        if COMPILED:
            while ends and ends[0] <= now:
                _pop(ends)
            _push(ends, now + cost)
        else:
            while ends and ends[0] <= now:
                heapq.heappop(ends)
            heapq.heappush(ends, now + cost)
        self.bursts += 1
        self.busy_time += cost
        busy = len(ends)
        if busy > self.max_busy:          # max() without a builtin call per burst
            self.max_busy = busy

    def summary(self) -> dict[str, float | int]:
        return {"bursts": self.bursts, "busy_time": self.busy_time, "max_busy": self.max_busy}


# heapq's heappush and heappop on floats, in this module: compiled, they compare two native
# floats, where heapq's (a module attribute looked up and called through Python's protocol per
# burst) cost as much as the rest of the burst; from source heapq's C code is the faster


def _push(heap: list[float], value: float) -> None:
    heap.append(value)
    pos = len(heap) - 1
    while pos > 0:
        up = (pos - 1) >> 1
        parent = heap[up]
        if value < parent:
            heap[pos] = parent
            pos = up
        else:
            break
    heap[pos] = value


def _pop(heap: list[float]) -> float:
    last = heap.pop()
    if not heap:
        return last
    first = heap[0]
    size = len(heap)
    pos = 0
    while True:
        child = 2 * pos + 1
        if child >= size:
            break
        right = child + 1
        if right < size and heap[right] < heap[child]:
            child = right
        low = heap[child]
        if low < last:
            heap[pos] = low
            pos = child
        else:
            break
    heap[pos] = last
    return first


#: whether this module runs compiled (then :func:`_push` and :func:`_pop` are native)
COMPILED: Final = not isinstance(_push, types.FunctionType)
