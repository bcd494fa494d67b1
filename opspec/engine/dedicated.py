"""The dedicated processor model's counts: :class:`DedicatedProcessor`.

A module of its own so that the compiled build (``opspec._native``) compiles it with the
engine: the dedicated model is the default, and every activity with a CPU demand records a
burst here (a robot spec: 54,000 an hour), which from :mod:`opspec.engine.processors`
(interpreted) cost a Python call each. The processor models are described in
:mod:`opspec.engine.processors`.
"""

from __future__ import annotations

import heapq
from typing import TYPE_CHECKING

from opspec.engine.timers import LINE_MAX, LINE_MIN, TUPLES

if TYPE_CHECKING:
    # (a native 64-bit integer compiled; from source only an annotation: no import)
    from mypy_extensions import i64

__all__ = ["DedicatedProcessor"]


class DedicatedProcessor:
    """Counts of the dedicated model's CPU use (it schedules nothing).

    ``burst(now, cost)`` records one activity holding its own worker from ``now`` for
    ``cost`` simulated seconds; ``bursts``, ``busy_time`` and ``max_busy`` (most bursts
    overlapping at one time) summarise them. Called only for activities with a CPU demand.
    """

    def __init__(self) -> None:
        # the end times of the bursts under way. From source a heap under heapq (its C code);
        # compiled, while they are few, a *line* as the run's timers keep theirs
        # (timers.line_push): sorted the latest first, the ended ones taken off its end, a
        # new one put in its place found by bisection (heapq's functions are calls through
        # Python's protocol from compiled code). Past LINE_MAX they are a heap again, until
        # fewer than LINE_MIN are under way.
        self._ends: list[float] = []
        self._lined = not TUPLES
        self.bursts = 0
        self.busy_time = 0.0
        self.max_busy = 0

    def burst(self, now: float, cost: float) -> None:
        ends = self._ends
        end = now + cost
        size = len(ends)
        if (self._lined and size and ends[-1] <= now
                and (size == 1 or (ends[-2] > now and ends[-2] > end))):
            # the commonest case: the earliest burst has ended, no other has, and the new
            # one ends first: it takes the ended one's place (a pop and an insertion
            # resized the list's storage each time it went from one to none and back)
            ends[-1] = end
            busy = size
        elif self._lined:
            # the ended bursts taken off but the last of them, ``spare``, which goes only
            # after the new one is in: a list emptied frees its storage, which the insertion
            # would allocate again at once (the earlier ones end no earlier than it)
            while len(ends) > 1 and ends[-2] <= now:
                ends.pop()
            spare = len(ends) > 0 and ends[-1] <= now
            lo: i64 = 0                 # (as timers.line_push's bisection)
            hi: i64 = len(ends) - 1 if spare else len(ends)
            while lo < hi:
                mid = (lo + hi) >> 1
                if ends[mid] > end:
                    lo = mid + 1
                else:
                    hi = mid
            ends.insert(lo, end)
            if spare:
                ends.pop()
            busy = len(ends)
            if busy > LINE_MAX:
                ends.reverse()          # the earliest first: sorted, so a heap
                self._lined = False
        else:
            while ends and ends[0] <= now:
                heapq.heappop(ends)
            heapq.heappush(ends, end)
            busy = len(ends)
            if busy < LINE_MIN and not TUPLES:
                ends.sort(reverse=True)
                self._lined = True
        self.bursts += 1
        self.busy_time += cost
        if busy > self.max_busy:  # noqa: PLR1730 - max() is a builtin call per burst
            self.max_busy = busy

    def summary(self) -> dict[str, float | int]:
        return {"bursts": self.bursts, "busy_time": self.busy_time, "max_busy": self.max_busy}
