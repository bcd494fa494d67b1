"""`opspec check` reads a compiled workflow script (.wfs) as show, run and evaluate do, and
gives its problems at the lines of the spec it was compiled from. It refused the script as
'not checked: the file could not be read as a spec', exit status 1, as if the spec had
errors."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]

# A process with an island: y and z lead to each other, no start leads to them (dead).
DEAD = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2026</Created></PackageHeader>
  <WorkflowProcesses>
    <WorkflowProcess Id="w">
      <ProcessHeader/>
      <Activities>
        <Activity Id="s"><Event><StartEvent Trigger="None"/></Event></Activity>
        <Activity Id="e"><Event><EndEvent Result="None"/></Event></Activity>
        <Activity Id="y"><Implementation><No/></Implementation></Activity>
        <Activity Id="z"><Implementation><No/></Implementation></Activity>
      </Activities>
      <Transitions>
        <Transition Id="t0" From="s" To="e"/>
        <Transition Id="t1" From="z" To="y"/>
        <Transition Id="t2" From="y" To="z"/>
      </Transitions>
    </WorkflowProcess>
  </WorkflowProcesses>
</Package>
"""


def test_a_sound_script_is_called_sound(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "dispenser.xpdl"
    shutil.copyfile(ROOT / "specs" / "medication_dispenser.xpdl", spec)
    assert main(["compile", str(spec)]) == 0
    capsys.readouterr()
    assert main(["check", str(tmp_path / "dispenser.wfs")]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == (
        f"{tmp_path / 'dispenser.wfs'}: 4 of 4 process level(s) sound, 0 problem(s)")


def test_a_script_s_problems_are_at_its_spec_s_lines(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    Path("dead.xpdl").write_text(DEAD, encoding="utf-8")
    assert main(["compile", "dead.xpdl"]) == 0
    capsys.readouterr()
    assert main(["check", "dead.xpdl"]) == 1
    from_spec = capsys.readouterr().out.splitlines()
    assert from_spec[:2] == ["dead.xpdl:10: error: w: dead activity: 'y' can never run",
                             "dead.xpdl:11: error: w: dead activity: 'z' can never run"]
    assert main(["check", "dead.wfs"]) == 1
    from_script = capsys.readouterr().out.splitlines()
    assert from_script[:2] == from_spec[:2]
    assert from_script[2:] == [line.replace("dead.xpdl:", "dead.wfs:")
                               for line in from_spec[2:]]
    assert main(["check", "dead.wfs", "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert (report["path"], report["lines_in"], report["loaded"]) == ("dead.wfs", "dead.xpdl",
                                                                      True)
    assert [(p["kind"], p["activity"], p["line"]) for p in report["problems"]] == [
        ("dead", "y", 10), ("dead", "z", 11)]


def test_a_corrupt_script_is_said_in_one_line_and_not_checked(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    script = tmp_path / "broken.wfs"
    script.write_text('{"format": "opspec-wfs", "vers', encoding="utf-8")
    assert main(["check", str(script)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"{script}:1: error: corrupt workflow script (invalid JSON")
    assert out[1].startswith(f"{script}: not checked:")
