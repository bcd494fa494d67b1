"""A loop's count that is no expression is said at its line, in either reader, and the spec
does not run with a guessed number of instances: the XPDL reader warns where it reads
``MI_Condition`` (the gate then refuses the loop: its number of instances is unknown), the
BPMN reader refuses ``loopCardinality`` at once."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.cli import main
from opspec.errors import Severity
from opspec.xpdl.loader import load_package

ROOT = Path(__file__).resolve().parents[2]
WCP13 = ROOT / "tests" / "patterns" / "specs" / "p13_mi_design_time.xpdl"

BPMN = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="s"/>
    <bpmn:task id="t">
      <bpmn:multiInstanceLoopCharacteristics>
        <bpmn:loopCardinality>3 +* x</bpmn:loopCardinality>
      </bpmn:multiInstanceLoopCharacteristics>
    </bpmn:task>
    <bpmn:endEvent id="e"/>
    <bpmn:sequenceFlow id="f1" sourceRef="s" targetRef="t"/>
    <bpmn:sequenceFlow id="f2" sourceRef="t" targetRef="e"/>
  </bpmn:process>
</bpmn:definitions>
"""


def test_an_xpdl_multi_instance_count_that_is_no_expression(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = WCP13.read_text(encoding="utf-8")
    assert 'MI_Condition="3"' in text
    path = tmp_path / "bad_count.xpdl"
    path.write_text(text.replace('MI_Condition="3"', 'MI_Condition="3 +* x"'), encoding="utf-8")
    line = next(n for n, row in enumerate(path.read_text().splitlines(), 1)
                if "MI_Condition=" in row and "<LoopMultiInstance" in row)
    result = load_package(path)
    found = [d for d in result.diagnostics if d.code == "bad-expression"]
    assert [(d.severity, d.location.path, d.location.line) for d in found] == [
        (Severity.WARNING, str(path), line)]
    assert "multi-instance count '3 +* x' cannot be understood" in found[0].message
    # validate (= run) refuses the loop whose number of instances is unknown
    assert main(["validate", str(path)]) == 1
    out = capsys.readouterr().out
    assert "cannot be evaluated, so the number of instances is unknown" in out
    assert "Traceback" not in out


def test_a_bpmn_loop_cardinality_that_is_no_expression(tmp_path: Path) -> None:
    path = tmp_path / "bad_count.bpmn"
    path.write_text(BPMN, encoding="utf-8")
    result = load_package(path)
    found = [d for d in result.diagnostics if d.code == "bad-expression"]
    assert [(d.severity, d.location.path, d.location.line) for d in found] == [
        (Severity.ERROR, str(path), 7)]
    assert "loopCardinality '3 +* x' cannot be understood" in found[0].message
    assert "e.g. 3 or count + 1" in found[0].hint
    assert not result.ok
