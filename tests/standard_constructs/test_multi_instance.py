"""A multi-instance activity's completionCondition cancels the instances that remain once it
holds; a boundary timer on a multi-instance activity fires once, for the whole activity."""

from __future__ import annotations

import pytest

from .conftest import completed, kinds, run


def _names(name: str) -> list[tuple[float, str]]:
    outcome = run(name, until=60)
    assert [e.kind for e in outcome.trace if e.kind.startswith("process.")] == [
        "process.started", "process.completed"]
    return completed(outcome)


@pytest.mark.parametrize(("name", "expected"), [
    # sequential, five 1 s instances, nrOfCompletedInstances >= 2: the third never starts
    ("mi_completion_sequential.bpmn",
     [(0.0, "start"), (1.0, "each"), (2.0, "each"), (2.0, "after"), (2.0, "end")]),
    # parallel, three 10 s instances, nrOfCompletedInstances >= 1: the other two are cancelled
    # at the instant the first completes
    ("mi_completion_parallel.bpmn", [(0.0, "start"), (10.0, "each"), (10.0, "after"),
                                     (10.0, "end")]),
])
def test_completion_condition_cancels_the_remaining_instances(
        name: str, expected: list[tuple[float, str]]) -> None:
    """BPMN 2.0 (MultiInstanceLoopCharacteristics), completionCondition: "This attribute
    defines a boolean Expression that when evaluated to true, cancels the remaining Activity
    instances and produces a token." — the token moves on once, and no instance of the
    activity completes (or starts) after the condition held."""
    assert _names(name) == expected


def test_a_boundary_timer_on_a_sequential_multi_instance_activity_times_the_whole_activity(
        ) -> None:
    """BPMN 2.0 Table 10.93 (BoundaryEvent), attachedToRef: "Denotes the Activity that
    boundary Event is attached to" — the multi-instance activity, whose instances are its
    loop (§10.2.8), not each instance: three sequential 4 s instances take 12 s, so the 10 s
    interrupting timer fires (at 10 s, during the third instance), cancels the activity and
    takes its path; timed per instance it would never fire."""
    assert _names("mi_boundary_interrupting.bpmn") == [
        (0.0, "start"), (4.0, "each"), (8.0, "each"), (10.0, "late"), (10.0, "handle_late"),
        (10.0, "end_late")]


def test_a_non_interrupting_boundary_timer_fires_once_for_all_instances() -> None:
    """BPMN 2.0 Table 10.93 (as above: the event belongs to the Activity, not to each of its
    instances). Three parallel 10 s instances with a non-interrupting 5 s timer: its path runs
    once at 5 s (not once per instance), and the activity completes at 10 s."""
    names = _names("mi_boundary_noninterrupting.bpmn")
    assert [n for n in names if n[1] == "handle_late"] == [(5.0, "handle_late")]
    assert names[-2:] == [(10.0, "after"), (10.0, "end")]


def test_the_instances_cancelled_leave_no_token_behind() -> None:
    """Every token is accounted for: the instance completes, nothing is left waiting."""
    for name in ("mi_completion_parallel.bpmn", "mi_boundary_interrupting.bpmn"):
        outcome = run(name, until=60)
        assert outcome.summary["instances"]["open"] == 0
        assert not kinds(outcome, "deadlock")
