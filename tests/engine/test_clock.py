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


def test_the_clock_is_a_simpy_environment_that_counts_every_event_scheduled_on_it() -> None:
    """``sim_events`` counts what SimPy schedules: each timeout, and per ``run(until)`` the
    stop event SimPy schedules and puts back once it has stopped (so ``peek`` after a run
    gives ``until``: a run stopped at its horizon is not taken for one with nothing left)."""
    clock = Clock()
    assert isinstance(clock, simpy.Environment) and clock.now == 0.0
    fired: list[float] = []
    for delay in (0.5, 2.0, 2.5):
        clock.timeout(delay).callbacks.append(lambda _e: fired.append(clock.now))
    clock.run(until=2.0)
    assert fired == [0.5] and clock.now == 2.0 and clock.peek() == 2.0
    clock.run(until=10.0)
    assert fired == [0.5, 2.0, 2.5] and clock.now == 10.0
    assert clock.scheduled == events_scheduled(clock) == 3 + 2 + 2
    assert events_scheduled(simpy.Environment()) is None


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
