"""The command line's usage help: a mistyped option shows the subcommand it belongs to, and
the shell completes commands and options (argcomplete)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.mark.parametrize("command", [["run"], ["evaluate"], ["validate"], ["show"]])
def test_an_unknown_option_prints_the_subcommands_usage(command, capsys):
    with pytest.raises(SystemExit) as exit_:
        main([*command, str(SPEC), "--bogus-option"])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(f"usage: opspec {command[0]} ")
    assert f"opspec {command[0]}: error: unrecognized arguments: --bogus-option" in err


def _complete(line: str, tmp_path: Path) -> list[str]:
    """What argcomplete offers the shell for ``line`` (the cursor at its end)."""
    out = tmp_path / "completions"
    env = {**os.environ, "_ARGCOMPLETE": "1", "_ARGCOMPLETE_IFS": "\n", "COMP_LINE": line,
           "COMP_POINT": str(len(line)), "_ARGCOMPLETE_STDOUT_FILENAME": str(out),
           "OPSPEC_PURE_PYTHON": "1"}
    done = subprocess.run([sys.executable, "-m", "opspec"], env=env, cwd=tmp_path,
                          capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    return out.read_text(encoding="utf-8").split("\n")


def test_the_shell_completes_commands_and_their_options(tmp_path):
    pytest.importorskip("argcomplete", reason="argcomplete is a dependency: pip install -e .")
    assert [c.strip() for c in _complete("opspec eva", tmp_path)] == ["evaluate"]
    options = _complete("opspec evaluate --us", tmp_path)
    assert {"--users", "--user-model", "--users-per-draw"} <= {c.strip() for c in options}


@pytest.mark.parametrize("command", [[], ["run"], ["evaluate"], ["validate"]])
def test_the_help_texts_name_bpmn(command, capsys):
    """BPMN 2.0 files run, evaluate and validate like XPDL ones (docs/bpmn.md); the help of
    each command that takes a spec says so."""
    with pytest.raises(SystemExit):
        main([*command, "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "BPMN 2.0" in out or ".bpmn" in out


def test_validate_a_folder_finds_bpmn_files(tmp_path, capsys):
    (tmp_path / "dispenser.bpmn").write_bytes((ROOT / "specs" / "medication_dispenser.bpmn")
                                              .read_bytes())
    status = main(["validate", str(tmp_path)])
    out = capsys.readouterr().out
    assert "1 file checked" in out and status in (0, 1)
