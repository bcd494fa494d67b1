"""`-o -` is the standard output for compile and show, as it is for preprocess: both wrote a
file named '-' in the current folder (compile also a '-.users.toml' beside it)."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main
from opspec.model.codec import loads

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def test_compile_writes_the_script_to_stdout(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["compile", str(SPEC), "-o", "-"]) == 0
    captured = capsys.readouterr()
    assert loads(captured.out).id == "medication_dispenser"
    assert captured.err == ""
    assert list(tmp_path.iterdir()) == []


def test_compile_to_stdout_refuses_a_spec_with_errors(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    bad = tmp_path / "bad.xpdl"
    bad.write_text(SPEC.read_text(encoding="utf-8").replace(
        'Name="opspec:Priority" Value="2"', 'Name="opspec:Priority" Value="high"'),
        encoding="utf-8")
    assert main(["compile", "bad.xpdl", "-o", "-"]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.endswith("opspec compile: bad.xpdl has errors; nothing written\n")
    assert main(["compile", "missing.xpdl", "-o", "-"]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.xpdl"]


def test_show_writes_to_stdout(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                               capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["show", str(SPEC), "-o", "-"]) == 0
    assert capsys.readouterr().out.startswith("Package 'medication_dispenser'")
    assert list(tmp_path.iterdir()) == []
