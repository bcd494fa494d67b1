"""An event sub-process either runs as BPMN defines it or is refused at its line; never
ignored with a warning while the rest of the process runs."""

from __future__ import annotations

import pytest

from opspec.cli import main
from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

from .conftest import DATA


def test_an_event_sub_process_is_refused_at_its_line(
        capsys: pytest.CaptureFixture[str]) -> None:
    """BPMN 2.0 §10.2.5 (Event Sub-Process): "Unlike a standard Sub-Process, which uses the
    flow of the parent Process as a trigger, an Event Sub-Process has a Start Event with a
    trigger. Each time the Start Event is triggered while the parent Process is active, then
    the Event Sub-Process will start." opspec does not run event
    sub-processes yet, so a process with one is refused — `validate` and `run` fail with an
    error at the sub-process's line (the construct registry's `not-run`) — rather than run as
    if its handler were not there."""
    path = DATA / "event_sub_process.bpmn"
    _package, report = validate_spec(path)
    errors = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    assert [(d.location.line, d.code) for d in errors] == [(11, "not-run"), (12, "not-run")]
    assert main(["run", str(path)]) == 1
    err = capsys.readouterr().err
    assert f"{path}:11:" in err and "Traceback" not in err
