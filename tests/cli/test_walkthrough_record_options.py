"""``opspec walkthrough SPEC --record FILE --no-record``: refused in one line, before the
session, as --record with --replay is. The session ran and FILE was silently not written."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def test_record_with_no_record_is_refused(tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    record = tmp_path / "session.json"
    assert main(["walkthrough", str(SPEC), "--record", str(record), "--no-record"]) == 2
    err = capsys.readouterr().err
    assert err == (f"opspec walkthrough: --record {record} with --no-record: the session "
                   "cannot be recorded and not recorded (leave out one of them)\n")
    assert not record.exists()
