"""The engine runs on SimPy (opspec/engine/clock.py), through its public API only: a run's
clock is a :class:`simpy.Environment` (by default a :class:`Clock`, which counts its events),
and a caller may hand the engine a plain SimPy environment shared by several households."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import simpy

from opspec.engine.clock import Clock, EmptySchedule, events_scheduled
from opspec.engine.compiled import compile_package
from opspec.engine.lanes import user_lane
from opspec.engine.random import user_stream
from opspec.engine.simulation import Simulation
from opspec.usermodels.loader import load_user_model
from opspec.xpdl.open_spec import open_spec

SPECS = Path(__file__).resolve().parents[2] / "specs"
DAY = 86400.0


def test_the_clock_is_a_simpy_environment_that_counts_the_stop_events_of_run_until() -> None:
    """Per ``run(until)`` SimPy schedules a stop event and puts it back once it has stopped
    (so ``peek`` after a run gives ``until``: a run stopped at its horizon is not taken for
    one with nothing left); the clock counts those, the run its own timeouts."""
    clock = Clock()
    assert isinstance(clock, simpy.Environment) and clock.now == 0.0
    fired: list[float] = []
    for delay in (0.5, 2.0, 2.5):
        clock.timeout(delay).callbacks.append(lambda _e: fired.append(clock.now))
    clock.run(until=2.0)
    assert fired == [0.5] and clock.now == 2.0 and clock.peek() == 2.0
    clock.run(until=10.0)
    assert fired == [0.5, 2.0, 2.5] and clock.now == 10.0
    assert clock.scheduled == events_scheduled(clock) == 2 + 2
    assert events_scheduled(simpy.Environment()) is None


class _SchedulingCounted(simpy.Environment):
    """A plain SimPy environment counting every event scheduled on it, as SimPy's event ids
    do: on it the engine makes every timed callback a SimPy timeout of its own (on a
    :class:`Clock` it keeps them on its own heap, opspec/engine/timers.py)."""

    def __init__(self) -> None:
        super().__init__(0.0)
        self.every = 0

    def schedule(self, event: simpy.Event, priority: simpy.events.EventPriority = simpy.events.NORMAL,
                 delay: float = 0) -> None:
        self.every += 1
        super().schedule(event, priority, delay)


def test_sim_events_is_every_event_simpy_scheduled_for_the_run() -> None:
    """"N simulation events" is the number of events SimPy schedules for the run when every
    timed callback is a timeout of its own: the run's timeouts (durations, deadlines, the
    user's answers, periodic timers) and the two events of each ``run(until)``, over several
    runs of one simulation (on the run's own :class:`Clock`, where most of them never become
    SimPy events, the same number)."""
    compiled = compile_package(open_spec(SPECS / "medication_dispenser.xpdl"))
    model = load_user_model(SPECS / "medication_dispenser.users.toml")
    counts = []
    for env in (_SchedulingCounted(), Clock()):
        user = model.performer(user_stream(3, 0))
        sim = Simulation(compiled, performers={n: user for n in user_lane(compiled).bind_names},
                         seed=3, env=env)
        sim.run(until=DAY)
        counts.append(sim.run(until=3 * DAY).summary["sim_events"])
        if isinstance(env, _SchedulingCounted):
            counts[-1] = env.every
    assert counts[0] == counts[1] > 30


def test_time_zero_is_a_float_and_step_on_nothing_raises_simpys_empty_schedule() -> None:
    """A trace writes the start of a run as ``0.0`` (SimPy's own default is the int 0)."""
    clock = Clock()
    assert type(clock.now) is float
    assert EmptySchedule is simpy.core.EmptySchedule
    with pytest.raises(EmptySchedule):
        clock.step()
    assert clock.peek() == math.inf


def _household_runs(shared: bool) -> list[list[tuple[float, str, str | None]]]:
    compiled = compile_package(open_spec(SPECS / "medication_dispenser.xpdl"))
    model = load_user_model(SPECS / "medication_dispenser.users.toml")
    names = user_lane(compiled).bind_names
    env = simpy.Environment() if shared else None
    sims = []
    for u in range(3):
        user = model.performer(user_stream(7, u))
        sims.append(Simulation(compiled, performers={n: user for n in names}, seed=7,
                               scope=(u,), keep_trace=True, env=env))
    if env is not None:            # start every household, then run the one clock
        for sim in sims:
            sim.boot()
        env.run(until=2 * DAY)
    results = [sim.run(until=2 * DAY) for sim in sims]     # shared: only ends each run
    if env is not None:
        assert all(r.summary["sim_events"] is None for r in results)   # a plain environment
    return [[(e.time, e.kind, e.activity) for e in r.trace] for r in results]


def test_households_sharing_one_plain_simpy_environment_run_as_they_run_alone() -> None:
    """Each household on a shared clock keeps its own data, random streams and performers,
    so its trace is the one it has run alone (SimPy orders each household's own events as it
    scheduled them)."""
    alone = _household_runs(shared=False)
    together = _household_runs(shared=True)
    assert all(len(trace) > 50 for trace in alone)
    assert together == alone


def _waiter() -> Simulation:
    """A workflow that waits for message ``go`` and then for its user (``a``)."""
    from builders import catch, manual, pkg, proc

    from opspec.engine.builtin_performers import ScriptedUser

    return Simulation(pkg(proc("p", [catch("w", "message", "go"), manual("a")], [("w", "a")])),
                      performers={"user": ScriptedUser([])}, keep_trace=True,
                      env=simpy.Environment())


def test_the_engine_reads_the_time_when_called_from_outside_its_own_callbacks() -> None:
    """The engine keeps the time it last read from ``env.now``; a call from a SimPy process
    of the caller's (no engine event moved the clock) and a start after ``run(until)`` (the
    stop event moved it) must see the clock where it is, not where the engine last was."""
    sim = _waiter()
    env = sim.env
    sim.run(until=5.0)                       # nothing of the engine's happens by then

    def caller() -> object:
        yield env.timeout(7.0)
        sim.raise_trigger("go")              # at 12, from a process the engine never saw
    env.process(caller())
    env.run(until=20.0)
    started = sim.start("p")                 # at 20, after a run(until) of the caller's
    trace = sim.result().trace
    assert trace is not None
    times = {(e.kind, e.activity, e.instance): e.time for e in trace}
    assert times[("activity.completed", "w", 1)] == 12.0
    assert times[("process.started", None, started)] == 20.0
    assert sim.session.now == 20.0
