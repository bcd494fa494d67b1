"""A boundary timer with a timeCycle fires at every cycle while its activity runs when it is
non-interrupting, and once (cancelling the activity) when it is interrupting."""

from __future__ import annotations

from .conftest import completed, run


def _path(name: str) -> list[tuple[float, str]]:
    outcome = run(name, until=7200)
    assert [e.kind for e in outcome.trace if e.kind.startswith("process.")] == [
        "process.started", "process.completed"]
    return [c for c in completed(outcome) if c[1] in ("remind", "work", "end")]


def test_non_interrupting_cycle_fires_at_every_cycle_while_the_activity_runs() -> None:
    """BPMN 2.0 §10.4.5, Table 10.101 (TimerEventDefinition): "The return type of the
    attribute timeCycle MUST conform to the ISO-8601 format for recurring time interval
    representations"; Table 10.93 (BoundaryEvent, cancelActivity): "If the Activity is not
    cancelled, multiple instances of that handler can run concurrently."

    A cycle R/PT10M (unbounded repetitions of ten minutes) on an activity that runs 35 min
    fires at 10, 20 and 30 min, then no more (the activity has completed); each firing runs
    the boundary path once, beside the activity."""
    assert _path("boundary_cycle_noninterrupting.bpmn") == [
        (600.0, "remind"), (1200.0, "remind"), (1800.0, "remind"),
        (2100.0, "work"), (2100.0, "end")]


def test_the_same_in_xpdl() -> None:
    """XPDL 2.1 takes its TriggerTimer TimeCycle from BPMN (an ISO 8601 recurring interval);
    a timer IntermediateEvent attached to an activity (Target) that does not interrupt it
    (Interrupting="false", XPDL 2.2's attribute) fires at every cycle as the BPMN one does."""
    assert _path("boundary_cycle_noninterrupting.xpdl") == [
        (600.0, "remind"), (1200.0, "remind"), (1800.0, "remind"),
        (2100.0, "work"), (2100.0, "end")]


def test_the_repetition_count_bounds_the_firings() -> None:
    """BPMN 2.0 Table 10.101: timeCycle is an "ISO-8601 … recurring time interval"; in ISO
    8601 "Rn/duration" is n repetitions of the interval: "R2/PT10M" is two repetitions of ten
    minutes — two firings, at 10 and 20 min, though the activity runs
    on to 35 min."""
    assert _path("boundary_cycle_noninterrupting_r2.bpmn") == [
        (600.0, "remind"), (1200.0, "remind"), (2100.0, "work"), (2100.0, "end")]


def test_interrupting_cycle_fires_once_and_cancels_the_activity() -> None:
    """BPMN 2.0 Table 10.93 (BoundaryEvent): "cancelActivity: Denotes whether the Activity
    should be cancelled or not" — an interrupting cycle cancels its activity when it first
    fires, so its first cycle is its only firing: the activity is cancelled at 10 min and never completes."""
    assert _path("boundary_cycle_interrupting.bpmn") == [(600.0, "remind")]
