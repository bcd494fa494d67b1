"""A multi-instance over a list given as data (Camunda's ``camunda:collection`` with
``camunda:elementVariable``; Zeebe's ``inputCollection``/``inputElement``) runs one instance
per item, each instance seeing its own item under the element variable (issue 28).

Camunda's reference (docs.camunda.io, Multi-instance): "one instance for every element of the
inputCollection is created (sequentially or in parallel)"; in parallel "The instances are
executed concurrently and independently from each other"; sequentially "When one instance is
completed, a new instance is created for the next element in the inputCollection" — each
instance sees its own element (inputElement / camunda:elementVariable), not a neighbour's.
BPMN 2.0 §10.2.8, Table 10.29 (MultiInstanceLoopCharacteristics, loopDataInputRef): "This
DataInput is used to determine the number of Activity instances, one Activity instance per item
in the collection of data stored in that DataInput element." — Camunda's collection is the
same rule with the list named by an expression.
"""

from __future__ import annotations

import json
import subprocess
from collections import Counter
from pathlib import Path
from typing import Any

import pytest

import opspec
from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

DIAGRAM = Path(__file__).parent / "data" / "written" / "camunda_mi_collection.bpmn"


def _final(outcome: opspec.RunOutcome, name: str) -> object:
    values = [e.data[name] for e in outcome.trace
              if e.kind == "data.changed" and name in e.data]
    return values[-1] if values else None


def _completed(outcome: opspec.RunOutcome, activity: str) -> list[float]:
    return [e.time for e in outcome.trace
            if e.kind == "activity.completed" and e.activity == activity]


def test_each_instance_sees_its_own_item() -> None:
    """Parallel instances of 10 s each end at the same instant: each adds its own score
    (1 + 2 + 3 = 6; instances sharing one variable would all add the last item, 9).
    Sequential instances run in the collection's order: appending each as a digit gives 123.
    """
    _package, report = validate_spec(DIAGRAM)
    assert report.ok, report.lines()
    outcome = opspec.run(DIAGRAM, until=100)
    assert _final(outcome, "total") == 6
    assert _completed(outcome, "weigh") == [10.0, 10.0, 10.0]
    assert _final(outcome, "order") == 123
    assert len(_completed(outcome, "append")) == 3


def test_the_completion_condition_reads_the_completed_instances_item() -> None:
    """BPMN 2.0 (MultiInstanceLoopCharacteristics), completionCondition: "This attribute
    defines a boolean Expression that when evaluated to true, cancels the remaining Activity
    instances and produces a token." — ``${s == 2}`` holds once the instance with item 2
    completes, so the sequential instance for item 3 never starts: 12."""
    outcome = opspec.run(DIAGRAM, until=100)
    assert _final(outcome, "stopped") == 12
    assert [e.kind for e in outcome.trace if e.kind.startswith("process.")] == [
        "process.started", "process.completed"]


def test_the_element_variable_is_not_left_in_the_process_data() -> None:
    """Camunda: the element variable is local to the instance; after the activity, nothing
    wrote it into the process's data."""
    outcome = opspec.run(DIAGRAM, until=100)
    assert not any("score" in e.data or "s" in e.data for e in outcome.trace
                   if e.kind == "data.changed")


def _variant(tmp_path: Path, fields: str, loop: str) -> Path:
    path = tmp_path / "collection.bpmn"
    path.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"
    xmlns:camunda="http://camunda.org/schema/1.0/bpmn"
    xmlns:zeebe="http://camunda.org/schema/zeebe/1.0" xmlns:opspec="urn:opspec:sisarl:1"
    id="d" targetNamespace="t">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:extensionElements>{fields}
      <opspec:DataField Id="total" Type="INTEGER" InitialValue="0"/>
    </bpmn:extensionElements>
    <bpmn:startEvent id="start"/>
    <bpmn:sequenceFlow id="f0" sourceRef="start" targetRef="each"/>
    <bpmn:scriptTask id="each" scriptFormat="python">
      {loop}
      <bpmn:script>total = total + score</bpmn:script>
    </bpmn:scriptTask>
    <bpmn:sequenceFlow id="f1" sourceRef="each" targetRef="end"/>
    <bpmn:endEvent id="end"/>
  </bpmn:process>
