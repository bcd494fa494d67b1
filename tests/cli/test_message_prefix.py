"""Every message a command prints on stderr begins with that command, as argparse's usage
errors do (``opspec run: ...``, ``opspec devices list: ...``); ``opspec:`` alone only where
no command was parsed. Before, what reached ``cli.main`` said ``opspec:`` whatever ran."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import pytest

from opspec.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
CYCLE = ROOT / "tests" / "engine" / "hang_specs" / "cycle.xpdl"


def opspec(*args: str, cwd: Path, **env: str) -> subprocess.CompletedProcess[str]:
    """``opspec ARGS`` as a user runs it, in its own process."""
    return subprocess.run([sys.executable, "-m", "opspec", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=120, check=False,
                          env={**os.environ, "PYTHONPATH": str(ROOT), **env},
                          stdin=subprocess.DEVNULL)


def lines(stderr: str) -> list[str]:
    assert "Traceback" not in stderr
    return [line for line in stderr.splitlines() if line.strip()]


def test_a_spec_error_from_run_begins_with_opspec_run(tmp_path: Path) -> None:
    bad = tmp_path / "bad.xpdl"
    bad.write_text("<Package", encoding="utf-8")
    done = opspec("run", str(bad), cwd=tmp_path)
    assert done.returncode == 1
    [line] = lines(done.stderr)
    assert line.startswith(f"opspec run: {bad}:1: "), line


def test_a_file_error_from_validate_begins_with_opspec_validate(tmp_path: Path) -> None:
    missing = tmp_path / "missing.xpdl"
    done = opspec("validate", str(missing), cwd=tmp_path)
    assert done.returncode == 2
    [line] = lines(done.stderr)
    assert line.startswith(f"opspec validate: {missing}: "), line


def test_a_zero_time_cycle_begins_with_opspec_run(tmp_path: Path) -> None:
    done = opspec("run", str(CYCLE), "--timeline", "none", cwd=tmp_path,
                  OPSPEC_MAX_INSTANT_STEPS="20000")
    assert done.returncode == 1
    [line] = lines(done.stderr)
    assert line.startswith(f"opspec run: {CYCLE}:"), line
    assert ": the simulated clock stopped advancing at t=0.000 s" in line, line


def test_an_opspec_error_from_evaluate_begins_with_opspec_evaluate(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["evaluate", str(SPEC), "--workers", "0", "--out", str(tmp_path / "out")]) == 2
    assert lines(capsys.readouterr().err) == ["opspec evaluate: --workers must be >= 1, not 0"]


def test_an_unknown_command_keeps_opspec_alone(tmp_path: Path) -> None:
    done = opspec("evalute", "x.xpdl", cwd=tmp_path)
    assert done.returncode == 2
    assert lines(done.stderr)[-1].startswith(
        "opspec: error: argument COMMAND: invalid choice: 'evalute' (did you mean 'evaluate'?")


def test_a_subcommand_of_a_command_begins_with_both(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / "nowhere"
    assert main(["devices", "list", "--profiles", str(missing)]) == 2
    [line] = lines(capsys.readouterr().err)
    assert line.startswith(f"opspec devices list: device profile directory {missing} "), line


def test_an_output_that_would_replace_the_spec_is_said_once_prefixed(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The refusal travels as an error without a prefix: cli adds the command's, once."""
    spec = tmp_path / "spec.xpdl"
    spec.write_bytes(SPEC.read_bytes())
    assert main(["run", str(spec), "--trace", str(spec)]) == 2
    assert lines(capsys.readouterr().err) == [
        (f"opspec run: --trace {spec} is the file this command reads as SPEC; refusing to "
         "overwrite it (give --trace another file)")]


def test_a_translation_prints_its_own_refusal_once_prefixed(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "spec.xpdl"
    spec.write_bytes(SPEC.read_bytes())
    assert main(["preprocess", str(spec), "-o", str(spec)]) == 2
    [line] = lines(capsys.readouterr().err)
    assert line.startswith(f"opspec preprocess: -o {spec} is the file this command reads as "
                           "IN; refusing to overwrite it"), line


def _handler_raising(monkeypatch: pytest.MonkeyPatch, error: BaseException) -> None:
    """``opspec validate`` raises ``error`` as soon as it runs."""
    from opspec.commands import validate

    def run(_args: argparse.Namespace) -> int:
        raise error

    monkeypatch.setattr(validate, "run", run)


def test_an_interruption_begins_with_the_command(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    _handler_raising(monkeypatch, KeyboardInterrupt())
    assert main(["validate", str(SPEC)]) == 130
    assert lines(capsys.readouterr().err) == ["opspec validate: interrupted"]


def test_an_internal_error_begins_with_the_command(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.delenv("OPSPEC_DEBUG", raising=False)
    _handler_raising(monkeypatch, RuntimeError("boom"))
    assert main(["validate", str(SPEC)]) == 70
    [line] = lines(capsys.readouterr().err)
    assert line.startswith("opspec validate: internal error: RuntimeError: boom (this is a "
                           "bug in opspec"), line


def test_a_command_that_cannot_load_begins_with_its_name(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    from opspec.commands import new

    def register(_subparsers: object) -> None:
        raise RuntimeError("broken on purpose")

    monkeypatch.delenv("OPSPEC_DEBUG", raising=False)
    monkeypatch.setattr(new, "register", register)
    assert main(["new", "thing"]) == 70
    [line] = lines(capsys.readouterr().err)
    assert line.startswith("opspec new: internal error: the 'new' command cannot be loaded "
                           "(RuntimeError: broken on purpose)"), line


def test_evaluate_takes_o_for_its_output_folder(tmp_path: Path) -> None:
    args = build_parser("evaluate").parse_args(["evaluate", str(SPEC), "-o", str(tmp_path)])
    assert args.out == str(tmp_path)
