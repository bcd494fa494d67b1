"""``opspec evaluate -o FILE``: --out names a folder; a file there is said to be one, with
what to give instead, before anything runs (it was "cannot create the output folder: File
exists", which read as if a folder were in the way)."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.mark.parametrize("under", ["", "sub"], ids=["the-file", "a-folder-in-it"])
@pytest.mark.parametrize("resume", [False, True], ids=["new", "resume"])
def test_an_out_that_is_a_file_is_said_to_be_one(tmp_path: Path, capsys, under, resume):
    notes = tmp_path / "notes.txt"
    notes.write_text("mine\n", encoding="utf-8")
    out = notes / under if under else notes
    args = ["--resume"] if resume else [str(SPEC), "--users", "2", "--days", "1"]
    assert main(["evaluate", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert err.startswith(f"opspec evaluate: --out {out}")
    assert f"{notes} is a file, not a folder" in err
    assert "give a new or an existing folder" in err and "File exists" not in err
    assert notes.read_text(encoding="utf-8") == "mine\n"
