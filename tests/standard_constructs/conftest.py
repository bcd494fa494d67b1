"""Helpers of the standard-construct tests: run a small BPMN or XPDL file of ``data/`` and
read what its trace says (which activities completed, when, how the instance ended)."""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

DATA = Path(__file__).parent / "data"


def run(name: str, **options: object) -> opspec.RunOutcome:
    """Run ``data/NAME`` (after checking it validates without errors)."""
    path = DATA / name
    _package, report = validate_spec(path)
    errors = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    assert not errors, report.lines()
    options.setdefault("seed", 0)
    return opspec.run(path, **options)  # type: ignore[arg-type]


def completed(outcome: opspec.RunOutcome, process: str | None = None
              ) -> list[tuple[float, str]]:
    """``(time, activity)`` of every ``activity.completed`` event, in order."""
    return [(round(e.time, 6), e.activity or "") for e in outcome.trace
            if e.kind == "activity.completed" and (process is None or e.process == process)]


def kinds(outcome: opspec.RunOutcome, kind: str) -> list[opspec.engine.trace.TraceEvent]:
    return [e for e in outcome.trace if e.kind == kind]


def instances(outcome: opspec.RunOutcome, process: str = "p") -> list[list[str]]:
    """The activities each instance of ``process`` completed, in order, one list per
    instance (sorted: instances' ids are not what a test asserts)."""
    found: dict[int, list[str]] = {}
    for event in outcome.trace:
        if event.process == process and event.kind == "activity.completed":
            found.setdefault(event.instance or 0, []).append(event.activity or "")
    return sorted(found.values())


@pytest.fixture
def data() -> Path:
    return DATA
