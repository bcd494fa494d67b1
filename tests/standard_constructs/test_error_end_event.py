"""An error end event is caught by the nearest enclosing boundary error event (the one for
its error code, else one catching every error), which cancels that sub-process or call
activity and takes its exception flow; an error nothing catches fails the instance, with a
located fault."""

from __future__ import annotations

import pytest

from .conftest import completed, kinds, run


@pytest.mark.parametrize(("code", "path"), [
    (1, ["throw_jam", "catch_jam", "fix_jam", "end_jam"]),
    (2, ["throw_empty", "catch_any", "fix_other", "end_other"]),
])
def test_the_nearest_enclosing_boundary_error_event_for_the_code_catches(
        code: int, path: list[str]) -> None:
    """BPMN 2.0 Table 10.88 (End Event types), Error: "All currently active threads in the
    particular Sub-Process are terminated as a result. The Error will be caught by a Catch
    Error Intermediate Event with the same errorCode or no errorCode which is on the boundary
    of the nearest enclosing parent Activity (hierarchically)."

    The error is thrown in "inner", which has no boundary event, so "outer" catches it: its
    event for "Jammed" takes "Jammed" (though the catch-all comes first in the file), the
    catch-all takes "Empty". "outer" is cancelled at t=1 with everything in it ("slow", 10 s,
    never completes) and its normal flow ("after") is not taken."""
    outcome = run("error_end_event.bpmn", until=60, params={"code": code})
    assert completed(outcome)[-4:] == [(1.0, name) for name in path]
    done = {name for _t, name in completed(outcome)}
    assert not done & {"slow", "outer", "inner", "after"}
    assert [e.activity for e in kinds(outcome, "activity.failed")] == ["outer"]
    assert len(kinds(outcome, "process.completed")) == 1


def test_without_an_error_the_sub_processes_complete_normally() -> None:
    """The same file when no error end event is reached (code 3): "outer" completes when
    "slow" does, and the normal flow goes on — the boundary error events never fire."""
    outcome = run("error_end_event.bpmn", until=60, params={"code": 3})
    names = [name for _t, name in completed(outcome)]
    assert names[-3:] == ["outer", "after", "end"]
    assert not kinds(outcome, "activity.failed")


def test_an_error_crosses_a_call_activity() -> None:
    """BPMN 2.0 Table 10.88 (as above: "the nearest enclosing parent Activity
    (hierarchically)"); §10.2.5 (Call Activity): the called process runs as the call
    activity's content. The error end event of the called process "child" is caught by the
    boundary error event of the call activity: "child" is ended, "main" takes the exception
    flow ("handle"), not the normal one ("after")."""
    outcome = run("error_through_call_activity.bpmn", until=60)
    names = [name for _t, name in completed(outcome)]
    assert names == ["start", "c_start", "work", "c_error", "caught", "handle", "end_handled"]
    assert [(e.process, e.time) for e in kinds(outcome, "process.terminated")] == [("child", 2.0)]
    assert [e.process for e in kinds(outcome, "process.completed")] == ["main"]


def test_an_uncaught_error_fails_the_instance_visibly() -> None:
    """BPMN 2.0 Table 10.88, Error: "The behavior of the Process is unspecified if no Activity
    in the hierarchy has such an Error Intermediate Event. The system executing the process
    may define additional Error handling in this case, a common one being termination of the
    Process instance." opspec aborts the instance with a fault that names the file, the line
    of the end event and the error: never a normal completion."""
    outcome = run("error_uncaught.bpmn", until=60)
    assert not kinds(outcome, "process.completed")
    (aborted,) = kinds(outcome, "process.aborted")
    assert aborted.time == 2.0
    (fault,) = outcome.summary["faults"]
    assert fault["activity"] == "s_error"
    assert "error_uncaught.bpmn:11" in fault["message"]
    assert "'Jammed'" in fault["message"] and "caught by no boundary error event" in fault["message"]
    assert "after" not in [name for _t, name in completed(outcome)]


def test_xpdl_error_end_event_in_an_activity_set() -> None:
    """XPDL 2.1, End Event Result "Error" (its text is BPMN 1.x's): "This type of End indicates that a named
    Error should be generated. This Error will be caught by an Intermediate Event within the
    Event Context." — for opspec an EXCEPTION transition of the BlockActivity named for the
    ErrorCode. The set is cancelled ("slow" never completes) and "fix" runs, not "after"."""
    outcome = run("error_end_event.xpdl", until=60)
    assert completed(outcome) == [(0.0, "start"), (0.0, "s_start"), (0.0, "fork"),
                                  (2.0, "work"), (2.0, "s_error"), (2.0, "fix"),
                                  (2.0, "end_fixed")]
