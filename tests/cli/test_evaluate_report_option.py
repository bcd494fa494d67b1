"""``opspec evaluate SPEC --report DIR`` (as ``opspec model-check --report DIR`` takes it):
argparse took ``--report`` for an abbreviation of ``--report-template`` and read DIR, or an
earlier report.html, as a Jinja template ("cannot read the report template …", or a report
drawn from the wrong file). It is refused in one line that says where the report goes."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.mark.parametrize("given", [["--report"], ["--report", "out"], ["--report=out"]])
def test_report_says_where_the_report_goes(given: list[str], tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["evaluate", str(SPEC), "--users", "2", "--out", str(tmp_path / "run"), *given])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "usage:" not in err
    assert err.startswith("opspec evaluate: --report is not an option of evaluate")
    assert "OUT/report.html" in err and "--out DIR" in err
    assert "report template" not in err
    assert not (tmp_path / "run").exists()


def test_it_is_not_in_the_help(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["evaluate", "--help"])
    assert "--report " not in capsys.readouterr().out
