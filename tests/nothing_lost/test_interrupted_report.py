"""Ctrl-C while the report is being written, every replication stored: the run said only
"interrupted", so the reader could not tell that nothing was lost, nor how to get the
report. It now says how many replications are stored and the command that writes the
report, which gives the report of the uninterrupted run."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main
from opspec.evaluation import report

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def test_ctrl_c_during_the_report_says_what_is_kept_and_how_to_write_it(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    out = tmp_path / "run"
    argv = ["evaluate", str(SPEC), "--users", "3", "--days", "0.25", "--workers", "1",
            "--out", str(out), "--quiet"]

    def interrupted(*_args: object, **_kwargs: object) -> Path:
        raise KeyboardInterrupt

    with monkeypatch.context() as patched:
        patched.setattr(report, "write_report", interrupted)
        assert main(argv) == 130
    err = capsys.readouterr().err
    assert "3 of 3 replications are stored" in err, err
    assert f"the report is not written; write it with `opspec evaluate --resume --out {out}`" \
        in err
    assert not (out / "report.html").exists()
    assert main(["evaluate", "--resume", "--out", str(out), "--quiet"]) == 0
    assert (out / "report.html").is_file()
