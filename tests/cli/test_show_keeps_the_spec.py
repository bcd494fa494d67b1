"""`opspec show SPEC -o SPEC` refuses, as compile and preprocess do: it wrote the description
over the spec it described (the spec was lost, exit status 0)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


@pytest.mark.parametrize("fmt", ["text", "dot"])
def test_output_naming_the_spec_is_refused_and_the_spec_kept(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], fmt: str) -> None:
    spec = tmp_path / "dispenser.xpdl"
    shutil.copyfile(SPEC, spec)
    before = spec.read_bytes()
    assert main(["show", str(spec), "--format", fmt, "-o", str(spec)]) == 2
    err = capsys.readouterr().err
    assert spec.read_bytes() == before
    suffix = {"text": "txt", "dot": "dot"}[fmt]
    assert err == (f"opspec show: -o {spec} is the file this command reads as SPEC; refusing "
                   f"to overwrite it (give -o another file, e.g. dispenser.{suffix})\n")


def test_a_link_to_the_spec_is_refused_too(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "dispenser.xpdl"
    shutil.copyfile(SPEC, spec)
    link = tmp_path / "link.xpdl"
    link.symlink_to(spec)
    assert main(["show", str(link), "-o", str(spec)]) == 2
    assert "refusing to overwrite it" in capsys.readouterr().err
    assert spec.read_bytes() == SPEC.read_bytes()


def test_a_compiled_script_is_kept_too(tmp_path: Path,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    script = tmp_path / "dispenser.wfs"
    assert main(["compile", str(SPEC), "-o", str(script)]) == 0
    before = script.read_bytes()
    assert main(["show", str(script), "-o", str(script)]) == 2
    assert script.read_bytes() == before
