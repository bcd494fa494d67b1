"""A run's own timer heap (opspec/engine/timers.py) gives the run SimPy gives it with one
timeout per timed callback: the same trace, event for event, in the same order, whatever
else is scheduled on the clock at the same instants, stepped or run, and the same
``sim_events``.

The reference is the engine on a plain :class:`simpy.Environment`, where every timed callback
is still a SimPy timeout of its own (``Timers.heaped`` is false there): SimPy orders events
by ``(time, priority, event id)``, the id counting up as events are scheduled."""

from __future__ import annotations

from collections.abc import Callable, Generator
from pathlib import Path
from typing import Any

import pytest
import simpy
from builders import catch, manual, pkg, proc

from opspec.engine.builtin_performers import ScriptedUser
from opspec.engine.clock import Clock
from opspec.engine.compiled import compile_package
from opspec.engine.lanes import user_lane
from opspec.engine.random import user_stream
from opspec.engine.simulation import RunResult, Simulation
from opspec.engine.timers import exact_delay
from opspec.usermodels.loader import load_user_model
from opspec.xpdl.open_spec import open_spec

SPECS = Path(__file__).resolve().parents[2] / "specs"
DAY = 86400.0


class _Counted(simpy.Environment):
    """A plain SimPy environment (so the engine schedules one timeout per timed callback)
    that counts what is scheduled on it, as SimPy's event ids do."""

    def __init__(self) -> None:
        super().__init__(0.0)
        self.every = 0

    def schedule(self, event: simpy.Event, priority: Any = simpy.events.NORMAL,
                 delay: Any = 0) -> None:
        self.every += 1
        super().schedule(event, priority, delay)


class _CountedClock(Clock):
    def __init__(self) -> None:
        super().__init__()
        self.every = 0

    def schedule(self, event: simpy.Event, priority: Any = simpy.events.NORMAL,
                 delay: Any = 0) -> None:
        self.every += 1
        super().schedule(event, priority, delay)


def _rows(result: RunResult) -> list[tuple[Any, ...]]:
    assert result.trace is not None
    return [(e.time, e.kind, e.process, e.instance, e.activity, dict(e.data))
            for e in result.trace]


def _dispenser(env: simpy.Environment, seed: int = 3, spec: str = "medication_dispenser.xpdl"
               ) -> Simulation:
    compiled = compile_package(open_spec(SPECS / spec))
    model = load_user_model(SPECS / "medication_dispenser.users.toml")
    user = model.performer(user_stream(seed, 0))
    return Simulation(compiled, performers={n: user for n in user_lane(compiled).bind_names},
                      seed=seed, keep_trace=True, env=env)


@pytest.mark.parametrize("spec", ["medication_dispenser.xpdl", "medication_dispenser.bpmn"])
def test_the_dispenser_runs_on_the_heap_as_on_one_timeout_per_callback(spec: str) -> None:
    """Three days in two ``run(until)`` calls: the same trace, and ``sim_events`` the
    number of events SimPy schedules when every timed callback is a timeout of its own
    (the heap schedules a small part of them on SimPy)."""
    plain = _Counted()
    direct = _dispenser(plain, spec=spec)
    direct.run(until=DAY)
    expected = direct.run(until=3 * DAY)
    clock = _CountedClock()
    heaped = _dispenser(clock, spec=spec)
    assert heaped.heaped and not direct.heaped
    heaped.run(until=DAY)
    got = heaped.run(until=3 * DAY)
    assert len(_rows(got)) > 100
    assert _rows(got) == _rows(expected)
    assert got.summary["sim_events"] == plain.every
    assert got.metrics == expected.metrics
    assert clock.every < plain.every / 4


def test_stepping_runs_one_timed_callback_per_step_in_simpys_order() -> None:
    """The walkthrough and wall-clock runs step SimPy themselves: stepped, the heap runs one
    callback per driver, so what is seen between steps is what was seen before."""
    runs = []
    for env in (simpy.Environment(0.0), Clock()):
        sim = _dispenser(env)
        seen = []
        while sim.peek() < DAY:
            sim.step()
            seen.append((env.now, sim.seq))
        runs.append((_rows(sim.result()), sorted(set(seen))))
    assert runs[0] == runs[1]
    assert len(runs[0][0]) > 20


def _waiter(env: simpy.Environment, answers: list[float]) -> Simulation:
    """Workflow ``p`` waits for message ``go`` (``w``) and then for its user twice (``a``,
    ``b``), who answers after the given delays; ``q`` waits for message ``ping``."""
    steps = [(delay, f"complete {name}") for delay, name in zip(answers, "ab", strict=True)]
    model = pkg(proc("p", [catch("w", "message", "go"), manual("a"), manual("b")],
                     [("w", "a"), ("a", "b")]),
                proc("q", [catch("x", "message", "ping")]))
    return Simulation(model, performers={"user": ScriptedUser(steps)}, keep_trace=True,
                      env=env)


