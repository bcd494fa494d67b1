from __future__ import annotations

import json
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS_TOML = ROOT / "specs" / "medication_dispenser.users.toml"


@pytest.fixture
def evaluate(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch):
    """``evaluate(*args)`` → (exit status, JSON document or None, stderr).

    ``evaluate(*args, report=False)`` stores and summarises as always but draws no report
    (``write_report`` returns the report's path unwritten): for the second run of a pair whose
    first run draws the same kind of report (one or two workers, resumed or whole, Dask or
    local), and for runs whose report another test of this folder draws and reads. The
    report is almost all of a small evaluation's cost (4 users x 2 days: 1.2 of 1.23 CPU-s)."""

    def run(*args: str, report: bool = True) -> tuple[int, dict | None, str]:
        with monkeypatch.context() as patch:
            if not report:
                patch.setattr("opspec.evaluation.report.write_report", _report_not_drawn)
                # nor start the processes that would draw it (--workers 2)
                patch.setattr("opspec.evaluation.plots.drawing_processes", _no_drawing)
            status = main(["evaluate", *args, "--json"])
        captured = capsys.readouterr()
        doc = json.loads(captured.out) if captured.out.strip() else None
        return status, doc, captured.err

    return run


@contextmanager
def _no_drawing(_workers: int) -> Iterator[None]:
    yield


def _report_not_drawn(store, summaries=None, **_options) -> Path:
    return Path(store.folder) / "report.html"


def metrics_of(doc: dict) -> dict:
    """The metrics of an ``--json`` document, without each metric's ``users`` count."""
    return {k: {f: v for f, v in m.items() if f != "users"} for k, m in doc["metrics"].items()}
