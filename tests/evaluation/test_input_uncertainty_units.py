"""The input-uncertainty table (``opspec evaluate --input-uncertainty B``) writes each number
in its metric's units, as the run's own table just above it does: a declared proportion in %,
a duration with its unit. It printed ``taken_rate 0.9883 [0.9861, 0.9902]`` under the run's
``taken_rate 98.83 % [98.61 %, 99.02 %]``, and ``report_latency_s 143.1`` without its s."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.fixture(scope="module")
def evaluated(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, Path]:
    """The terminal output and the folder of a small evaluation with 2 parameter draws."""
    from evaluate_without_report import without_report

    folder = tmp_path_factory.mktemp("units")
    trace, model = folder / "person.jsonl", folder / "person.users.toml"
    printed = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["run", str(SPEC), "--user-model", "dispenser-reference", "--days", "2",
                     "--seed", "11", "--trace", str(trace), "--timeline", "none"]) in (0, 1)
        assert main(["fit", str(trace), "-o", str(model), "--draws", "2"]) == 0
    with without_report(), contextlib.redirect_stdout(printed):
        assert main(["evaluate", str(SPEC), "--users", "6", "--days", "2", "--workers", "1",
                     "--quiet", "--user-model", str(model), "--input-uncertainty", "2",
                     "--users-per-draw", "3", "--out", str(folder / "run")]) == 0
    return printed.getvalue(), folder / "run"


def _row(text: str, metric: str) -> str:
    table = text[text.index("Input uncertainty:"):]
    return next(line for line in table.splitlines() if line.split()[:1] == [metric])


def test_a_proportion_is_in_percent(evaluated: tuple[str, Path]) -> None:
    row = _row(evaluated[0], "taken_rate")
    cells = row.split()
    assert cells[2] == "%" and "%]" in row, row          # "taken_rate  98.33 %  [.. %, .. %]"
    assert row.count(" %") >= 7, row                     # estimate and three intervals


def test_a_duration_has_its_unit(evaluated: tuple[str, Path]) -> None:
    row = _row(evaluated[0], "report_latency_s")
    assert row.split()[2] == "s" and row.count(" s") >= 7, row


def test_a_count_is_a_plain_number(evaluated: tuple[str, Path]) -> None:
    row = _row(evaluated[0], "doses_due")
    assert "%" not in row.split("]")[0] and " s" not in row, row
