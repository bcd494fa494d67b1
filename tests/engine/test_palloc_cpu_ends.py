"""A CPU demand's end (``activities._CpuDone``) is used again once it has run: demands that
overlap (two branches of one instance, instances of two workflows) each get one of their own,
and a run's trace is the one it gives when every timed callback is a SimPy timeout of its own
(a plain :class:`simpy.Environment`), with instances suspended, resumed and terminated while
their demands are on the clock. A free end holds no activity instance."""

from __future__ import annotations

from typing import Any

import pytest
import simpy
from builders import act, pkg, proc

from opspec.engine.simulation import RunResult, Simulation


def _model() -> Any:
    # p: two demands at once in one instance, then one more; q: one demand overlapping p's
    return pkg(
        proc("p", [act("fork", split="AND"), act("left", cpu=0.25), act("right", cpu=0.375),
                   act("join", join="AND"), act("last", cpu=0.125)],
             [("fork", "left"), ("fork", "right"), ("left", "join"), ("right", "join"),
              ("join", "last")], start="period:1"),
        proc("q", [act("work", cpu=0.3125), "done"], [("work", "done")], start="period:0.5"))


def _rows(result: RunResult) -> list[tuple[Any, ...]]:
    assert result.trace is not None
    return [(e.time, e.kind, e.process, e.instance, e.activity) for e in result.trace]


def _run(env: simpy.Environment | None) -> tuple[Simulation, RunResult]:
    sim = Simulation(_model(), seed=1, keep_trace=True, env=env)
    sim.run(until=3.1)              # p#.. and q#.. have demands on the clock
    running = sorted(sim.live)
    sim.suspend(running[0])
    sim.terminate(running[-1])
    sim.run(until=4.6)
    sim.resume(running[0])
    return sim, sim.run(until=12.0)


@pytest.mark.parametrize("shared", [False, True], ids=["own-heap", "shared-simpy"])
def test_ends_used_again_give_the_trace_of_one_timeout_each(shared: bool) -> None:
    _, expected = _run(simpy.Environment())
    sim, got = _run(simpy.Environment() if shared else None)
    assert _rows(got) == _rows(expected)
    done = [r for r in _rows(got) if r[1] == "activity.completed" and r[4] == "last"]
    assert len(done) >= 10
    free = []
    end = sim.activities.cpu_ends
    while end is not None:
        free.append(end)
        end = end.spare
    assert 2 <= len(free) <= 4            # as many as were ever on the clock at once
    assert all(end.ai is None for end in free)
