"""An event sub-process either runs as BPMN defines it or is refused at its line; never
ignored with a warning while the rest of the process runs."""

from __future__ import annotations

import pytest

from opspec.cli import main
from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

from .conftest import DATA, run


def test_an_event_sub_process_is_refused_at_its_line(
        capsys: pytest.CaptureFixture[str]) -> None:
    """BPMN 2.0 §10.2.5 (Event Sub-Process): "Unlike a standard Sub-Process, which uses the
    flow of the parent Process as a trigger, an Event Sub-Process has a Start Event with a
    trigger. Each time the Start Event is triggered while the parent Process is active, then
    the Event Sub-Process will start." opspec runs those with a timer or message start event
    (below); one with a signal start event it does not run yet, so a process with one is refused — `validate` and `run` fail with an
    error at the sub-process's line (the construct registry's `not-run`) — rather than run as
    if its handler were not there."""
    path = DATA / "event_sub_process.bpmn"
    _package, report = validate_spec(path)
    errors = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    assert [(d.location.line, d.code) for d in errors] == [(11, "not-run"), (12, "not-run")]
    assert main(["run", str(path)]) == 1
    err = capsys.readouterr().err
    assert f"{path}:11:" in err and "Traceback" not in err


def _completed(outcome: object) -> list[tuple[float, str]]:
    return [(round(e.time, 3), e.activity or "") for e in outcome.trace  # type: ignore[attr-defined]
            if e.process == "p" and e.kind == "activity.completed"
            and not (e.activity or "").endswith(("__trigger", "__body"))]


def test_an_interrupting_timer_event_sub_process_cancels_its_parent() -> None:
    """BPMN 2.0 §10.2.5 (Event Sub-Process): "Each time the Start Event is triggered while the
    parent Process is active, then the Event Sub-Process will start." §10.4.6 (Handling
    Events), interrupting event handlers: "Whenever the Event occurs, regardless of whether the
    Event is handled inline or on the boundary, the associated Activity is interrupted", and
    "If the inline Event Sub-Process completes without 're-throwing' the Event, the Activity
    is considered to have completed".

    "work" would take an hour; the timer start event (PT10M) starts "on_timeout" at 10 min,
    which cancels "work" (it never completes, nor does "end") and runs "handle" for a minute;
    then the instance completes. validate has nothing to say about it."""
    _package, report = validate_spec(DATA / "event_sub_process_timer.bpmn")
    assert [d for d in report.diagnostics if d.code in ("not-run", "runs-differently")] == []
    outcome = run("event_sub_process_timer.bpmn", until=7200)
    assert _completed(outcome) == [(0, "start"), (600, "timeout"), (660, "handle"),
                                   (660, "timeout_end"), (660, "on_timeout")]
    ended = [(e.time, e.kind) for e in outcome.trace if e.process == "p"
             and e.kind.startswith("process.") and e.kind != "process.started"]
    assert ended == [(660.0, "process.completed")]


def test_a_non_interrupting_message_event_sub_process_runs_beside_its_parent() -> None:
    """BPMN 2.0 §10.4.6 (Handling Events), non-interrupting event handlers: "For Event
    Sub-Processes, whenever the Event occurs it is consumed and the associated Event
    Sub-Process is performed. [...] The non-interrupting Start Event indicates that the Event
    SubProcess instance runs concurrently to the Sub-Process proper."

    "caller" sends "note" at 10 and 20 min: each starts "on_note", which runs "log" beside
    "work"; "work" goes on and completes at 1 h, and so does the instance."""
    outcome = run("event_sub_process_message.bpmn", until=7200)
    handler = [(600, "noted"), (600, "log"), (600, "note_end"), (600, "on_note")]
    assert _completed(outcome) == [(0, "start"), *handler,
                                   *[(1200, a) for _t, a in handler],
                                   (3600, "work"), (3600, "end")]
    ended = [e.time for e in outcome.trace if e.process == "p"
             and e.kind == "process.completed"]
    assert ended == [3600.0]