</bpmn:definitions>
""", encoding="utf-8")
    return path


CAMUNDA = ('<bpmn:multiInstanceLoopCharacteristics camunda:collection="${scores}" '
           'camunda:elementVariable="score"/>')
ZEEBE = ('<bpmn:multiInstanceLoopCharacteristics><bpmn:extensionElements>'
         '<zeebe:loopCharacteristics inputCollection="= scores" inputElement="score"/>'
         '</bpmn:extensionElements></bpmn:multiInstanceLoopCharacteristics>')


def _list(value: str) -> str:
    return f'<opspec:DataField Id="scores" Type="INTEGER" IsArray="true" InitialValue="{value}"/>'


@pytest.mark.parametrize("loop", [CAMUNDA, ZEEBE], ids=["camunda", "zeebe"])
def test_zeebe_and_camunda_run_alike(tmp_path: Path, loop: str) -> None:
    outcome = opspec.run(_variant(tmp_path, _list("[4, 5]"), loop))
    assert _final(outcome, "total") == 9
    assert len(_completed(outcome, "each")) == 2


def test_an_empty_collection_completes_the_activity_at_once(tmp_path: Path) -> None:
    """BPMN 2.0 Table 10.29, loopDataInputRef: "one Activity instance per item in the
    collection" — none here. §13.3.7 says nothing more of zero instances; with none the
    activity has nothing to wait for: it completes at once and the token moves on (as Camunda 7
    and SpiffWorkflow do for an empty collection, below); no script runs."""
    outcome = opspec.run(_variant(tmp_path, _list("[]"), CAMUNDA))
    assert _final(outcome, "total") is None
    assert _completed(outcome, "end") == [0.0]
    assert [e.kind for e in outcome.trace if e.kind.startswith("process.")] == [
        "process.started", "process.completed"]


def _errors(path: Path) -> list[tuple[str, int | None, str]]:
    _package, report = validate_spec(path)
    return [(d.code, d.location.line, d.message) for d in report.diagnostics
            if d.severity is Severity.ERROR]


@pytest.mark.parametrize(("fields", "says"), [
    ("", "its collection 'scores' is no data field"),
    ('<opspec:DataField Id="scores" Type="INTEGER" InitialValue="3"/>',
     "its collection 'scores' is not a list"),
])
def test_a_missing_or_non_list_collection_is_refused_at_its_line(
        tmp_path: Path, fields: str, says: str) -> None:
    errors = _errors(_variant(tmp_path, fields, CAMUNDA))
    assert [(code, line) for code, line, _ in errors] == [("multi-instance-without-count", 13)]
    assert says in errors[0][2]


def test_a_package_field_that_is_no_list_is_refused_at_its_line(tmp_path: Path) -> None:
    path = _variant(tmp_path, "", CAMUNDA)
    path.write_text(path.read_text(encoding="utf-8").replace(
        '<bpmn:process id="p"', '<bpmn:extensionElements><opspec:DataField Id="scores" '
        'Type="INTEGER" InitialValue="3"/></bpmn:extensionElements><bpmn:process id="p"'),
        encoding="utf-8")
    errors = _errors(path)
    assert [(code, line) for code, line, _ in errors] == [("multi-instance-without-count", 13)]
    assert "its collection 'scores' is not a list" in errors[0][2]


def test_a_sub_process_over_a_collection_is_refused_at_its_line(tmp_path: Path) -> None:
    """The activities inside a sub-process read their process instance's data, not the
    instance's own item: parallel instances would read one another's, so opspec refuses."""
    path = _variant(tmp_path, _list("[1, 2]"), CAMUNDA)
    text = path.read_text(encoding="utf-8").replace(
        '<bpmn:scriptTask id="each" scriptFormat="python">',
        '<bpmn:subProcess id="each"><bpmn:scriptTask id="inner">').replace(
        "</bpmn:scriptTask>", "</bpmn:scriptTask></bpmn:subProcess>")
    # the loop belongs to the sub-process: move it out of the inner task
    text = text.replace(CAMUNDA, "").replace('<bpmn:subProcess id="each">',
                                             '<bpmn:subProcess id="each">' + CAMUNDA)
    path.write_text(text, encoding="utf-8")
    errors = _errors(path)
    assert [code for code, _, _ in errors] == ["multi-instance-without-count"]
    assert "subProcess" in errors[0][2]


class Recorder:
    """A user who completes each offered work item a second later, noting the item each
    instance's work item carries."""

    def __init__(self) -> None:
        self.seen: list[tuple[float, object]] = []

    def attach(self, session: Any) -> None:
        self.session = session

    def offer(self, item: Any) -> None:
        self.seen.append((self.session.now, item.data.get("score")))
        self.session.call_later(1.0, lambda: self.session.complete(item, None))

    def withdraw(self, item: Any, reason: str) -> None:
        pass


@pytest.mark.parametrize(("sequential", "offered"), [
    ("false", [(0.0, 1), (0.0, 2), (0.0, 3)]),
    ("true", [(0.0, 1), (1.0, 2), (2.0, 3)]),
])
def test_each_work_item_carries_its_own_item(tmp_path: Path, sequential: str,
                                              offered: list[tuple[float, int]]) -> None:
    """The performer of each instance's work item sees that instance's element: all three
    at once in parallel, one after another (in the list's order) when sequential."""
    loop = CAMUNDA.replace("/>", f' isSequential="{sequential}"/>')
    path = _variant(tmp_path, _list("[1, 2, 3]"), loop)
    path.write_text(path.read_text(encoding="utf-8").replace(
        '<bpmn:scriptTask id="each" scriptFormat="python">', '<bpmn:userTask id="each">').replace(
        "<bpmn:script>total = total + score</bpmn:script>\n    </bpmn:scriptTask>",
        "</bpmn:userTask>"), encoding="utf-8")
    user = Recorder()
    outcome = opspec.run(path, performers={"user": user})
    assert user.seen == offered
    assert [e.kind for e in outcome.trace if e.kind.startswith("process.")] == [
        "process.started", "process.completed"]