def _caller(env: simpy.Environment, sim: Simulation, at: list[tuple[float, str]]
            ) -> Generator[Any, Any, None]:
    last = 0.0
    for when, message in at:
        yield env.timeout(when - last)
        last = when
        sim.raise_trigger(message)


def _shared_instants(env: simpy.Environment, before_boot: bool) -> list[tuple[Any, ...]]:
    """A SimPy process of the caller's raises messages at exactly the instants the user
    answers (5 and 12 s), and a listener schedules SimPy events of its own at the instant
    it hears of each answer (delay 0: they fall between the engine's callbacks there)."""
    sim = _waiter(env, [5.0, 7.0])
    if not before_boot:
        sim.boot()
    env.process(_caller(env, sim, [(0.0, "go"), (5.0, "ping"), (12.0, "ping")]))
    heard: list[float] = []

    def listener(event: Any) -> None:
        if event.kind == "activity.completed" and event.activity in ("a", "b"):
            env.timeout(0).callbacks.append(lambda _e: heard.append(float(env.now)))
            env.process(_caller(env, sim, [(0.0, "ping")]))
    sim.listeners.append(listener)
    sim.full.append((listener, None))
    result = sim.run(until=30.0)
    assert heard == [5.0, 12.0]
    return _rows(result)


@pytest.mark.parametrize("before_boot", [True, False])
def test_events_of_others_at_the_same_instants_keep_simpys_order(before_boot: bool) -> None:
    """SimPy runs the events of one instant in the order they were scheduled, the engine's
    and anyone else's alike; the heap gives its callbacks due at an instant SimPy timeouts
    of their own when something else is scheduled at that instant, so the order holds."""
    direct = _shared_instants(simpy.Environment(0.0), before_boot)
    heaped = _shared_instants(Clock(), before_boot)
    assert heaped == direct
    kinds = [(row[0], row[1], row[4]) for row in heaped]
    assert (5.0, "activity.completed", "x") in kinds and (12.0, "activity.completed", "a") \
        not in kinds


def test_the_clock_reads_the_runs_time_while_the_run_is_ahead_of_simpy() -> None:
    """Inside ``run`` the heap may go ahead of SimPy's clock; whoever reads ``env.now`` from
    a callback then (a performer, a listener, a mode loader) reads the run's time, and
    what they schedule on the clock counts from it."""
    clock = Clock()
    sim = _waiter(clock, [5.0, 7.0])
    seen: list[tuple[float, float]] = []
    timed: list[float] = []

    def listener(event: Any) -> None:
        if event.kind == "activity.completed" and event.activity in ("a", "b"):
            seen.append((event.time, float(clock.now)))
            clock.timeout(1.5).callbacks.append(lambda _e: timed.append(float(clock.now)))
    sim.listeners.append(listener)
    sim.full.append((listener, None))
    sim.boot()
    sim.raise_trigger("go")
    sim.run(until=30.0)
    assert seen == [(5.0, 5.0), (12.0, 12.0)]
    assert timed == [6.5, 13.5] and clock.now == 30.0


def test_a_run_to_the_end_stops_the_clock_at_its_last_event() -> None:
    """``run()`` with no end runs until nothing is scheduled; the clock stands at the last
    timed callback, a lost race's included, as SimPy's did."""
    ends = []
    for env in (simpy.Environment(0.0), Clock()):
        sim = _waiter(env, [5.0, 7.0])
        sim.boot()
        sim.raise_trigger("go")
        result = sim.run()
        ends.append((env.now, result.summary["time"], _rows(result)))
    assert ends[0] == ends[1] and ends[0][0] == 12.0


@pytest.mark.parametrize(("base", "target"), [(0.1, 0.3), (1e9 + 0.1, 1e9 + 0.7),
                                              (3.0, 3.0), (0.0, 86400.0 * 30 + 1e-7),
                                              (12345.678, 98765.4321)])
def test_the_driver_falls_exactly_at_its_entrys_time(base: float, target: float) -> None:
    """SimPy adds the delay to its clock; ``exact_delay`` gives the delay whose sum is the
    entry's time to the bit (``0.1 + (0.3 - 0.1)`` is not ``0.3``)."""
    delay = exact_delay(base, target)
    assert delay >= 0.0 and base + delay == target


def test_a_second_run_on_a_clock_uses_one_timeout_per_callback() -> None:
    """One run drives a clock; another run on the same clock schedules its timeouts on
    SimPy directly (the clock reports them to the first as anyone else's)."""
    clock = Clock()
    first = _waiter(clock, [5.0, 7.0])
    second = _waiter(clock, [2.0, 3.0])
    assert first.heaped and not second.heaped
    for sim in (first, second):
        sim.boot()
        sim.raise_trigger("go")
    clock.run(until=20.0)
    done: Callable[[Simulation], list[tuple[float, str | None]]] = lambda sim: [
        (row[0], row[4]) for row in _rows(sim.result()) if row[1] == "activity.completed"]
    assert done(first) == [(0.0, "w"), (5.0, "a"), (12.0, "b")]
    assert done(second) == [(0.0, "w"), (2.0, "a"), (5.0, "b")]
