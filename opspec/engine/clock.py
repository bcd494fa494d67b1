"""The engine's clock: SimPy's :class:`simpy.Environment`, through its public API only.

Everything that waits in simulated time in a run is a timed callback the engine schedules
itself (a duration, a deadline, a periodic timer, a worker's CPU time, a performer's
``call_later``): a SimPy timeout with the callback attached,
``env.timeout(delay).callbacks.append(callback)`` — SimPy's documented way to have a function
called when an event is processed. Nothing in opspec runs SimPy processes, and nothing reads
SimPy's private state (``tests/engine/test_engine_shape.py`` checks that). Time is
``env.now``; ``env.peek()``, ``env.step()`` and ``env.run(until)`` are SimPy's own, so the
order of a run is SimPy's ``(time, priority, event id)`` and ``run(until)`` stops before what
falls at ``until`` as SimPy does.

:class:`Clock` is the environment a run makes when it is given none. It adds one thing SimPy
does not offer publicly: :attr:`Clock.scheduled`, how many events were scheduled on it (the
run summary's ``sim_events``, "N simulation events"), counted by overriding the public
:meth:`simpy.Environment.schedule` every event goes through — the same number SimPy's event
ids reach, its ``run(until)`` stop event and the stop's requeueing included. It starts at the
float ``0.0`` (SimPy's default is the int ``0``), so a trace writes time 0 as ``0.0``.

A caller may pass any :class:`simpy.Environment` instead, e.g. one shared by the simulations
of several households (``Simulation(..., env=env)``); the engine then schedules on it the
same way, and ``sim_events`` is ``None`` unless it is a :class:`Clock`.

Why SimPy and not a hand-written heap: SimPy is part of the stack opspec is built on (see
docs/architecture.md, "The clock"); the cost of its event objects was measured
(docs/engine-performance.md).
"""

from __future__ import annotations

from typing import Any

import simpy
from simpy.core import EmptySchedule
from simpy.events import NORMAL, EventPriority

__all__ = ["Clock", "EmptySchedule", "events_scheduled"]


class Clock(simpy.Environment):
    """A SimPy environment that counts the events scheduled on it (:attr:`scheduled`)."""

    def __init__(self, initial_time: float = 0.0) -> None:
        super().__init__(float(initial_time))
        #: events scheduled so far (every one: timeouts, and run(until)'s stop events)
        self.scheduled = 0

    def schedule(self, event: simpy.Event, priority: EventPriority = NORMAL,
                 delay: float = 0) -> None:
        self.scheduled += 1
        super().schedule(event, priority, delay)


def events_scheduled(env: simpy.Environment) -> int | None:
    """How many events were scheduled on ``env`` (``None``: a plain SimPy environment does
    not say)."""
    scheduled: Any = getattr(env, "scheduled", None)
    return scheduled if isinstance(scheduled, int) else None
