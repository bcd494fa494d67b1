"""The engine's clock: SimPy's :class:`simpy.Environment`, through its public API only.

Time is ``env.now``; ``env.peek()``, ``env.step()`` and ``env.run(until)`` are SimPy's own, so
the order of a run is SimPy's ``(time, priority, event id)`` and ``run(until)`` stops before
what falls at ``until`` as SimPy does. Everything that waits in simulated time in a run is a
timed callback the engine schedules itself (a duration, a deadline, a periodic timer, a
worker's CPU time, a performer's ``call_later``): on a plain environment a SimPy timeout with
the callback attached, ``env.timeout(delay).callbacks.append(callback)`` (SimPy's documented
way to have a function called when an event is processed); on a :class:`Clock` an entry on
the run's own heap, one SimPy timeout at a time driving it (:mod:`opspec.engine.timers`).
Nothing reads SimPy's private state (``tests/engine/test_engine_shape.py`` checks that).

:class:`Clock` is the environment a run makes when it is given none. It tells the run that
drives it (:attr:`Clock.owner`) of every event anything else schedules on it, before SimPy
numbers it (so the run's entries due at that instant go first, as their earlier event ids
would have put them), and reports the run's time while the run has gone ahead of SimPy's
clock. The run summary's ``sim_events`` ("N simulation events") is the number of events
SimPy's event ids would reach with one timeout per timed callback: the engine counts the
timed callbacks it schedules (``RunState.sim_events``), and :attr:`Clock.scheduled` counts
the two events of each ``run(until)`` (its stop event and the stop's requeueing). It starts at
the float ``0.0`` (SimPy's default is the int ``0``), so a trace writes time 0 as ``0.0``.

A caller may pass any :class:`simpy.Environment` instead, e.g. one shared by the simulations
of several households (``Simulation(..., env=env)``); the engine then schedules a timeout per
timed callback on it, and ``sim_events`` is ``None`` unless it is a :class:`Clock`.

Why SimPy and not a hand-written clock: SimPy is part of the stack opspec is built on (see
docs/architecture.md, "The clock"); the cost of its event objects was measured
(docs/engine-performance.md).
"""

from __future__ import annotations

from typing import Any

import simpy
from simpy.core import EmptySchedule
from simpy.events import NORMAL, URGENT

__all__ = ["Clock", "EmptySchedule", "events_scheduled"]


class Clock(simpy.Environment):
    """A SimPy environment that counts the stop events of its ``run(until)`` calls
    (:attr:`scheduled`; the run counts its own timeouts, ``RunState.sim_events``) and that one
    run may drive with its own timer heap (:attr:`owner`, :mod:`opspec.engine.timers`): the
    clock tells that run about every event anything else schedules on it, before SimPy
    numbers it, and reports the run's time while the run is ahead of SimPy's clock."""

    def __init__(self, initial_time: float = 0.0) -> None:
        super().__init__(float(initial_time))
        #: events SimPy scheduled for run(until): the stop event, and the stop put back
        #: once it has stopped the run
        self.scheduled = 0
        #: the run keeping its timed callbacks on its own heap (opspec.engine.timers.Timers)
        self.owner: Any = None

    @property
    def now(self) -> Any:
        """The current simulated time (the owner's while it runs ahead of SimPy's clock)."""
        owner = self.owner
        if owner is not None and owner.lagging:
            return owner.now
        return _SIMPY_NOW(self)

    def schedule(self, event: simpy.Event, priority: Any = NORMAL, delay: Any = 0) -> None:
        """SimPy's ``schedule``, after telling the owner (its entries due at the same instant
        come first: they were scheduled first)."""
        owner = self.owner
        if owner is not None and not owner.scheduling:
            owner.foreign(priority == URGENT, float(delay))
        simpy.Environment.schedule(self, event, priority, delay)

    def run(self, until: Any = None) -> Any:
        if until is None or isinstance(until, simpy.Event) or float(until) <= self.now:
            return super().run(until)
        self.scheduled += 1
        value = super().run(until)
        self.scheduled += 1
        return value


_SIMPY_NOW: Any = simpy.Environment.now.fget  # type: ignore[attr-defined]  # the property's getter


def events_scheduled(env: simpy.Environment) -> int | None:
    """How many stop events ``run(until)`` scheduled on ``env`` (``None``: a plain SimPy
    environment does not say)."""
    scheduled: Any = getattr(env, "scheduled", None)
    return scheduled if isinstance(scheduled, int) else None
