"""Issue 33, bounded and located: a value that a spec's assignments grow on every step (a text
appended to itself, an integer squared) stops the run with a located error naming the spec's
file:line, instead of exhausting memory."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main

_SPEC = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="grow" Name="grow">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2026</Created></PackageHeader>
  <WorkflowProcesses>
    <WorkflowProcess Id="p"><ProcessHeader/>
      <DataFields>
        <DataField Id="v"><DataType><BasicType Type="{kind}"/></DataType><InitialValue>{initial}</InitialValue></DataField>
      </DataFields>
      <Activities>
        <Activity Id="grow">
          <Route/>
          <Loop LoopType="Standard"><LoopStandard LoopCondition="true" TestTime="After"/></Loop>
          <Assignments><Assignment AssignTime="End"><Target>v</Target><Expression>{grow}</Expression></Assignment></Assignments>
        </Activity>
      </Activities>
    </WorkflowProcess>
  </WorkflowProcesses>
</Package>
"""


@pytest.mark.parametrize(("kind", "initial", "grow", "said"), [
    ("STRING", "ab", "v + v", "more than 1,000,000"),
    ("INTEGER", "3", "v * v", "more than 1024 bits"),
])
def test_a_value_doubled_on_every_step_is_a_located_error(
        kind: str, initial: str, grow: str, said: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "grow.xpdl"
    text = _SPEC.format(kind=kind, initial=initial, grow=grow)
    spec.write_text(text, encoding="utf-8")
    line = text[:text.index('<Activity Id="grow">')].count("\n") + 1
    status = main(["run", str(spec), "--until", "60", "--timeline", "none"])
    captured = capsys.readouterr()
    err = captured.out + captured.err
    assert status == 1, err
    assert "internal error" not in err and "Traceback" not in err
    assert f"{spec}:" in err and said in err
    assert f"fault: {spec}:{line}: activity 'grow'" in err
