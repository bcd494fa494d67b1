"""Deadlocks are reported with the waiting activities, never a silent hang."""

from __future__ import annotations

from builders import act, catch, manual, pkg, proc, route
from engine_runs import events, run

from opspec.engine.builtin_performers import ScriptedUser


def test_and_join_that_can_never_fire_is_reported_with_its_name() -> None:
    model = pkg(proc("p", [route("x", split="XOR"), "a", "b", act("sync", join="AND")],
                     [("x", "a", "true"), ("x", "b", "otherwise"), ("a", "sync"),
                      ("b", "sync")]))
    result = run(model)
    deadlock = result.summary["deadlocks"][0]
    assert deadlock["waiting"] == ["sync"]
    assert "join" in deadlock["message"]
    assert events(result, "deadlock")[0].data["waiting"] == ["sync"]
    error = result.deadlock_error()
    assert error is not None and "sync" in str(error)


def test_catch_event_no_one_throws_is_a_deadlock_when_nothing_is_scheduled() -> None:
    model = pkg(proc("p", [catch("wait_report", "message", "trg_1"), "after"],
                     [("wait_report", "after")]))
    result = run(model)
    message = result.summary["deadlocks"][0]["message"]
    assert "wait_report (message:trg_1)" in message and "nothing is scheduled" in message


def test_manual_activity_without_performer_is_reported_even_at_the_horizon() -> None:
    model = pkg(proc("p", [manual("press_button")]), proc("clock", ["tick"], start="period:60"))
    result = run(model, until=600.0)
    assert "press_button" in result.summary["deadlocks"][0]["message"]
    assert "no performer" in result.summary["deadlocks"][0]["message"]


def test_waiting_at_the_end_of_the_horizon_is_not_a_deadlock() -> None:
    model = pkg(proc("p", [manual("press_button")]), proc("clock", ["tick"], start="period:60"))
    user = ScriptedUser([])              # bound, just slow
    result = run(model, performers={"user": user}, until=600.0)
    assert result.summary["deadlocks"] == []
    assert result.summary["instances"]["open"] == 1


def test_a_run_stopped_at_its_horizon_reports_no_catch_deadlock_even_with_nothing_queued() -> None:
    """At the horizon, waiting is normal unless an activity waits for a performer that does
    not exist (Simulation.check_waiting): a catch event nobody throws is still waiting when
    the run's length is reached, even with nothing else scheduled (the clock keeps the
    run's stop queued at the horizon, as SimPy's did)."""
    model = pkg(proc("p", [catch("wait_report", "message", "trg_1"), "after"],
                     [("wait_report", "after")]))
    result = run(model, until=600.0)
    assert result.summary["deadlocks"] == []
    assert result.summary["time"] == 600.0
