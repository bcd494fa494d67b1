"""A workflow's deadline (``opspec:Deadline``) whose instance has ended by the time it falls
due is dropped before it reaches the run's timer heap (``Timers.schedule_droppable``):
nothing to push, pop or drain. Nothing a user sees changes: a deadline whose instance still
runs fires at its time and in its place, a run to the end stops where it stopped, a stepped
run takes the steps it took, ``sim_events`` counts what it counted, and the zero-time guard
stops the runs it stopped, at the same step.

The reference is the engine on a plain :class:`simpy.Environment`, where every timed callback
is a SimPy timeout of its own (nothing dropped, nothing on a heap)."""

from __future__ import annotations

from typing import Any

import pytest
import simpy
from builders import act, catch, pkg, proc, subflow
from test_timer_heap import _Counted

from opspec.engine.clock import Clock
from opspec.engine.process_deadlines import _Deadline
from opspec.engine.simulation import RunResult, Simulation
from opspec.errors import ZeroTimeCycleError
from opspec.model import Loop

# binary fractions: the sums are exact. The deadlines fall between the ticker's instants
# (multiples of 1/16 s) and apart from each other, so nothing else runs at their instants.
QUICK = 0.125        # ``quick`` waits this long, well within its deadline
SLOW = 0.375         # ``slow`` waits this long, past its deadline
DEADLINE = {"quick": 9 / 32, "slow": 11 / 32}


def _package() -> Any:
    return pkg(proc("quick", [catch("w", "timer", seconds=QUICK)], start="period:0.5",
                    deadline=DEADLINE["quick"]),
               proc("slow", [catch("w", "timer", seconds=SLOW)], start="period:1",
                    deadline=DEADLINE["slow"]),
               proc("ticker", ["tick"], start="period:0.0625"))


def _rows(result: RunResult) -> list[tuple[Any, ...]]:
    assert result.trace is not None
    return [(e.time, e.kind, e.process, e.instance, e.activity, dict(e.data))
            for e in result.trace]


def _deadlines_on_heap(sim: Simulation) -> list[Any]:
    entries = [item[2] if isinstance(item, tuple) else item for item in sim.heap]
    return [entry for entry in entries if isinstance(entry, _Deadline)]


def test_a_deadline_whose_instance_ended_never_reaches_the_heap() -> None:
    """Watched at every trace event: no deadline of an ended instance is ever on the heap
    (``quick``'s are all dropped; armed as each instance started, they sat there until they
    fell due), while ``slow``'s, whose instances overrun them, expire at exactly start +
    deadline, in the same trace as with a SimPy timeout each."""
    plain = _Counted()
    expected = Simulation(_package(), seed=5, keep_trace=True, env=plain).run(until=20.0)
    sim = Simulation(_package(), seed=5, keep_trace=True)
    watched: list[float] = []

    def watch(event: Any) -> None:
        for entry in _deadlines_on_heap(sim):
            assert entry.inst.state in (1, 2), "the deadline of an ended instance"
        watched.append(event.time)
    sim.listeners.append(watch)
    sim.full.append((watch, None))
    got = sim.run(until=20.0)
    assert sim.heaped
    assert _rows(got) == _rows(expected)
    assert got.summary["sim_events"] == plain.every
    assert len(watched) > 1000
    started = {r[3]: (r[2], r[0]) for r in _rows(got) if r[1] == "process.started"}
    expired = [(r[0], r[3]) for r in _rows(got) if r[1] == "deadline.expired"]
    assert expired == sorted((at + DEADLINE["slow"], iid) for iid, (pid, at) in started.items()
                             if pid == "slow" and at + DEADLINE["slow"] < 20.0)
    assert len(expired) == 20
    assert sum(1 for pid, _at in started.values() if pid == "quick") == 40


def test_a_run_to_the_end_still_stops_at_the_last_deadline() -> None:
    """``run()`` with no end stops the clock at the last timed callback, a deadline whose
    instance ended long before included, as with a SimPy timeout each."""
    ends = []
    for env in (simpy.Environment(0.0), Clock()):
        sim = Simulation(pkg(proc("p", [catch("w", "timer", seconds=1.0)], deadline=5.0)),
                         keep_trace=True, env=env)
        result = sim.run()
        ends.append((float(env.now), result.summary["time"], _rows(result)))
    assert ends[0] == ends[1]
    assert ends[0][0] == 5.0


def test_stepping_takes_the_steps_it_took() -> None:
    """Stepped (the walkthrough, wall-clock runs), every deadline is a step of its own at its
    time, as a SimPy timeout each makes it: what is seen between steps is the same."""
    runs = []
    for env in (simpy.Environment(0.0), Clock()):
        sim = Simulation(_package(), seed=5, keep_trace=True, env=env)
        seen = []
        while sim.peek() < 5.0:
            sim.step()
            seen.append((float(env.now), sim.seq))
        runs.append((_rows(sim.result()), sorted(set(seen))))
    assert runs[0] == runs[1]
    assert any(row[1] == "deadline.expired" for row in runs[0][0])


SPINS = 2500         # past the limit, the guard samples 2,000 steps before it stops a run


def _burst(limit: int, env: simpy.Environment | None, monkeypatch: pytest.MonkeyPatch
           ) -> tuple[float | None, str, int]:
    """``main`` starts ``burst`` and ends at once; its deadline falls due at exactly the
    instant ``burst`` wakes to spin, and before it (armed first): the deadline's drain is a
    step of that instant for the zero-time guard. (Both start on a timer, and ``ticker``
    runs before that instant: the run reaches it going through its own instants, where
    deadlines are dropped.)"""
    monkeypatch.setenv("OPSPEC_MAX_INSTANT_STEPS", str(limit))
    model = pkg(proc("main", [subflow("s", "burst", asynchronous=True)], start="period:10",
                     deadline=0.5),
                proc("burst", [catch("w", "timer", seconds=0.5),
                               act("spin", loop=Loop(maximum=SPINS))], [("w", "spin")]),
                proc("ticker", ["tick"], start="period:0.375"))
    sim = Simulation(model, keep_trace=True, env=env)
    try:
        sim.run(until=3.0)
    except ZeroTimeCycleError as error:
        assert sim.memory is not None
        return error.sim_time, str(error), len(sim.memory.events)
    assert sim.memory is not None
    return None, "", len(sim.memory.events)


def test_the_zero_time_guard_counts_a_deadline_at_a_busy_instant(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A deadline whose instance ended, due at an instant where other work runs, still
    counts for the guard: at each limit around the one where the burst is just stopped, the
    same decision, at the same step (the same message, the same events before it)."""
    low, high = 1, SPINS * 4            # the highest limit at which the burst is stopped
    while low < high:
        middle = (low + high + 1) // 2
        if _burst(middle, simpy.Environment(0.0), monkeypatch)[0] is not None:
            low = middle
        else:
            high = middle - 1
    edge = low
    assert _burst(edge, simpy.Environment(0.0), monkeypatch)[0] == 0.5
    for limit in range(edge - 2, edge + 3):
        assert _burst(limit, Clock(), monkeypatch) == _burst(limit, simpy.Environment(0.0),
                                                            monkeypatch)
