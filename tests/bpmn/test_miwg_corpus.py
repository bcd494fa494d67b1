"""Diagrams from modellers, as the BPMN Model Interchange Working Group's test suite holds
them (tests/bpmn/data/miwg: the reference models and four tools' exports): each loads, or
is refused at file:line for a reason docs/bpmn.md lists as not simulable; a run is never
decided by a silent default (every random branch was announced by validate); no traceback,
no hang.

``OPSPEC_MIWG=PATH`` (a checkout of github.com/bpmn-miwg/bpmn-miwg-test-suite) runs the
same checks over every ``.bpmn`` file under PATH (831 files from 35 tools at commit bc9f858:
the counts are in docs/bpmn.md).
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

import opspec
from opspec.errors import OpspecError, Severity
from opspec.commands.validate import engine_checks
from opspec.xpdl.validate import validate_file, validate_spec

DATA = Path(__file__).parent / "data" / "miwg"
DOCS = Path(__file__).parents[2] / "docs" / "bpmn.md"
WHOLE = os.environ.get("OPSPEC_MIWG")
FILES = sorted(Path(WHOLE).rglob("*.bpmn")) if WHOLE else sorted(DATA.glob("*.bpmn"))


def _not_simulable_codes() -> set[str]:
    """The error codes docs/bpmn.md's "What a diagram must say to be simulated" lists."""
    text = DOCS.read_text(encoding="utf-8")
    section = text.split("## What a diagram must say to be simulated", 1)[1].split("\n## ", 1)[0]
    return set(re.findall(r"`([a-z][a-z-]+)`", section))


LISTED = _not_simulable_codes()


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_a_modellers_diagram_runs_or_is_refused_at_its_lines_for_a_listed_reason(
        path: Path) -> None:
    # what `opspec validate` checks: the reader's checks and whether the engine compiles it
    report = validate_file(path, extra=engine_checks)
    package, _report = validate_spec(path)
    errors = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    assert not [d for d in errors if d.code == "internal-error"], report.lines()
    for error in errors:
        assert error.location.line is not None or error.code == "not-well-formed", str(error)
        assert error.code in LISTED, f"{error} (a reason docs/bpmn.md does not list)"
    if errors:
        return
    announced = {d.location.line for d in report.diagnostics if d.code == "undecided-gateway"}
    try:
        outcome = opspec.run(path, until=86400.0)
    except OpspecError as error:        # validate = run: what validate passes, run runs
        pytest.fail(f"validate passed but run refused: {error}")
    assert package is not None
    drawn = {e.activity for e in outcome.trace if e.kind == "branch.chosen"}
    if drawn:
        # every gateway that drew its branch was named by validate at its line
        lines = {a.id: a.location.line for p in package.processes
                 for a in p.all_activities() if a.location is not None}
        assert {lines.get(a) for a in drawn} <= announced


def test_the_corpus_counts_stay_as_documented() -> None:
    """How many of the committed exports load and run (docs/bpmn.md states them)."""
    if WHOLE:
        pytest.skip("counts are for the committed sample")
    loaded = sum(1 for p in FILES if validate_file(p, extra=engine_checks).ok)
    assert (len(FILES), loaded) == (76, LOADED)


LOADED = 44
