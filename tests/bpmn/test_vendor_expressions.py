"""Camunda's JUEL conditions (and Spin's JSON accessors) run where they are pure reads and
comparisons (docs/bpmn.md, the table of Camunda expressions), and are refused at their line
otherwise. The expected branches are worked by hand from the JUEL meaning of each operator
(Jakarta Expression Language 4.0, §1.8-1.10: ``eq``/``ne``/``lt``/``gt``/``le``/``ge``,
``empty``, ``and``/``or``/``not``)."""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec


def _diagram(tmp_path: Path, condition: str, fields: str) -> Path:
    text = f"""<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"
    xmlns:opspec="urn:opspec:sisarl:1" id="d" targetNamespace="t">
  <bpmn:extensionElements>{fields}</bpmn:extensionElements>
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start"/>
    <bpmn:sequenceFlow id="f0" sourceRef="start" targetRef="g"/>
    <bpmn:exclusiveGateway id="g" default="otherwise"/>
    <bpmn:sequenceFlow id="chosen" sourceRef="g" targetRef="yes">
      <bpmn:conditionExpression>${{{condition}}}</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:sequenceFlow id="otherwise" sourceRef="g" targetRef="no"/>
    <bpmn:endEvent id="yes"/>
    <bpmn:endEvent id="no"/>
  </bpmn:process>
</bpmn:definitions>
"""
    path = tmp_path / "juel.bpmn"
    path.write_text(text, encoding="utf-8")
    return path


def _field(name: str, kind: str, value: str) -> str:
    return f'<opspec:DataField Id="{name}" Type="{kind}" InitialValue="{value}"/>'


def _end(path: Path) -> str:
    outcome = opspec.run(path)
    return next(e.activity or "" for e in outcome.trace if e.kind == "activity.completed"
                and e.activity in ("yes", "no"))


@pytest.mark.parametrize(("condition", "fields", "end"), [
    ("score gt 50", _field("score", "INTEGER", "70"), "yes"),
    ("score le 50", _field("score", "INTEGER", "70"), "no"),
    ("score ge 70 and score lt 71", _field("score", "INTEGER", "70"), "yes"),
    ("score ne 70 or score eq 71", _field("score", "INTEGER", "70"), "no"),
    ("not empty name", _field("name", "STRING", "Ada"), "yes"),
    ("empty name", _field("name", "STRING", "Ada"), "no"),
    ('execution.getVariable("approved")', _field("approved", "BOOLEAN", "true"), "yes"),
    ('status.equals("ok")', _field("status", "STRING", "ok"), "yes"),
    ('status eq "a eq b"', _field("status", "STRING", "ok"), "no"),     # eq inside a string
])
def test_a_pure_juel_condition_decides_as_juel_defines(tmp_path: Path, condition: str,
                                                      fields: str, end: str) -> None:
    path = _diagram(tmp_path, condition.replace("&", "&amp;"), fields)
    _package, report = validate_spec(path)
    assert report.ok, report.lines()
    assert _end(path) == end


def test_spin_json_accessors_read_a_record_field(tmp_path: Path) -> None:
    record = _field("customer", "STRING", "")
    condition = 'S(customer).prop("age").numberValue() ge 18'
    path = _diagram(tmp_path, condition, record)
    package, report = validate_spec(path)
    # the condition reads customer.age; the reader's translation is what the parser got
    flow = next(t for t in package.processes[0].transitions if t.id == "chosen")
    assert flow.condition.text == condition            # the file's text is kept as written
    assert "customer" in repr(flow.condition.expression) and "age" in repr(
        flow.condition.expression)


@pytest.mark.parametrize("condition", [
    'execution.setVariable("x", 1)',        # an effect, not a read
    "bean.check(score)",                     # a call into the application
])
def test_a_juel_expression_that_is_no_pure_read_is_refused_at_its_line(
        tmp_path: Path, condition: str) -> None:
    path = _diagram(tmp_path, condition, _field("score", "INTEGER", "1"))
    _package, report = validate_spec(path)
    errors = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    assert [(d.code, d.location.line) for d in errors] == [("bad-condition", 10)]
