"""Script tasks and conditions written in Python (SpiffWorkflow) or JUEL/JavaScript/Groovy
(Camunda): what is in opspec's expression grammar runs, the rest is refused at its own line
with the construct named; nothing is silently skipped except output statements."""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

DATA = Path(__file__).parent / "data"

HEAD = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d"
    targetNamespace="t">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start"/>
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="s"/>
    <bpmn:scriptTask id="s">
      <bpmn:script>"""          # the script's first line is line 8 of the file
TAIL = """</bpmn:script>
    </bpmn:scriptTask>
    <bpmn:sequenceFlow id="f2" sourceRef="s" targetRef="g"/>
    <bpmn:exclusiveGateway id="g" default="other"/>
    <bpmn:sequenceFlow id="chosen" sourceRef="g" targetRef="yes">
      <bpmn:conditionExpression>{condition}</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:sequenceFlow id="other" sourceRef="g" targetRef="no"/>
    <bpmn:endEvent id="yes"/>
    <bpmn:endEvent id="no"/>
  </bpmn:process>
</bpmn:definitions>
"""


def _spec(tmp_path: Path, script: str, condition: str = "x == 1") -> Path:
    path = tmp_path / "script.bpmn"
    path.write_text(HEAD + script + TAIL.replace("{condition}", condition), encoding="utf-8")
    return path


def _errors(path: Path) -> list[tuple[str, int | None, str]]:
    _package, report = validate_spec(path)
    return [(d.code, d.location.line, d.message) for d in report.diagnostics
            if d.severity is Severity.ERROR]


def _end(path: Path) -> str:
    outcome = opspec.run(path)
    return next(e.activity or "" for e in outcome.trace if e.kind == "activity.completed"
                and e.activity in ("yes", "no"))


def test_spiffworkflows_script_test_is_refused_statement_by_statement() -> None:
    # ScriptTest.bpmn builds dicts and lists, defines a function, assigns an item and uses a
    # comprehension: none of it is opspec's grammar, each is named at its own line
    errors = _errors(DATA / "spiff_ScriptTest.bpmn")
    assert [(code, line) for code, line, _ in errors] == [
        ("bad-script", 11), ("bad-script", 12), ("bad-script", 24), ("bad-script", 27),
        ("bad-script", 28)]
    named = [message.split("cannot be run: ", 1)[1] for _, _, message in errors]
    assert named[0].startswith("a dict or set literal")
    assert named[1].startswith("a list literal")
    assert named[2].startswith("a function definition (def)")
    assert named[3].startswith("an assignment to an item (testvar['new'])")
    assert named[4].startswith("a comprehension")


def test_assignments_tuples_augmented_and_comments_run(tmp_path: Path) -> None:
    path = _spec(tmp_path, "# set up\nx, y = 0, 'a'   # two at once\nx += 1; y = y.upper()\n"
                 "print(f'x is {x}')")
    _package, report = validate_spec(path)
    assert report.ok, report.lines()
    printed = next(d for d in report.diagnostics if d.code == "script-output")
    assert (printed.severity, printed.location.line) == (Severity.INFO, 11)
    outcome = opspec.run(path)
    values: dict[str, object] = {}
    for event in outcome.trace:
        if event.kind == "data.changed":
            values.update(event.data)
    assert values == {"x": 1, "y": "A"}
    assert _end(path) == "yes"


@pytest.mark.parametrize(("script", "line", "named"), [
    ("x = 1\na, b = b, a", 9, "the value of 'b' reads 'a', which the same statement assigns"),
    ("x = 1\na, b = f()", 9, "unpacking 1 value into 2 names"),
    ("x = 1\nif x > 0:\n    x = 2", 9, "an if statement"),
    ("x = 1\nfor i in range(3):\n    x += i", 9, "a for loop"),
    ("import math\nx = 1", 8, "an import"),
    ("x = 1\ndel(x)", 9, "a del statement"),
    ("x = 1\nrecord.kind = 'a'", 9, "an assignment to an attribute (record.kind)"),
    ("x = 1\nx = y = 2", 9, "a chained assignment"),
    ("x = 1\nitems = [1,\n  2", 9, "a bracket opened here is never closed"),
    ("x = 1\nwhen = datetime.now()", 9, "Python's datetime module"),
    ("x = 1\nn = 2 ** 3", 9, "the power operator **"),
])
def test_what_is_not_in_the_grammar_is_refused_at_its_line(
        tmp_path: Path, script: str, line: int, named: str) -> None:
    errors = _errors(_spec(tmp_path, script))
    assert [(code, at) for code, at, _ in errors] == [("bad-script", line)], errors
    assert named in errors[0][2]


@pytest.mark.parametrize(("condition", "end"), [
    ("x == 1 and not (y != 'a')", "yes"),
    ("x is not None", "yes"),
    ("y is None", "no"),
    ("${x &gt; 0 &amp;&amp; y == 'a'}", "yes"),          # Camunda's JUEL wrapper
    ("x = 1", "yes"),                                    # = is equality in a condition
])
def test_python_and_juel_conditions_in_the_grammar_run(
        tmp_path: Path, condition: str, end: str) -> None:
    path = _spec(tmp_path, "x, y = 1, 'a'", condition)
    assert _errors(path) == []
    assert _end(path) == end


@pytest.mark.parametrize(("condition", "named"), [
    ("x in [1, 2]", "a membership test (x in …)"),
    ("x not in (1, 2)", "a membership test (not in)"),
    ("1 if x else 2", "a conditional expression (a if c else b)"),
    ("data['x'] == 1", "item access (x[…])"),
    ("lambda: x", "a lambda"),
    ("x // 2 == 0", "floor division //"),
])
def test_conditions_outside_the_grammar_are_refused_naming_the_construct(
        tmp_path: Path, condition: str, named: str) -> None:
    errors = _errors(_spec(tmp_path, "x = 1", condition))
    assert [(code, line) for code, line, _ in errors] == [("bad-condition", 13)], errors
    assert named in errors[0][2]


def test_javascript_declarations_and_increments_run(tmp_path: Path) -> None:
    path = _spec(tmp_path, "var x = 0;\nx++;\nlet y = 'a'")
    assert _errors(path) == []
    assert _end(path) == "yes"
