"""An escalation end event or intermediate throw escalation event is caught by the nearest
enclosing boundary escalation event (the one for its escalationCode, else one without
escalationRef): an interrupting one cancels that sub-process and takes its flow, a
non-interrupting one starts its flow while the sub-process goes on; an escalation nothing
catches changes nothing (unlike an error, the instance does not fail)."""

from __future__ import annotations

from opspec.xpdl.validate import validate_spec

from .conftest import DATA, completed, kinds, run


def test_an_interrupting_boundary_event_for_the_escalation_code_catches_it() -> None:
    """BPMN 2.0 §10.4.1: "A trigger that is propagated is forwarded from the location where
    the Event has been thrown to the innermost enclosing scope instance (e.g., Process level)
    which has an attached Event being able to catch the trigger." Table 8.42 (escalationCode),
    for an event on the boundary of an Activity: "If there is an escalationCode, then only an
    Escalation that matches the escalationCode SHALL trigger the Event." BoundaryEvent
    cancelActivity (default true): "Denotes whether the Activity should be cancelled or not".

    "Late" is thrown by the end event in "inner" (no boundary event), so "outer" catches it
    with its interrupting event for "Late" — not with the catch-all, which comes first in the
    file. "outer" is cancelled at t=1 with everything in it ("slow", 10 s, never completes),
    its normal flow ("after") is not taken, and the catch-all never fires."""
    outcome = run("escalation_end_event.bpmn", until=60, params={"code": 1})
    assert completed(outcome)[-4:] == [(1.0, name) for name in
                                       ("throw_late", "catch_late", "fix_late", "end_late")]
    done = {name for _t, name in completed(outcome)}
    assert not done & {"slow", "outer", "inner", "after", "catch_any", "note_low"}
    assert len(kinds(outcome, "process.completed")) == 1
    assert not outcome.summary["faults"]


def test_a_non_interrupting_catch_all_lets_the_sub_process_go_on() -> None:
    """BPMN 2.0 Table 8.42 (escalationCode), on the boundary: "If there is no escalationCode,
    then any Escalation SHALL trigger the Event." Table 10.88 (End Event types), Escalation:
    "This type of End indicates that an Escalation should be triggered. Other active threads
    are not affected by this and continue to be executed." BoundaryEvent cancelActivity: "If
    the Activity is not cancelled, multiple instances of that handler can run concurrently."

    "Low" has no boundary event of its own, so the catch-all (cancelActivity="false") of
    "outer" takes it at t=1 and "note_low" runs, while "outer" goes on: its branch "slow"
    completes at t=10, then "outer" itself and its normal flow ("after", "end")."""
    outcome = run("escalation_end_event.bpmn", until=60, params={"code": 2})
    done = completed(outcome)
    assert [name for _t, name in done if name in {"throw_low", "catch_any", "note_low",
                                                     "end_low"}] == [
        "throw_low", "catch_any", "note_low", "end_low"]
    times = dict((name, t) for t, name in done)
    assert times["note_low"] == 1.0 and times["inner"] == 1.0
    assert times["slow"] == times["outer"] == times["after"] == times["end"] == 10.0
    assert "catch_late" not in times and "fix_late" not in times
    assert len(kinds(outcome, "process.completed")) == 1


def test_without_an_escalation_no_boundary_event_fires() -> None:
    """The same file when no escalation end event is reached (code 3): "outer" completes when
    "slow" does and the normal flow goes on; neither boundary escalation event fires."""
    outcome = run("escalation_end_event.bpmn", until=60, params={"code": 3})
    names = [name for _t, name in completed(outcome)]
    assert names[-3:] == ["outer", "after", "end"]
    assert not {"catch_late", "catch_any"} & set(names)


def test_an_intermediate_throw_is_caught_and_an_uncaught_escalation_changes_nothing() -> None:
    """BPMN 2.0 §10.4.1: "If no catching Event is found for an error or escalation trigger,
    this trigger is unresolved." — and unlike an error end event (Table 10.88: for an
    Error, "All currently active threads in the particular Sub-Process are terminated"), an
    escalation leaves the other threads alone. §10.4.4 (Intermediate Events in normal flow):
    the Escalation Intermediate Event "raises an Escalation"; the token then goes on.

    "raise_notice" is caught by the non-interrupting "catch_notice" of "sub" ("tell" runs at
    t=0) and "sub" goes on; "raise_other" (t=2) and the process-level end event "top_throw"
    (t=0) throw "Other", which nothing catches: the paths go on, "sub" completes at t=3 and
    the instance completes, without a fault."""
    outcome = run("escalation_throw.bpmn", until=60)
    times = {name: t for t, name in completed(outcome)}
    assert times["raise_notice"] == 0.0 and times["catch_notice"] == 0.0
    assert times["tell"] == 0.0 and times["told"] == 0.0
    assert times["raise_other"] == 2.0 and times["go_on"] == 3.0
    assert times["sub"] == 3.0 and times["end"] == 3.0 and times["top_throw"] == 0.0
    assert [e.process for e in kinds(outcome, "process.completed")] == ["p"]
    assert not kinds(outcome, "process.aborted") and not outcome.summary["faults"]


def test_an_escalation_crosses_a_call_activity_whose_process_goes_on() -> None:
    """BPMN 2.0 §10.4.1 (as above: "forwarded ... to the innermost enclosing scope
    instance"); §10.2.5 (Call Activity): the called process runs as the call activity's
    content. The escalation thrown in the called process "child" at t=2 is caught by the
    non-interrupting boundary escalation event of "call": "handle" runs at t=2 while "child"
    goes on ("more", t=5); "call" then completes and "main" takes its normal flow."""
    outcome = run("escalation_through_call_activity.bpmn", until=60)
    times = {name: t for t, name in completed(outcome)}
    assert times["raise"] == times["caught"] == times["handle"] == 2.0
    assert times["more"] == times["c_end"] == times["call"] == times["end"] == 5.0
    assert sorted(e.process for e in kinds(outcome, "process.completed")) == ["child", "main"]
    assert not kinds(outcome, "process.terminated")


def test_validate_no_longer_warns_about_escalation_events() -> None:
    """Escalation end and throw events run as BPMN 2.0 defines them, so validate says nothing
    about them (before, it warned that the escalation was not handed on)."""
    for name in ("escalation_end_event.bpmn", "escalation_throw.bpmn",
                 "escalation_through_call_activity.bpmn"):
        _package, report = validate_spec(DATA / name)
        assert not report.diagnostics, report.lines()
