from __future__ import annotations

import json
from contextlib import nullcontext

import pytest
from evaluate_without_report import without_report

from opspec.cli import main

@pytest.fixture
def evaluate(capsys: pytest.CaptureFixture[str]):
    """``evaluate(*args)`` → (exit status, JSON document or None, stderr).

    ``evaluate(*args, report=False)`` stores and summarises as always but draws no report
    (tests/evaluate_without_report.py): for the second run of a pair whose
    first run draws the same kind of report (one or two workers, resumed or whole, Dask or
    local), and for runs whose report another test of this folder draws and reads. The
    report is almost all of a small evaluation's cost (4 users x 2 days: 1.2 of 1.23 CPU-s)."""

    def run(*args: str, report: bool = True) -> tuple[int, dict | None, str]:
        with without_report() if not report else nullcontext():
            status = main(["evaluate", *args, "--json"])
        captured = capsys.readouterr()
        doc = json.loads(captured.out) if captured.out.strip() else None
        return status, doc, captured.err

    return run
