"""WfMC life cycle: defined once with `transitions`, checked by table lookup per instance."""

from __future__ import annotations

import pytest
from builders import catch, pkg, proc
from engine_runs import completed, events

from opspec.engine.lifecycle import (
    ABORTED,
    COMPLETED,
    LIFECYCLE,
    NOT_STARTED,
    RUNNING,
    SUSPENDED,
    TERMINATED,
)
from opspec.engine.simulation import Simulation
from opspec.errors import ExecutionError


@pytest.mark.parametrize(("state", "trigger", "expected"), [
    (NOT_STARTED, "start", RUNNING), (RUNNING, "suspend", SUSPENDED),
    (SUSPENDED, "resume", RUNNING), (RUNNING, "complete", COMPLETED),
    (SUSPENDED, "terminate", TERMINATED), (RUNNING, "abort", ABORTED),
], ids=lambda v: str(v))
def test_legal_transitions_follow_the_wfmc_states(state: int, trigger: str,
                                                 expected: int) -> None:
    assert LIFECYCLE.next(state, trigger) == expected


@pytest.mark.parametrize(("state", "trigger"), [
    (COMPLETED, "start"), (NOT_STARTED, "suspend"), (SUSPENDED, "complete"),
    (TERMINATED, "resume"), (RUNNING, "resume"), (ABORTED, "terminate"),
], ids=["restart-completed", "suspend-unstarted", "complete-suspended", "resume-terminated",
        "resume-running", "terminate-aborted"])
def test_illegal_transitions_are_rejected(state: int, trigger: str) -> None:
    with pytest.raises(ExecutionError, match=f"cannot {trigger}"):
        LIFECYCLE.next(state, trigger)


def _waiting_model() -> object:
    return pkg(proc("p", [catch("wait", "timer", seconds=10.0), "after"], [("wait", "after")]))


def test_suspended_instance_does_not_move_until_resumed() -> None:
    sim = Simulation(_waiting_model(), keep_trace=True)
    sim.run(until=5.0)
    sim.suspend(1)
    assert sim.instance_state(1) == "suspended"
    sim.run(until=20.0)
    assert events(sim.result(), "activity.completed", activity="wait") == []
    sim.resume(1)
    result = sim.run(until=30.0)
    assert completed(result) == ["wait", "after"]
    assert events(result, "activity.completed", activity="wait")[0].time == 20.0


def test_terminate_cancels_an_instance_and_rejects_a_second_suspend() -> None:
    sim = Simulation(_waiting_model(), keep_trace=True)
    sim.run(until=1.0)
    sim.terminate(1)
    result = sim.run(until=20.0)
    assert events(result, "process.terminated")
    assert completed(result) == []
    with pytest.raises(ExecutionError, match="not running"):
        sim.suspend(1)


def test_resuming_a_running_instance_is_illegal() -> None:
    sim = Simulation(_waiting_model())
    sim.run(until=1.0)
    with pytest.raises(ExecutionError, match="cannot resume instance 1: it is running"):
        sim.resume(1)


def test_per_instance_state_is_a_small_int_not_a_machine() -> None:
    sim = Simulation(_waiting_model())
    sim.run(until=1.0)
    inst = sim.live[1]
    assert isinstance(inst.state, int)
    assert not hasattr(inst, "__dict__")
