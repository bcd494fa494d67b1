"""`opspec show --format html -o FILE`: the file is written whole when the picture is drawn,
and not at all when it cannot be (no Graphviz): a shell redirection would leave an empty
file behind."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def test_without_graphviz_no_file_is_left(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))     # no dot program on it
    out = tmp_path / "dispenser.html"
    assert main(["show", str(SPEC), "--format", "html", "-o", str(out)]) == 2
    assert "needs Graphviz's 'dot' program" in capsys.readouterr().err
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_the_text_goes_to_the_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "dispenser.txt"
    assert main(["show", str(SPEC), "-o", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert text.startswith("Package ") and "manual" in text
    # it says what it wrote, as opspec compile does ('FILE: compiled from SPEC')
    assert capsys.readouterr().out == f"{out}: text written from {SPEC}\n"


def test_a_dot_file_written_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "dispenser.dot"
    assert main(["show", str(SPEC), "--format", "dot", "-o", str(out)]) == 0
    assert out.read_text(encoding="utf-8").startswith("digraph")
    assert capsys.readouterr().out == f"{out}: dot written from {SPEC}\n"
