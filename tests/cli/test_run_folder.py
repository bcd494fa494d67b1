"""``opspec run FOLDER`` names the spec files in the folder: the one to give when there is
one, the first few when there are several. It never picks one and runs it: which spec is
meant is the user's to say.

It used to say ``a folder; give one specification file (e.g.
specs/medication_dispenser.xpdl)``, naming a file of opspec's repository, not of the folder.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main


def _refusal(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    capsys.readouterr()
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert "completed" not in captured.out, "nothing ran"
    return captured.err


def test_a_folder_with_one_spec_names_it(tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["new", str(tmp_path / "pillbox")]) == 0
    folder = tmp_path / "pillbox"
    err = _refusal(["run", str(folder), "--until", "1h"], capsys)
    assert f"{folder}: a folder; give the spec file: {folder / 'pillbox.xpdl'}" in err
    assert "medication_dispenser" not in err


@pytest.mark.parametrize("command", ["walkthrough", "evaluate"])
def test_other_commands_that_run_a_spec_name_it_too(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str) -> None:
    (tmp_path / "only.bpmn").write_text("<definitions/>", encoding="utf-8")
    (tmp_path / "notes.txt").write_text("not a spec", encoding="utf-8")
    err = _refusal([command, str(tmp_path)], capsys)
    assert f"give the spec file: {tmp_path / 'only.bpmn'}" in err


def test_a_folder_with_several_specs_lists_a_few(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    for name in ("a.xpdl", "b.wfs", "c.bpmn", "d.xpdl", "e.xpdl", "f.xpdl", ".hidden.xpdl"):
        (tmp_path / name).write_text("", encoding="utf-8")
    (tmp_path / "folder.xpdl").mkdir()
    err = _refusal(["run", str(tmp_path)], capsys)
    listed = ", ".join(str(tmp_path / n) for n in ("a.xpdl", "b.wfs", "c.bpmn", "d.xpdl"))
    assert f"{tmp_path}: a folder; give one specification file: {listed} (and 2 more)" in err
    assert ".hidden" not in err and "folder.xpdl" not in err


def test_a_folder_without_specs_is_told_what_a_spec_file_is(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    err = _refusal(["run", str(tmp_path)], capsys)
    assert "a folder; give one specification file (e.g. specs/medication_dispenser.xpdl)" in err
