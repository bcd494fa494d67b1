"""`opspec run` given a file for the wrong option (a user model to --script, a spec or a
script to --user-model): the error names the option it was given to and the one it is for."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
USERS = ROOT / "specs" / "medication_dispenser.users.toml"
AS_SPEC = "give it as the spec (the first argument: opspec run SPEC)"


def error_of(capsys: pytest.CaptureFixture[str], *options: str) -> str:
    assert main(["run", str(SPEC), "--until", "1h", *options]) == 2
    return capsys.readouterr().err


def test_a_user_model_given_to_script(capsys: pytest.CaptureFixture[str]) -> None:
    err = error_of(capsys, "--script", str(USERS))
    assert "unknown key(s) activities, busy" in err          # what was wrong, as before
    assert "(given to --script, but this is a user model: give it to --user-model)" in err


def test_a_spec_given_to_script(capsys: pytest.CaptureFixture[str]) -> None:
    err = error_of(capsys, "--script", str(SPEC.with_suffix(".bpmn")))
    assert "the script is not valid TOML" in err
    assert f"given to --script, but this is a spec (BPMN): {AS_SPEC}" in err


def test_a_spec_given_to_user_model(capsys: pytest.CaptureFixture[str]) -> None:
    err = error_of(capsys, "--user-model", str(SPEC))
    assert "medication_dispenser.xpdl:1: not valid TOML" in err
    assert f"given to --user-model, but this is a spec (XPDL): {AS_SPEC}" in err


def test_a_compiled_spec_given_to_user_model(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    wfs = tmp_path / "dispenser.wfs"
    wfs.write_text(json.dumps({"format": "opspec-wfs", "version": 1, "package": {}}),
                   encoding="utf-8")
    err = error_of(capsys, "--user-model", str(wfs))
    assert f"given to --user-model, but this is a compiled spec (.wfs): {AS_SPEC}" in err


def test_a_script_given_to_user_model(tmp_path: Path,
                                      capsys: pytest.CaptureFixture[str]) -> None:
    script = tmp_path / "late.toml"
    script.write_text('steps = [["after trg_2 400s", "press_report"]]\n', encoding="utf-8")
    err = error_of(capsys, "--user-model", str(script))
    assert "given to --user-model, but this is a script: give it to --script" in err


def test_a_broken_script_keeps_its_own_advice(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    script = tmp_path / "late.toml"
    script.write_text('steps = [\n', encoding="utf-8")
    err = error_of(capsys, "--script", str(script))
    assert "the script is not valid TOML" in err and "given to" not in err


def test_a_user_model_given_as_the_spec(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", str(USERS), "--until", "1h"]) == 1
    err = capsys.readouterr().err
    assert "this is a user model (TOML), not a specification" in err   # what the reader found
    assert "(given as SPEC, but this is a user model: give it to --user-model)" in err
    assert len(err.strip().splitlines()) == 1


def test_a_broken_spec_given_as_the_spec_gets_no_hint_to_move_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cut = tmp_path / "cut.xpdl"
    cut.write_bytes(SPEC.read_bytes()[:3000])
    assert main(["run", str(cut), "--until", "1h"]) == 1
    err = capsys.readouterr().err
    assert "the file ends inside a tag" in err and "given as SPEC" not in err
