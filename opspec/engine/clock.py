"""The engine's clock: simulated time and the heap of what falls due, owned outright.

Everything that waits in simulated time in a run is a timed callback the engine schedules
itself (a duration, a deadline, a periodic timer, a worker's CPU time, a performer's
``call_later``); nothing in opspec runs SimPy processes. So the engine keeps its own heap of
``(time, sequence, callback)`` rather than SimPy's ``Environment``: a callback is one tuple
on the heap, not an event object, and :meth:`Clock.run` pops and calls them in compiled code.

The order is SimPy's, so traces are the same as when the engine ran on SimPy: by time, and
at equal times in the order they were scheduled (SimPy's ``(time, priority, event id)`` with
every event at NORMAL priority). :meth:`Clock.run` with ``until`` stops, as SimPy's does,
*before* anything due at ``until`` (it falls after the run) and leaves the clock at
``now + (until - now)`` — the same float SimPy computes for its stop event — with that stop
still queued, as SimPy leaves it (so ``peek`` after a run gives ``until`` and the deadlock
check sees a run stopped at its horizon, not a dry one). :attr:`Clock.scheduled` counts as
SimPy's event ids did, the stop and its requeueing included, so a run's summary ("N
simulation events") is unchanged too.
"""

from __future__ import annotations

from collections.abc import Callable
from heapq import heappop, heappush
from typing import Final

__all__ = ["Clock", "EmptySchedule"]

_INF: Final = float("inf")


class EmptySchedule(Exception):  # noqa: N818 - SimPy's name for the same condition
    """:meth:`Clock.step` found nothing scheduled."""


class Clock:
    """Simulated time (``now``, seconds) and the callbacks due later."""

    def __init__(self, initial_time: float = 0.0) -> None:
        self.now: float = float(initial_time)
        self.scheduled: int = 0      # callbacks scheduled so far, and run(until) stops
        self._heap: list[tuple[float, int, Callable[[], None]]] = []

    def after(self, delay: float, callback: Callable[[], None]) -> None:
        """Call ``callback()`` when ``delay`` (>= 0) simulated seconds have passed; after
        everything scheduled before it for the same time."""
        seq = self.scheduled
        self.scheduled = seq + 1
        heappush(self._heap, (self.now + delay, seq, callback))

    def peek(self) -> float:
        """When the next callback is due (``inf`` when nothing is scheduled)."""
        heap = self._heap
        return heap[0][0] if heap else _INF

    def pending(self) -> int:
        """How many callbacks are scheduled and not yet called."""
        return len(self._heap)

    def step(self) -> None:
        """Move to the next callback's time and call it (:class:`EmptySchedule` when none)."""
        heap = self._heap
        if not heap:
            raise EmptySchedule()
        when, _seq, callback = heappop(heap)
        self.now = when
        callback()

    def run(self, until: float | None = None) -> None:
        """Call what falls due, in order: everything (``until=None``), or what falls before
        ``until`` (> ``now``), leaving the clock at ``until``."""
        heap = self._heap
        if until is None:
            while heap:
                when, _seq, callback = heappop(heap)
                self.now = when
                callback()
            return
        if not until > self.now:
            raise ValueError(f"until ({until}) must be after the current simulated time "
                             f"({self.now})")
        stop = self.now + (until - self.now)
        # SimPy's stop event: before anything else due at ``stop`` (a negative sequence)
        self.scheduled += 1
        heappush(heap, (stop, -self.scheduled, _nothing))
        while heap[0][0] < stop:
            when, _seq, callback = heappop(heap)
            self.now = when
            callback()
        heappop(heap)
        self.now = stop
        # ... which SimPy puts back once it has stopped the run: it stays queued at ``stop``
        # (``peek`` gives ``stop``, the next ``step`` takes it and does nothing), so what
        # looks at the queue after a run (the deadlock check, stepping) sees what it saw
        self.scheduled += 1
        heappush(heap, (stop, -self.scheduled, _nothing))


def _nothing() -> None:
    """The stop mark of :meth:`Clock.run`: nothing happens when it is reached."""
