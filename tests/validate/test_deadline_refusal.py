"""A DeadlineDuration opspec cannot read is one error at its line, which lists the duration
spellings; a Deadline that is an expression over data fields (XPDL's DeadlineDuration is an
Expression) is still accepted.

A misspelt deadline (``10 minuts``) used to give a warning ("it never expires in a
simulation") and, from the engine, an error telling to write an expression: two messages
that contradicted each other, neither of them naming the duration spellings.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.cli import main

TEMPLATE_DEADLINE = "<DeadlineDuration>PT10M</DeadlineDuration>"


def _spec_with_deadline(tmp_path: Path, text: str) -> tuple[Path, int]:
    """A new project's spec whose one Deadline reads ``text``, and the line it is on."""
    assert main(["new", str(tmp_path / "demo")]) == 0
    spec = tmp_path / "demo" / "demo.xpdl"
    source = spec.read_text(encoding="utf-8")
    assert source.count(TEMPLATE_DEADLINE) == 1
    spec.write_text(source.replace(TEMPLATE_DEADLINE,
                                   f"<DeadlineDuration>{text}</DeadlineDuration>"),
                    encoding="utf-8")
    line = next(n for n, row in enumerate(source.splitlines(), start=1)
                if TEMPLATE_DEADLINE in row)
    return spec, line


def _validate(spec: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, list[str]]:
    capsys.readouterr()
    status = main(["validate", str(spec)])
    out = capsys.readouterr().out
    return status, [row for row in out.splitlines() if ": error: " in row or ": warning: " in row]


@pytest.mark.parametrize("text", ["10 minuts", "ten minutes", "1h30x"])
def test_a_misspelt_deadline_is_one_error_that_lists_the_duration_spellings(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str) -> None:
    spec, line = _spec_with_deadline(tmp_path, text)
    status, rows = _validate(spec, capsys)
    assert status == 1
    assert len(rows) == 1, rows
    row = rows[0]
    assert row.startswith(f"{spec}:{line}: error: ")
    assert f"cannot read duration '{text}': not a duration" in row
    assert "never expires" not in row
    assert "PT5M" in row and "5 min" in row and "1h30m" in row, "the spellings are listed"
    assert "expression over data fields" in row, "a Deadline may also be an expression"


@pytest.mark.parametrize("text", ["beeps *", "timedelta(seconds=3)"])
def test_an_unreadable_deadline_expression_is_one_error_that_lists_the_duration_spellings(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str) -> None:
    spec, line = _spec_with_deadline(tmp_path, text)
    status, rows = _validate(spec, capsys)
    assert status == 1
    assert len(rows) == 1, rows
    row = rows[0]
    assert row.startswith(f"{spec}:{line}: error: deadline of activity 'wait_taken' ")
    assert "never expires" not in row
    assert "PT5M" in row and "1h30m" in row, "the spellings are listed"


def test_a_deadline_over_data_fields_is_still_a_deadline(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec, _ = _spec_with_deadline(tmp_path, "beeps * 300 + 600")
    status, rows = _validate(spec, capsys)
    assert (status, rows) == (0, [])


def test_a_deadline_naming_no_data_field_is_refused_as_such(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec, line = _spec_with_deadline(tmp_path, "soon")
    status, rows = _validate(spec, capsys)
    assert status == 1
    assert len(rows) == 1, rows
    assert rows[0].startswith(f"{spec}:{line}: error: ")
    assert "'soon', which is not a data field" in rows[0]


def test_run_refuses_a_misspelt_deadline_with_the_same_error(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec, line = _spec_with_deadline(tmp_path, "10 minuts")
    capsys.readouterr()
    assert main(["run", str(spec), "--until", "1h"]) != 0
    err = capsys.readouterr().err
    assert f"{spec}:{line}: " in err
    assert "cannot read duration '10 minuts': not a duration" in err
    assert "was not understood" not in err


def test_a_deadline_without_duration_never_expires_and_says_so_once(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """XPDL 2.1's Deadline has ``DeadlineDuration minOccurs="0"`` (the schema), so a Deadline
    with none is valid: it never expires, which validate says once as a warning, and the run
    runs. (The engine refused it, "has no expression", beside the reader's warning that it
    never expires: two messages that contradicted each other.)"""
    spec, line = _spec_with_deadline(tmp_path, "")
    status, rows = _validate(spec, capsys)
    assert status == 0
    assert rows == [(f"{spec}:{line}: warning: Deadline has no duration; it never expires "
                     "(add <DeadlineDuration>PT5M</DeadlineDuration>)")]
    trace = tmp_path / "trace.jsonl"
    # nobody answers: with its PT10M the deadline expired; without a duration, never
    assert main(["run", str(spec), "--days", "1", "--no-user", "--timeline", "none",
                 "--trace", str(trace)]) == 0
    kinds = {json.loads(row)["kind"] for row in trace.read_text().splitlines()[1:]}
    assert "activity.started" in kinds and "deadline.expired" not in kinds
