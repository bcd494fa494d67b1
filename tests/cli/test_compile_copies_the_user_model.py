"""`opspec compile IN -o OUT.wfs` copies IN.users.toml to OUT.users.toml, as `preprocess` does.
A run of OUT looks for OUT.users.toml: without the copy the script ran with nobody on the user
lane (the dispenser: every dose missed) where the spec ran with its user model."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"


def _events(trace: Path) -> list[str]:
    return trace.read_text(encoding="utf-8").splitlines()[1:]      # the header names the spec


def test_a_script_written_elsewhere_runs_with_the_spec_s_users(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "dispenser.xpdl"
    shutil.copyfile(SPECS / "medication_dispenser.xpdl", spec)
    shutil.copyfile(SPECS / "medication_dispenser.users.toml", tmp_path / "dispenser.users.toml")
    (tmp_path / "build").mkdir()
    script = tmp_path / "build" / "pills.wfs"
    assert main(["compile", str(spec), "-o", str(script)]) == 0
    out = capsys.readouterr().out
    copy = tmp_path / "build" / "pills.users.toml"
    assert f"{copy}: user model of the output, copied from {tmp_path / 'dispenser.users.toml'}" \
        in out
    assert copy.read_bytes() == (tmp_path / "dispenser.users.toml").read_bytes()
    for path, trace in ((spec, "spec.jsonl"), (script, "script.jsonl")):
        assert main(["run", str(path), "--seed", "3", "--trace", str(tmp_path / trace),
                     "--timeline", "none"]) == 0
    assert _events(tmp_path / "script.jsonl") == _events(tmp_path / "spec.jsonl")
    assert any('"kind": "activity.completed"' in e and "take_pill" in e
               for e in _events(tmp_path / "script.jsonl"))


def test_a_different_user_model_already_there_is_kept_and_said(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "dispenser.xpdl"
    shutil.copyfile(SPECS / "medication_dispenser.xpdl", spec)
    shutil.copyfile(SPECS / "medication_dispenser.users.toml", tmp_path / "dispenser.users.toml")
    mine = tmp_path / "pills.users.toml"
    mine.write_text("# mine\n", encoding="utf-8")
    assert main(["compile", str(spec), "-o", str(tmp_path / "pills.wfs")]) == 0
    assert mine.read_text(encoding="utf-8") == "# mine\n"
    assert (f"opspec compile: kept {mine}, which differs from "
            f"{tmp_path / 'dispenser.users.toml'} (the output's user model)"
            in capsys.readouterr().err)
