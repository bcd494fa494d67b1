"""A compiled script given to compile (with -o) or preprocess is the wrong file, not a spec
with errors: one line and exit status 2, as `opspec compile IN.wfs` without -o said already.
Both printed the reader's error and '... has errors; nothing written', exit status 1."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.fixture
def script(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    assert main(["compile", str(SPEC), "-o", "dispenser.wfs"]) == 0
    return Path("dispenser.wfs")


@pytest.mark.parametrize("output", [["-o", "again.wfs"], ["-o", "-"]])
def test_compile_refuses_a_script_in_one_line(script: Path, output: list[str],
                                              capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    assert main(["compile", str(script), *output]) == 2
    captured = capsys.readouterr()
    assert captured.err == (
        "opspec compile: dispenser.wfs is already compiled (a workflow script, .wfs); nothing "
        "written. Compile the XPDL it was compiled from, or use dispenser.wfs as it is: "
        "opspec show, run and evaluate read it directly\n")
    assert captured.out == "" and not Path("again.wfs").exists()


@pytest.mark.parametrize("output", [[], ["-o", "-"]])
def test_preprocess_refuses_a_script_in_one_line(script: Path, output: list[str],
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    assert main(["preprocess", str(script), *output]) == 2
    captured = capsys.readouterr()
    assert captured.err == (
        "opspec preprocess: dispenser.wfs is a compiled workflow script (.wfs), not XPDL; "
        "nothing written. Preprocess the XPDL it was compiled from\n")
    assert captured.out == "" and not Path("dispenser.std.xpdl").exists()
