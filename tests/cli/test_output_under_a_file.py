"""An output path whose folder is in fact a file (``-o notes.txt/out.html``, a typo of a
folder's name): every command says which file stands where a folder should, in one line, exit
2. ``opspec show -o`` ended in an internal error (exit 70), ``run --trace`` and ``walkthrough
--record`` said only "File exists", ``new`` "Not a directory"."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.fixture
def a_file(tmp_path: Path) -> Path:
    path = tmp_path / "notes.txt"
    path.write_text("a file, not a folder\n", encoding="utf-8")
    return path


def _said(capsys: pytest.CaptureFixture[str], a_file: Path) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err and "internal error" not in err
    assert f"{a_file} is a file, not a folder" in err, err
    assert "File exists" not in err and "Not a directory" not in err
    return err


def test_show_output(a_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", str(SPEC), "-o", str(a_file / "spec.txt")]) == 2
    _said(capsys, a_file)
    assert a_file.read_text(encoding="utf-8") == "a file, not a folder\n"


def test_run_trace(a_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", str(SPEC), "--timeline", "none",
                 "--trace", str(a_file / "trace.jsonl")]) == 2
    assert f"cannot write the trace {a_file / 'trace.jsonl'}" in _said(capsys, a_file)


def test_walkthrough_record(a_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["walkthrough", str(SPEC), "--record", str(a_file / "session.json")]) == 2
    assert "cannot write the recording" in _said(capsys, a_file)


def test_new(a_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["new", str(a_file / "pill")]) == 2
    assert "nothing written" in _said(capsys, a_file)
