"""A new evaluation does not go into a folder holding an earlier one's outputs without its
results.sqlite: it used to overwrite report.html and leave the earlier run's B-* figures,
comparison figure and traces.xes (of another seed) beside the new results, a folder whose
files no longer belonged together. Refused now (exit 2, the files named, nothing touched);
a folder with files of the user's own is still used."""

from __future__ import annotations

from pathlib import Path

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def _evaluate(out: Path, *extra: str) -> int:
    return main(["evaluate", str(SPEC), "--users", "2", "--days", "0.5", "--workers", "1",
                 "--out", str(out), "--quiet", *extra])


def test_a_folder_with_an_earlier_runs_outputs_is_refused_and_kept(tmp_path: Path,
                                                                   capsys) -> None:
    out = tmp_path / "run"
    assert _evaluate(out, "--compare", str(SPEC), "--export", "xes") == 0
    (out / "results.sqlite").unlink()
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert any(p.name.startswith("B-") for p in before)
    capsys.readouterr()
    assert _evaluate(out, "--seed", "9") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "report.html" in err and "traces.xes" in err and "figures/" in err
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before


def test_a_folder_with_other_files_is_still_used(tmp_path: Path) -> None:
    out = tmp_path / "paper"
    out.mkdir()
    (out / "notes.txt").write_text("mine", encoding="utf-8")
    (out / "figures").mkdir()                     # empty: nothing of an earlier run
    assert _evaluate(out) == 0
    assert (out / "notes.txt").read_text(encoding="utf-8") == "mine"
    assert (out / "results.sqlite").is_file()
