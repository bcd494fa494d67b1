"""Timed callbacks on a SimPy clock, without ``simpy.Timeout``'s cost.

The engine schedules a few timed callbacks per dose cycle (durations, deadlines, periodic
timers, a performer's ``call_later``). ``env.timeout(d).callbacks.append(f)`` builds a
``Timeout`` in Python (``env.timeout``, ``Timeout.__init__``, ``env.schedule``: about 1.5 us
on the development machine, some 7 % of a dose cycle). :meth:`Wakeups.after` puts a minimal
event straight on the environment's queue instead, exactly where ``env.schedule`` would
(same time, NORMAL priority, next event id), so the order of events, and hence every
trace, is unchanged. ``Environment.step`` only reads an event's ``callbacks``, ``_ok`` and
``_value``; a :class:`Wakeup` has those and nothing else.
"""

from __future__ import annotations

from collections.abc import Callable
from heapq import heappush
from typing import Any, Final

import simpy
from simpy.events import NORMAL

__all__ = ["Wakeup", "Wakeups"]

_NORMAL: Final = int(NORMAL)      # the priority env.timeout gives its events


class Wakeup:
    """A scheduled, already-triggered SimPy event that calls ``callback(event)``."""

    def __init__(self, callback: Callable[[Any], None]) -> None:
        self.callbacks: list[Callable[[Any], None]] | None = [callback]
        self._ok = True
        self._value: Any = None


class Wakeups:
    """Schedules wakeups on one environment (its queue and event counter, which SimPy never
    replaces, are looked up once)."""

    def __init__(self, env: simpy.Environment) -> None:
        self.env = env
        self._queue: Any = env._queue
        self._eid: Any = env._eid

    def after(self, delay: float, callback: Callable[[Any], None]) -> None:
        """Call ``callback(event)`` when ``delay`` (>= 0) simulated seconds have passed."""
        heappush(self._queue, (self.env._now + delay, _NORMAL, next(self._eid),
                               Wakeup(callback)))
