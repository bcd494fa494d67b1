"""A CPU demand's end (``activities._CpuDone``): on the run's own heap and as a SimPy
timeout's callback on a shared environment, while its instance runs or is suspended."""

from __future__ import annotations

import pytest
import simpy
from builders import act, pkg, proc

from engine_runs import completed, events
from opspec.engine.simulation import Simulation


def _model() -> object:
    return pkg(proc("p", [act("compute", cpu=10.0), "after"], [("compute", "after")]))


@pytest.mark.parametrize("shared", [False, True], ids=["own-heap", "shared-simpy"])
def test_cpu_demand_ends_after_its_time(shared: bool) -> None:
    sim = Simulation(_model(), keep_trace=True, env=simpy.Environment() if shared else None)
    result = sim.run(until=30.0)
    assert completed(result) == ["compute", "after"]
    assert events(result, "activity.completed", activity="compute")[0].time == 10.0


@pytest.mark.parametrize("shared", [False, True], ids=["own-heap", "shared-simpy"])
def test_cpu_demand_ending_while_suspended_waits_for_the_resume(shared: bool) -> None:
    sim = Simulation(_model(), keep_trace=True, env=simpy.Environment() if shared else None)
    sim.run(until=5.0)
    sim.suspend(1)
    sim.run(until=20.0)
    assert events(sim.result(), "activity.completed", activity="compute") == []
    sim.resume(1)
    result = sim.run(until=30.0)
    assert completed(result) == ["compute", "after"]
    assert events(result, "activity.completed", activity="compute")[0].time == 20.0


def test_cpu_demand_of_an_instance_terminated_meanwhile_does_nothing() -> None:
    sim = Simulation(_model(), keep_trace=True)
    sim.run(until=5.0)
    sim.terminate(1)
    result = sim.run(until=30.0)
    assert completed(result) == []
