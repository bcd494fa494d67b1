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

from opspec.engine.timers import INF, LINE_MAX, LINE_MIN, TUPLES

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
        # The end times of the bursts under way. From source a heap under heapq (its C code).
        # Compiled, the two earliest as native floats, ``_first`` and ``_second`` (of them,
        # as many as ``_under_way`` says are held): a robot spec's bursts seldom overlap
        # more than two, and held so a burst boxes no float and resizes no list (a list of
        # one or two floats, its storage freed and allocated again as it went from one to
        # two and back, cost about 0.4k a burst). The later ones are in ``_ends``, a *line*
        # while they are few, as the run's timers keep theirs (timers.line_push): sorted the
        # latest first, the earliest taken off its end, a new one put in its place found by
        # bisection (heapq's functions are calls through Python's protocol from compiled
        # code); past LINE_MAX a heap again, until fewer than LINE_MIN are left.
        self._ends: list[float] = []
        self._lined = not TUPLES
        self._first = INF
        self._second = INF
        self._under_way: i64 = 0
        self.bursts = 0
        self.busy_time = 0.0
        self.max_busy = 0

    def burst(self, now: float, cost: float) -> None:
        end = now + cost
        if TUPLES:
            ends = self._ends
            while ends and ends[0] <= now:
                heapq.heappop(ends)
            heapq.heappush(ends, end)
            busy = len(ends)
        else:
            first = self._first
            second = self._second
            under: i64 = self._under_way
            while under and first <= now:        # the ended ones go, the earliest first
                under -= 1
                first = second
                second = self._take_later() if under >= 2 else INF
            if under == 0 or end < first:
                if under >= 2:
                    self._put_later(second)
                second = first
                first = end
            elif under == 1 or end < second:
                if under >= 2:
                    self._put_later(second)
                second = end
            else:
                self._put_later(end)
            under += 1
            self._first = first
            self._second = second
            self._under_way = under
            busy = under
        self.bursts += 1
        self.busy_time += cost
        if busy > self.max_busy:  # noqa: PLR1730 - max() is a builtin call per burst
            self.max_busy = busy

    def _put_later(self, end: float) -> None:
        """Compiled: ``end`` joins the bursts under way after the two earliest."""
        ends = self._ends
        if self._lined:
            lo: i64 = 0                 # (as timers.line_push's bisection)
            hi: i64 = len(ends)
            while lo < hi:
                mid = (lo + hi) >> 1
                if ends[mid] > end:
                    lo = mid + 1
                else:
                    hi = mid
            ends.insert(lo, end)
            if len(ends) > LINE_MAX:
                ends.reverse()          # the earliest first: sorted, so a heap
                self._lined = False
        else:
            heapq.heappush(ends, end)

    def _take_later(self) -> float:
        """Compiled: the earliest end after the two earliest, taken off (there is one)."""
        ends = self._ends
        if self._lined:
            return ends.pop()
        end = heapq.heappop(ends)
        if len(ends) < LINE_MIN:
            ends.sort(reverse=True)
            self._lined = True
        return end

    def summary(self) -> dict[str, float | int]:
        return {"bursts": self.bursts, "busy_time": self.busy_time, "max_busy": self.max_busy}
