"""What compile and preprocess say when their output cannot be written where the command line
(or the default) puts it: the input already compiled, an output that is the input, a folder
that does not exist. Each names the file and says what to do."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.fixture
def script(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> Path:
    path = tmp_path / "d.wfs"
    assert main(["compile", str(SPEC), "-o", str(path)]) == 0
    capsys.readouterr()
    return path


def test_compiling_a_compiled_script_says_it_is_compiled_already(
        script: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # It said "-o d.wfs is the file this command reads as IN; refusing to overwrite it (give
    # -o another file, e.g. d.wfs beside it)": no -o was given, and d.wfs is IN itself.
    before = script.read_bytes()
    assert main(["compile", str(script)]) == 2
    err = capsys.readouterr().err
    assert err == (f"opspec compile: {script} is already compiled (a workflow script, .wfs); "
                   "nothing written. Compile the XPDL it was compiled from, or use "
                   f"{script} as it is: opspec show, run and evaluate read it directly\n")
    assert script.read_bytes() == before


def test_compiling_a_compiled_script_onto_itself_says_both(
        script: Path, capsys: pytest.CaptureFixture[str]) -> None:
    before = script.read_bytes()
    assert main(["compile", str(script), "-o", str(script)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"opspec compile: -o {script} is IN itself, and {script} is already "
                          "compiled")
    assert "e.g. d.wfs" not in err and err.count("\n") == 1
    assert script.read_bytes() == before


@pytest.mark.parametrize("command, suffix", [("compile", ".wfs"), ("preprocess", ".xpdl")])
def test_an_output_in_a_missing_folder_names_the_folder(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, suffix: str) -> None:
    # It said only "cannot write …: No such file or directory".
    spec = tmp_path / "spec.xpdl"
    shutil.copy(SPEC, spec)
    target = tmp_path / "nodir" / "sub" / f"x{suffix}"
    capsys.readouterr()
    assert main([command, str(spec), "-o", str(target)]) == 2
    err = capsys.readouterr().err
    assert (f"opspec {command}: cannot write {target}: the folder {target.parent} does not "
            "exist (create it first)\n") in err
    assert not target.parent.exists()


def test_an_output_under_a_file_says_the_file_is_not_a_folder(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "spec.xpdl"
    shutil.copy(SPEC, spec)
    target = spec / "x.wfs"
    assert main(["compile", str(spec), "-o", str(target)]) == 2
    assert (f"opspec compile: cannot write {target}: {spec} is a file, not a folder"
            in capsys.readouterr().err)
