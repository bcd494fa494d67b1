"""XPDL 2.x ``Activity/@StartActivity``: "Designates the first activity to be executed when the
process is instantiated. Used when there is no other way to determine this." (XPDL 2.1, the
Activity's attributes; the same text in the XSD's annotation). A process that is one cycle,
with no start event and no activity outside the cycle, starts at the marked activity; beside
an activity without incoming transitions the mark changes nothing, and validate says so."""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec.errors import OpspecError, Severity
from opspec.xpdl.loader import load_package
from opspec.xpdl.validate import validate_spec
from opspec.xpdl.writer import write_xpdl

from .conftest import DATA, completed, run

CYCLE = DATA / "start_activity_cycle.xpdl"


def test_a_cycle_starts_at_its_marked_activity() -> None:
    """The instance starts at "review" (marked), not at "draft" (first in the file): review,
    file, then the loop once round back through draft, and ends after the second file."""
    outcome = run("start_activity_cycle.xpdl", until=60)
    assert completed(outcome, "p") == [(1.0, "review"), (2.0, "file"), (3.0, "draft"),
                                       (4.0, "review"), (5.0, "file"), (5.0, "end")]


def test_without_the_mark_the_cycle_is_refused_with_the_way_out(tmp_path: Path) -> None:
    """Without StartActivity nothing says where the cycle starts: validate refuses it at the
    process and names both remedies, a start event or the mark."""
    unmarked = tmp_path / "unmarked.xpdl"
    unmarked.write_text(CYCLE.read_text(encoding="utf-8").replace(
        ' StartActivity="true"', ""), encoding="utf-8")
    _package, report = validate_spec(unmarked)
    errors = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    assert [d.code for d in errors] == ["no-start-activity"]
    assert 'StartActivity="true"' in (errors[0].hint or "")
    with pytest.raises(OpspecError):
        opspec.run(unmarked, until=60)


def test_beside_an_activity_without_incoming_transitions_the_mark_is_said_and_ignored(
        tmp_path: Path) -> None:
    """With "draft" no longer in the cycle (nothing leads back to it) the process starts at
    draft, as XPDL's "used when there is no other way" says; the mark on "review", which has
    an incoming transition, is ignored, and validate says so at its line."""
    text = CYCLE.read_text(encoding="utf-8").replace('To="draft"', 'To="end"')
    path = tmp_path / "beside.xpdl"
    path.write_text(text, encoding="utf-8")
    _package, report = validate_spec(path)
    said = [(d.location.line, d.code) for d in report.diagnostics
            if "StartActivity" in d.message]
    line = text[:text.index('<Activity Id="review"')].count("\n") + 1
    assert said == [(line, "runs-differently")]
    outcome = opspec.run(path, until=60, seed=0)
    assert [a for _t, a in completed(outcome, "p")][:2] == ["draft", "review"]


def test_the_mark_is_written_back(tmp_path: Path) -> None:
    """opspec's XPDL writer keeps the mark (a spec written by `opspec convert` starts where
    the one it read did)."""
    package = load_package(CYCLE).package
    written = tmp_path / "written.xpdl"
    written.write_bytes(write_xpdl(package))
    again = load_package(written).package
    marks = {a.id: a.marked_start for a in again.processes[0].activities}
    assert marks == {"draft": False, "review": True, "file": False, "end": False}
    outcome = opspec.run(written, until=60, seed=0)
    assert completed(outcome, "p")[0] == (1.0, "review")
