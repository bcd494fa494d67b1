"""The engine's own clock (opspec/engine/clock.py) keeps the order SimPy gave the engine's
events, so traces did not change when the engine stopped running on SimPy: by time, then in
the order scheduled; ``run(until)`` stops before what falls at ``until``."""

from __future__ import annotations

import math

import pytest
import simpy

from opspec.engine.clock import Clock, EmptySchedule


def test_callbacks_fire_by_time_then_in_the_order_scheduled_as_simpy_timeouts_do() -> None:
    """The same delays scheduled on SimPy (``env.timeout``) and on the clock, some at equal
    times and some scheduled from inside a callback, fire in the same order."""
    delays = [3.0, 1.0, 1.0, 0.0, 3.0, 2.0, 0.0]
    orders: list[list[str]] = []
    env = simpy.Environment()
    simpy_order: list[str] = []

    def on_simpy(name: str, then: float | None) -> None:
        simpy_order.append(name)
        if then is not None:
            env.timeout(then).callbacks.append(lambda _e: on_simpy(name + "'", None))

    for n, delay in enumerate(delays):
        env.timeout(delay).callbacks.append(
            lambda _e, n=n: on_simpy(f"e{n}", 1.0 if n % 3 == 0 else None))
    env.run()
    orders.append(simpy_order)

    clock = Clock()
    clock_order: list[str] = []

    def on_clock(name: str, then: float | None) -> None:
        clock_order.append(name)
        if then is not None:
            clock.after(then, lambda: on_clock(name + "'", None))

    for n, delay in enumerate(delays):
        clock.after(delay, lambda n=n: on_clock(f"e{n}", 1.0 if n % 3 == 0 else None))
    clock.run()
    orders.append(clock_order)
    assert orders[0] == orders[1]
    assert clock.now == env.now == 4.0
    assert clock.scheduled == 10


def test_run_until_stops_before_what_falls_at_until_and_moves_the_clock_there() -> None:
    clock = Clock()
    fired: list[float] = []
    for delay in (0.5, 2.0, 2.5):
        clock.after(delay, lambda: fired.append(clock.now))
    clock.run(until=2.0)
    assert fired == [0.5] and clock.now == 2.0
    clock.run(until=10.0)
    assert fired == [0.5, 2.0, 2.5] and clock.now == 10.0
    # as SimPy counts its event ids: three callbacks, and per run(until) its stop event and
    # the stop put back on the queue
    assert clock.scheduled == 7


def test_after_a_run_until_the_queue_looks_as_simpys_does() -> None:
    """SimPy leaves its stop event queued at ``until`` after ``run(until)``: ``peek`` gives
    ``until`` (so a run stopped at its horizon is not taken for one where nothing is
    scheduled any more), and the next ``step`` takes it without doing anything."""
    env = simpy.Environment()
    clock = Clock()
    seen_env: list[float] = []
    seen_clock: list[float] = []
    env.timeout(5.0).callbacks.append(lambda _e: seen_env.append(env.now))
    clock.after(5.0, lambda: seen_clock.append(clock.now))
    env.run(until=3.0)
    clock.run(until=3.0)
    assert clock.peek() == env.peek() == 3.0
    env.step()
    clock.step()
    assert clock.now == env.now == 3.0 and seen_clock == seen_env == []
    assert clock.peek() == env.peek() == 5.0
    env.run(until=8.0)
    clock.run(until=8.0)
    assert seen_clock == seen_env == [5.0]
    assert clock.peek() == env.peek() == 8.0
    assert clock.scheduled == int(repr(env._eid)[6:-1])     # SimPy's next event id


def test_run_until_the_past_or_present_is_refused_and_step_on_nothing_raises() -> None:
    clock = Clock(initial_time=5.0)
    with pytest.raises(ValueError, match="after the current simulated time"):
        clock.run(until=5.0)
    with pytest.raises(EmptySchedule):
        clock.step()
    clock.after(1.0, lambda: None)
    clock.step()
    assert clock.now == 6.0 and clock.pending() == 0 and clock.peek() == math.inf


def test_the_clock_stops_where_simpy_stops_to_the_last_bit() -> None:
    """``run(until)`` leaves the clock at ``now + (until - now)``, the float SimPy's stop
    event is scheduled at (which may differ from ``until`` in the last bit)."""
    env = simpy.Environment(initial_time=0.1)
    clock = Clock(initial_time=0.1)
    for until in (0.3, 0.7, 1e9 + 0.1):
        env.run(until=until)
        clock.run(until=until)
        assert clock.now == env.now
