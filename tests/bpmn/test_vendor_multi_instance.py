"""A multi-instance over a vendor's collection (Camunda's ``camunda:collection`` with
``camunda:elementVariable``, Zeebe's ``inputCollection``/``inputElement``) whose list no data
field holds (the application would set it) is refused once, at the line of its
``multiInstanceLoopCharacteristics``, saying what to declare (issue 28: "runs over a list
given as data ... or refused at its line"). Run over a declared list:
test_collection_multi_instance.py.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

LOOP = {
    "camunda": '<bpmn:multiInstanceLoopCharacteristics camunda:collection="${creditScores}" '
               'camunda:elementVariable="score"/>',
    "zeebe": '<bpmn:multiInstanceLoopCharacteristics><bpmn:extensionElements>'
             '<zeebe:loopCharacteristics inputCollection="= creditScores" inputElement="score"/>'
             '</bpmn:extensionElements></bpmn:multiInstanceLoopCharacteristics>',
}


@pytest.mark.parametrize("vendor", ["camunda", "zeebe"])
def test_a_collection_multi_instance_is_refused_at_its_line_once(tmp_path: Path,
                                                                  vendor: str) -> None:
    path = tmp_path / "loan.bpmn"
    path.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"
    xmlns:camunda="http://camunda.org/schema/1.0/bpmn"
    xmlns:zeebe="http://camunda.org/schema/zeebe/1.0" id="d" targetNamespace="t">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start"/>
    <bpmn:sequenceFlow id="f0" sourceRef="start" targetRef="decide"/>
    <bpmn:task id="decide" name="Decide per score">
      {LOOP[vendor]}
    </bpmn:task>
    <bpmn:sequenceFlow id="f1" sourceRef="decide" targetRef="end"/>
    <bpmn:endEvent id="end"/>
  </bpmn:process>
</bpmn:definitions>
""", encoding="utf-8")
    _package, report = validate_spec(path)
    errors = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    assert len(errors) == 1, [str(e) for e in errors]
    error = errors[0]
    assert error.code == "multi-instance-without-count" and error.location.line == 9
    assert "its collection 'creditScores' is no data field" in error.message
    assert 'IsArray="true"' in (error.hint or "")