# -- beside SpiffWorkflow ------------------------------------------------------------------

ROOT = Path(__file__).resolve().parents[2]
SPIFF = ROOT / ".spiff-venv" / "bin" / "python"
SPIFF_FILE = ROOT / "tests/differential/data/spiff/camunda/parallel_multiinstance_collection.bpmn"


def _spiff(path: Path, items: list[int]) -> list[str]:
    if not SPIFF.exists():
        pytest.skip("no .spiff-venv (bash scripts/spiff-venv.sh makes it)")
    # (another test process may be making it this moment: the script waits, then checks it)
    if subprocess.run(["bash", str(ROOT / "scripts" / "spiff-venv.sh")], capture_output=True,
                      timeout=600, check=False).returncode != 0:
        pytest.skip("the .spiff-venv does not import SpiffWorkflow (bash scripts/spiff-venv.sh)")
    entry = {"file": str(path), "data": {"input_data": items}, "delay": 0, "parser": "camunda"}
    done = subprocess.run([str(SPIFF), str(ROOT / "tests/differential/spiff_driver.py")],
                          input=json.dumps([entry]), capture_output=True, text=True,
                          timeout=120, check=True)
    result = json.loads(done.stdout.splitlines()[-1])
    assert result["state"] == "completed", result
    return list(result["completed"])


def _declared(tmp_path: Path, items: list[int], sequential: bool) -> Path:
    """SpiffWorkflow's own collection diagram, with the list its test hands the workflow
    declared as opspec data (SpiffWorkflow's Camunda parser ignores the opspec element)."""
    text = SPIFF_FILE.read_text(encoding="utf-8").replace(
        '<bpmn:process id="main" isExecutable="true">',
        '<bpmn:process id="main" isExecutable="true"><bpmn:extensionElements>'
        '<opspec:DataField xmlns:opspec="urn:opspec:sisarl:1" Id="input_data" Type="INTEGER" '
        f'IsArray="true" InitialValue="{json.dumps(items)}"/></bpmn:extensionElements>')
    if sequential:
        text = text.replace('camunda:collection=', 'isSequential="true" camunda:collection=')
    path = tmp_path / ("seq.bpmn" if sequential else "par.bpmn")
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("sequential", [False, True], ids=["parallel", "sequential"])
def test_as_many_instances_as_spiffworkflow_runs(tmp_path: Path, sequential: bool) -> None:
    """SpiffWorkflow 3.2.0 (Camunda parser) given input_data = [1, 2, 3] completes any_task
    three times and ends; opspec, with input_data declared as that list, runs the same flow
    nodes as often (a multiset: BPMN orders nothing between parallel instances)."""
    path = _declared(tmp_path, [1, 2, 3], sequential)
    outcome = opspec.run(path)
    ours = [e.activity for e in outcome.trace if e.kind == "activity.completed"]
    assert Counter(ours) == Counter(_spiff(path, [1, 2, 3])) == Counter(
        {"StartEvent_1": 1, "any_task": 3, "Event_1xk7z3g": 1})


def test_an_empty_collection_ends_as_in_spiffworkflow(tmp_path: Path) -> None:
    """Given input_data = [], SpiffWorkflow runs no instance of any_task and ends; so does
    opspec (its trace records the activity, of no instance, completed once at t = 0, which
    SpiffWorkflow's list of completed tasks does not)."""
    path = _declared(tmp_path, [], False)
    outcome = opspec.run(path)
    ours = [e.activity for e in outcome.trace if e.kind == "activity.completed"]
    assert _spiff(path, []) == ["StartEvent_1", "Event_1xk7z3g"]
    assert ours == ["StartEvent_1", "any_task", "Event_1xk7z3g"]
    assert not any(e.kind == "activity.completed" and "instance" in e.data
                   for e in outcome.trace)


def test_without_an_element_variable_one_instance_runs_per_item(tmp_path: Path) -> None:
    """Camunda 7: elementVariable is optional; without it the instances are counted by the
    collection and read no item."""
    loop = CAMUNDA.replace(' camunda:elementVariable="score"', "")
    path = _variant(tmp_path, _list("[4, 5, 6]"), loop)
    path.write_text(path.read_text(encoding="utf-8").replace("total + score", "total + 1"),
                    encoding="utf-8")
    _package, report = validate_spec(path)
    assert report.ok, report.lines()
    assert _final(opspec.run(path), "total") == 3
