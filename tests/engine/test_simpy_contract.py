"""The engine stands on three private details of SimPy (its event queue, event counter and
clock: opspec/engine/wakeup.py, interpreter.py, simulation.py) for speed. pyproject.toml pins
SimPy to the versions these tests pass on; a SimPy that changes them fails here, by name,
instead of silently reordering events."""

from __future__ import annotations

import itertools
from importlib.metadata import version

import simpy

from opspec.engine.wakeup import Wakeups


def test_the_installed_simpy_is_a_pinned_version() -> None:
    major, minor = (int(x) for x in version("simpy").split(".")[:2])
    assert (major, minor) == (4, 1)


def test_the_environment_keeps_a_heap_of_time_priority_id_event_tuples() -> None:
    env = simpy.Environment(initial_time=5.0)
    assert env._now == env.now == 5.0
    assert isinstance(env._eid, itertools.count)
    event = env.timeout(2.0)
    [(at, priority, eid, queued)] = env._queue
    assert (at, queued) == (7.0, event)
    assert isinstance(priority, int) and isinstance(eid, int)


def test_a_wakeup_fires_exactly_where_a_timeout_would() -> None:
    """Interleaved timeouts and wakeups at equal and different times fire in the same order
    as if every one were an env.timeout (time, then scheduling order)."""
    order: list[str] = []
    env = simpy.Environment()
    wakeups = Wakeups(env)
    for n, delay in enumerate([3.0, 1.0, 1.0, 0.0, 3.0, 2.0]):
        name = f"{'w' if n % 2 else 't'}{n}"
        if n % 2:
            wakeups.after(delay, lambda _e, name=name: order.append(name))
        else:
            env.timeout(delay).callbacks.append(lambda _e, name=name: order.append(name))
    env.run()
    assert order == ["w3", "w1", "t2", "w5", "t0", "t4"]
    assert env.now == 3.0
