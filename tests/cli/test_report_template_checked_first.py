"""A ``--report-template`` with a syntax error is refused before the run, at its line: it
was found only when the report was written, after every replication had run (minutes for
1,000 users), and the run had to be resumed to write the report."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def test_a_broken_template_stops_the_run_before_it_starts(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    template = tmp_path / "mine.html.j2"
    template.write_text("<html>\n<h1>{{ title }}</h1>\n{{ broken\n</html>\n", encoding="utf-8")
    out = tmp_path / "run"
    assert main(["evaluate", str(SPEC), "--users", "2", "--days", "1", "--workers", "1",
                 "--quiet", "--report-template", str(template), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"opspec evaluate: {template}:") and "the report template fails" in err
    assert "replications are stored" not in err
    assert not out.exists()
