"""``opspec run specs/medication_dispenser.xpdl`` outside the clone: the spec is not found,
and the message says where a relative path was looked for and where the bundled specs are.
It said "give one specification file (e.g. specs/medication_dispenser.xpdl)", the very path
given."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("command", ["run", "evaluate"])
def test_a_relative_spec_not_found_says_where_it_was_looked_for(
        command: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    assert main([command, "specs/medication_dispenser.xpdl"]) == 2
    err = capsys.readouterr().err
    assert err == (f"opspec {command}: specs/medication_dispenser.xpdl: not found; give one "
                   "specification file (a relative path starts in the current folder, "
                   f"{tmp_path}; the bundled specs are in {ROOT / 'specs'})\n")
    assert not list(tmp_path.iterdir())


def test_an_absolute_path_keeps_its_message(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / "nowhere.xpdl"
    assert main(["run", str(missing)]) == 2
    assert capsys.readouterr().err == (f"opspec run: {missing}: not found; give one "
                                       "specification file (e.g. "
                                       "specs/medication_dispenser.xpdl)\n")


@pytest.mark.parametrize("command", ["show", "compile", "preprocess", "validate", "check"])
def test_the_other_commands_say_it_too(command: str, tmp_path: Path,
                                       monkeypatch: pytest.MonkeyPatch,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    assert main([command, "specs/medication_dispenser.xpdl"]) == 2
    err = capsys.readouterr().err
    assert (f"(a relative path starts in the current folder, {tmp_path}; the bundled specs "
            f"are in {ROOT / 'specs'})\n") in err
