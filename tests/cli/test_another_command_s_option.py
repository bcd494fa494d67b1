"""An option of another command given to this one (``opspec run SPEC --users 5``, as evaluate
takes it): the usage error says which command takes it. The closest option of this command
was offered instead, and for ``run --users`` that was ``--no-user``, the opposite of what
was meant."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = str(ROOT / "specs" / "medication_dispenser.xpdl")


def _refusal(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    return capsys.readouterr().err.splitlines()[-1]


def test_run_users_names_evaluate(capsys: pytest.CaptureFixture[str]) -> None:
    line = _refusal(["run", SPEC, "--users", "5"], capsys)
    assert line.endswith("(--users is not an option of opspec run, but of evaluate)")
    assert "--no-user" not in line


def test_evaluate_trace_names_run(capsys: pytest.CaptureFixture[str]) -> None:
    line = _refusal(["evaluate", SPEC, "--trace", "t.jsonl"], capsys)
    assert "(--trace is not an option of opspec evaluate, but of run)" in line


def test_a_nested_command_s_option(capsys: pytest.CaptureFixture[str]) -> None:
    line = _refusal(["devices", "list", "--port", "pty"], capsys)
    assert "but of study, devices emulate)" in line


def test_a_typo_still_gets_the_closest_name(capsys: pytest.CaptureFixture[str]) -> None:
    line = _refusal(["run", SPEC, "--dayz", "3"], capsys)
    assert line.endswith("(--dayz: did you mean --days?)")
