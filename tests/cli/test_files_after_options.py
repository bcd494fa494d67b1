"""The commands that take several files take them before and after options alike:
``opspec validate a.xpdl --strict b.xpdl`` checks both. argparse fills the list of files
from one run of arguments, and refused the second file as "unrecognized arguments"."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SUMO = str(ROOT / "specs" / "toy_sumo.xpdl")
VACUUM = str(ROOT / "specs" / "vacuum_cleaner.xpdl")


def test_validate_checks_a_file_after_an_option(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", SUMO, "--json", VACUUM]) == 0
    paths = [json.loads(line)["path"] for line in capsys.readouterr().out.splitlines()]
    assert paths == [SUMO, VACUUM]


def test_check_checks_a_file_after_an_option(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", SUMO, "--json", VACUUM]) == 0
    paths = [json.loads(line)["path"] for line in capsys.readouterr().out.splitlines()]
    assert paths == [SUMO, VACUUM]


def test_a_command_of_one_file_still_refuses_a_second(
        capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["run", SUMO, "--timeline", "none", VACUUM])
    assert exit_.value.code == 2
    assert f"unrecognized arguments: {VACUUM}" in capsys.readouterr().err


def test_an_unknown_option_beside_a_file_is_still_refused(
        capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["validate", SUMO, "--stict", VACUUM])
    assert exit_.value.code == 2
    assert "--stict: did you mean --strict?" in capsys.readouterr().err
