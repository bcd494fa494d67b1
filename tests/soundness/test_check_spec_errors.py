"""`opspec check` on a spec with errors: a process level with an error in it is never called
sound; a level without one is, and the summary says where the other errors lie."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.cli import main

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"


def broken(tmp_path: Path, *edits: tuple[str, str]) -> Path:
    text = SPEC.read_text(encoding="utf-8")
    for old, new in edits:
        assert text.count(old) == 1
        text = text.replace(old, new)
    path = tmp_path / "dispenser.xpdl"
    path.write_text(text, encoding="utf-8")
    return path


def line_of(path: Path, text: str) -> int:
    return next(n for n, line in enumerate(path.read_text().splitlines(), 1) if text in line)


DANGLING = ('From="start_notify" To="timer_done"', 'From="start_notify" To="nowhere"')
BAD_TTL = ('Name="opspec:MessageTTL" Value="PT60S"', 'Name="opspec:MessageTTL" Value="soon"')


def test_a_level_with_an_error_in_it_is_not_called_sound(tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]
                                                         ) -> None:
    path = broken(tmp_path, DANGLING)
    line = line_of(path, 'To="nowhere"')
    assert main(["check", str(path)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"{path}:{line}: error: Transition 't_started' points to")
    timer = next(o for o in out if o.startswith(f"{path}: timer_workflow: "))
    assert timer.startswith(f"{path}: timer_workflow: not sound: 1 spec error(s) in it "
                            f"(line {line}); in what could be read of it: no problem (")
    assert f"{path}: schedule_workflow: sound (11 states)" in out
    assert out[-1] == (f"{path}: not sound (the spec has errors): 3 of 4 process level(s) "
                       "sound, 0 problem(s), 1 spec error(s) (see `opspec validate`)")


def test_errors_outside_every_level_are_said_to_be(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    path = broken(tmp_path, BAD_TTL)
    assert main(["check", str(path)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert f"{path}: timer_workflow: sound (4 states)" in out
    assert out[-1] == (f"{path}: not sound (the spec has errors): 4 of 4 process level(s) "
                       "sound, 0 problem(s), 1 spec error(s) outside these process levels "
                       "(see `opspec validate`)")
    path = broken(tmp_path, BAD_TTL, DANGLING)
    assert main(["check", str(path)]) == 1
    assert capsys.readouterr().out.splitlines()[-1].endswith(
        "3 of 4 process level(s) sound, 0 problem(s), 2 spec error(s), 1 of them outside "
        "these process levels (see `opspec validate`)")


def test_json_says_which_level_has_errors(tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    path = broken(tmp_path, DANGLING)
    assert main(["check", "--json", str(path)]) == 1
    doc = json.loads(capsys.readouterr().out)
    levels = {p["process"]: p for p in doc["processes"]}
    assert levels["timer_workflow"]["sound"] is False
    assert levels["timer_workflow"]["spec_errors"] == 1
    assert levels["schedule_workflow"]["sound"] is True
    assert "spec_errors" not in levels["schedule_workflow"]
    assert doc["sound"] is False
