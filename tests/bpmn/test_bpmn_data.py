"""BPMN data: data objects, input/output specifications, data associations, Camunda form
fields and input/output parameters become the model's data fields, and runs give the values
SpiffWorkflow's own tests expect (each test names the SpiffWorkflow test it follows; the
files are unchanged copies, tests/bpmn/data/README.md)."""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pytest
from lxml import etree

import opspec
from opspec.cli import main
from opspec.errors import Severity
from opspec.model.data import BasicKind, ParameterMode
from opspec.testing import parse_script
from opspec.xpdl.loader import load_package
from opspec.xpdl.validate import validate_spec

DATA = Path(__file__).parent / "data"
BPMN = "http://www.omg.org/spec/BPMN/20100524/MODEL"


def _changes(outcome: opspec.RunOutcome, process: str | None = None
             ) -> list[tuple[float, str, dict[str, Any]]]:
    return [(round(e.time, 3), e.activity or "", dict(e.data)) for e in outcome.trace
            if e.kind == "data.changed" and (process is None or e.process == process)]


def _final(outcome: opspec.RunOutcome, process: str) -> dict[str, Any]:
    """The last value each field of ``process`` was given."""
    values: dict[str, Any] = {}
    for _time, _activity, change in _changes(outcome, process):
        values.update(change)
    return values


def _completed(outcome: opspec.RunOutcome) -> list[str]:
    return [e.activity or "" for e in outcome.trace if e.kind == "activity.completed"]


def _ended(outcome: opspec.RunOutcome) -> list[str]:
    return [e.kind for e in outcome.trace if e.kind.startswith("process.")]


class FormFiller:
    """A user who completes each offered form ``at`` seconds into the run, supplying the
    values given for its activity (values with spaces, which script words cannot carry)."""

    def __init__(self, at: float, values: Mapping[str, Mapping[str, Any]]) -> None:
        self.at = at
        self.values = values
        self.offered: list[tuple[float, str]] = []

    def attach(self, session: Any) -> None:
        self.session = session

    def offer(self, item: Any) -> None:
        now = self.session.now
        self.offered.append((round(now, 3), item.activity))
        self.session.call_later(max(self.at - now, 0.0), lambda: self.session.complete(
            item, self.values.get(item.activity)))

    def withdraw(self, item: Any, reason: str) -> None:
        pass


# -- SpiffWorkflow's data tests -----------------------------------------------------------

def test_a_data_object_set_by_a_task_decides_the_gateway() -> None:
    # DataObjectGatewayTest: the task sets the data object val = True; the gateway reads
    # the data object: the path ends at 'yes', not at 'no'
    outcome = opspec.run(DATA / "spiff_data_object_gateway.bpmn",
                         script=parse_script([(0, "complete set_data val=true")]))
    done = _completed(outcome)
    assert "yes" in done and "no" not in done
    assert _changes(outcome) == [(0.0, "set_data", {"val": True})]
    assert _ended(outcome) == ["process.started", "process.completed"]


def test_a_data_object_written_by_a_user_task_is_seen_by_the_tasks_after_it() -> None:
    # DataObjectReferenceTest: generate_data's output association copies obj_1 out of the
    # task ('hello'); the sub-process's task can write it again ('hello again')
    package = load_package(DATA / "spiff_data_object.bpmn").package
    assert package is not None
    process = package.processes[0]
    assert [f.id for f in process.data_fields] == ["obj_1"]      # one field, four references
    outcome = opspec.run(DATA / "spiff_data_object.bpmn", script=parse_script([
        (1, 'complete generate_data obj_1="hello"'), (1, "complete task_1"),
        (1, "complete read_data"), (1, 'complete placeholder obj_1="hello_again"')]))
    assert _changes(outcome) == [(1.0, "generate_data", {"obj_1": "hello"}),
                                 (4.0, "placeholder", {"obj_1": "hello_again"})]
    assert _ended(outcome) == ["process.started", "process.completed"]


def test_a_task_input_output_specification() -> None:
    # IOSpecOnTaskTest: the script's tuple assignment sets in_1 = 1, in_2 = 'hello world';
    # the manual task's outputs out_1, out_2 are what its performer supplies
    package = load_package(DATA / "spiff_io_spec_on_task.bpmn").package
    assert package is not None
    fields = {f.id for f in package.processes[0].data_fields}
    assert {"in_1", "in_2", "out_1", "out_2"} <= fields
    outcome = opspec.run(DATA / "spiff_io_spec_on_task.bpmn",
                         script=parse_script([(1, "complete any_task out_1=1 out_2=bye")]))
    final = _final(outcome, "main")
    assert final == {"in_1": 1, "in_2": "hello world", "unused": True, "out_1": 1,
                     "out_2": "bye"}
    assert _ended(outcome) == ["process.started", "process.completed"]


def test_a_missing_task_input_is_refused_at_the_inputs_line(tmp_path: Path) -> None:
    # IOSpecOnTaskTest.testIOSpecOnTaskMissingInput: with the script setting only in_1,
    # SpiffWorkflow raises a WorkflowDataException naming data input in_2; opspec refuses the
    # file, at the line of that dataInput
    text = (DATA / "spiff_io_spec_on_task.bpmn").read_text(encoding="utf-8")
    text = text.replace('in_1, in_2, unused = 1, "hello world", True', "in_1, unused = 1, True")
    spec = tmp_path / "missing_input.bpmn"
    spec.write_text(text, encoding="utf-8")
    _package, report = validate_spec(spec)
    errors = [d for d in report.diagnostics if d.severity is Severity.ERROR]
    assert [(d.code, d.location.line) for d in errors] == [("undefined-data-field", 20)]
    assert "'in_2'" in errors[0].message and "dataObject" in errors[0].hint


def test_a_call_activity_passes_inputs_and_gets_outputs_by_name(tmp_path: Path) -> None:
    # CallActivityDataTest (io_spec.bpmn + io_spec_parent.bpmn, loaded together there; here
    # the called process is put into the caller's file, since opspec calls into one package):
    # the caller's in_1, in_2 go in, out_1 = in_1 * 2 and out_2 = in_2.upper() come back,
    # the caller's own variables are unchanged
    called = load_package(DATA / "spiff_io_spec.bpmn").package
    assert called is not None
    formals = [(f.id, f.mode) for f in called.processes[0].formal_parameters]
    assert formals == [("in_1", ParameterMode.IN), ("in_2", ParameterMode.IN),
                       ("out_1", ParameterMode.OUT), ("out_2", ParameterMode.OUT)]
    parent = etree.parse(str(DATA / "spiff_io_spec_parent.bpmn"))
    process = etree.parse(str(DATA / "spiff_io_spec.bpmn")).getroot().find(f"{{{BPMN}}}process")
    assert process is not None
    parent.getroot().insert(1, process)
    merged = tmp_path / "io_spec_together.bpmn"
    parent.write(str(merged))
    outcome = opspec.run(merged)
    assert _final(outcome, "parent") == {"in_1": 1, "in_2": "hello world", "unused": True,
                                         "out_1": 2, "out_2": "HELLO WORLD"}
    assert _final(outcome, "subprocess")["unused"] is False      # the callee's own variable
    assert _ended(outcome).count("process.completed") == 2


def test_a_tuple_assignment_script() -> None:
    # PythonScriptEngineEnvironmentTest (script-start.bpmn): x, y = 1, 2; z = x + y
    outcome = opspec.run(DATA / "spiff_script-start.bpmn",
                         script=parse_script([(1, "complete manual")]))
    assert _final(outcome, "Process_cozt5fu") == {"x": 1, "y": 2, "z": 3}
    assert _ended(outcome) == ["process.started", "process.completed"]


def test_forms_in_a_loop_under_a_non_interrupting_timer() -> None:
    # NITimerDurationTest: one ready form until the 0.2 s timer fires, then two; work_done =
    # 'Yes' ends the loop, and the workflow ends with work_done 'Yes', delay_reason 'Just
    # Because'
    user = FormFiller(0.3, {"Activity_Work": {"work_done": "Yes"},
                            "GetReason": {"delay_reason": "Just Because"}})
    outcome = opspec.run(DATA / "spiff_timer-non-interrupt-boundary.bpmn",
                         performers={"user": user})
    assert user.offered == [(0.0, "Activity_Work"), (0.2, "GetReason")]
    assert _final(outcome, "NonInterruptTimer") == {"work_done": "Yes",
                                                    "delay_reason": "Just Because"}
    assert _ended(outcome) == ["process.started", "process.completed"]


def test_an_interrupting_timer_ends_a_form_loop() -> None:
    # TimerDurationTest (boundary.bpmn): the 0.03 s timer cancels the sub-process whose form
    # keeps asking "Are we there yet?" (answer defaults to 'No'); the remaining manual tasks
    # then complete the workflow
    package = load_package(DATA / "spiff_boundary.bpmn").package
    assert package is not None
    answer = next(f for f in package.processes[0].data_fields if f.id == "answer")
    assert (answer.type.kind, answer.initial) == (BasicKind.STRING, "No")
    outcome = opspec.run(DATA / "spiff_boundary.bpmn", script=parse_script([
        (0, "complete Activity_09c27ms"), (1, "complete Activity_1ya1db2"),
        (1, "complete StopCar"), ("otherwise", "wait")]))   # nobody answers "Are we there yet?"
    withdrawn = [e.activity for e in outcome.trace if e.kind == "activity.withdrawn"]
    assert "Activity_Pester_Dad" in withdrawn
    assert {"Activity_1ya1db2", "StopCar"} <= set(_completed(outcome))
    assert "Subworkflow" not in _completed(outcome)
    assert _ended(outcome) == ["process.started", "process.completed"]


def test_lanes_and_a_boolean_form_field() -> None:
    # SwimLaneTest: A1 in lane A, then the tasks of lane B; NeedClarification (a boolean
    # form field, default "No") false leads on to lane C and its sub-process task
    package = load_package(DATA / "spiff_lanes.bpmn").package
    assert package is not None
    field = next(f for f in package.processes[0].data_fields if f.id == "NeedClarification")
    assert (field.type.kind, field.initial) == (BasicKind.BOOLEAN, False)
    outcome = opspec.run(DATA / "spiff_lanes.bpmn", script=parse_script([
        (1, "complete Activity_B1 NeedClarification=false"), ("otherwise", "complete")]))
    offered = [(e.activity, e.lane) for e in outcome.trace if e.kind == "activity.offered"]
    assert offered == [("Activity_A1", "A_id"), ("Activity_B1", "B_id"),
                       ("Implement_Feature", "B_id"), ("Activity_1uksrqx", "Lane_03noz08"),
                       ("SubProcessTask", "Lane_03noz08")]


# -- Camunda ------------------------------------------------------------------------------

def test_a_camunda_start_form_gives_typed_fields_with_defaults() -> None:
    # camunda-bpm-examples parse-bpmn: the start form declares name (string, 'test') and age
    # (long, 0); foo is set by a camunda:expression opspec does not run, so it is a run input
    # (issue 28): said at the first condition reading it, given with --param foo=...
    package, report = validate_spec(DATA / "camunda_parse-bpmn_process.bpmn")
    assert package is not None
    fields = {f.id: (f.type.kind, f.initial) for f in package.processes[0].data_fields}
    assert fields == {"name": (BasicKind.STRING, "test"), "age": (BasicKind.INTEGER, 0)}
    assert report.ok
    inputs = [d for d in report.diagnostics if d.code == "run-input"]
    assert [(d.location.line, d.severity) for d in inputs] == [(24, Severity.WARNING)]
    assert "'foo'" in inputs[0].message and "--param foo=" in inputs[0].hint
    assert [f.id for f in package.data_fields] == ["foo"]       # package-wide: params set it
    codes = {d.code for d in report.diagnostics}
    assert {"form-fields", "script-output"} <= codes          # println is skipped, said so


def test_a_camunda_output_parameter_computed_by_a_script_is_supplied_by_a_performer() -> None:
    # camunda-bpm-examples rest-service: the connector's output parameter isHoliday comes from
    # parseHoliday.js, which opspec does not run: a located warning, and the field exists
    package, report = validate_spec(DATA / "camunda_rest-service_invokeRestService.bpmn")
    assert package is not None and report.ok
    warning = next(d for d in report.diagnostics if d.code == "parameter-not-run")
    assert warning.location.line == 18 and "isHoliday" in warning.message
    assert "isHoliday" in {f.id for f in package.processes[0].data_fields}
    # the connector's own inputs (url, method, headers) are not data of the process
    assert not {"url", "method", "headers"} & {f.id for f in package.processes[0].data_fields}


CAMUNDA_FORM = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"
    xmlns:camunda="http://camunda.org/schema/1.0/bpmn" id="d" targetNamespace="t">
  <bpmn:process id="approval" isExecutable="true">
    <bpmn:startEvent id="start"/>
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="prepare"/>
    <bpmn:serviceTask id="prepare">
      <bpmn:extensionElements>
        <camunda:inputOutput>
          <camunda:inputParameter name="limit">${500 * 2}</camunda:inputParameter>
          <camunda:outputParameter name="status">checked</camunda:outputParameter>
        </camunda:inputOutput>
      </bpmn:extensionElements>
    </bpmn:serviceTask>
    <bpmn:sequenceFlow id="f2" sourceRef="prepare" targetRef="approve"/>
    <bpmn:userTask id="approve">
      <bpmn:extensionElements>
        <camunda:formData>
          <camunda:formField id="approved" type="boolean" defaultValue="false"/>
          <camunda:formField id="amount" type="long"/>
        </camunda:formData>
      </bpmn:extensionElements>
    </bpmn:userTask>
    <bpmn:sequenceFlow id="f3" sourceRef="approve" targetRef="decide"/>
    <bpmn:exclusiveGateway id="decide" default="no"/>
    <bpmn:sequenceFlow id="yes" sourceRef="decide" targetRef="paid">
      <bpmn:conditionExpression>${approved &amp;&amp; amount &lt;= limit}</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:sequenceFlow id="no" sourceRef="decide" targetRef="refused"/>
    <bpmn:endEvent id="paid"/>
    <bpmn:endEvent id="refused"/>
  </bpmn:process>
</bpmn:definitions>
"""


@pytest.mark.parametrize(("action", "end"), [
    ("complete approve approved=true amount=800", "paid"),
    ("complete approve approved=true amount=1500", "refused"),     # over limit = 500 * 2
    ("complete approve amount=800", "refused"),                   # approved keeps its default
])
def test_a_camunda_form_is_submitted_by_the_performers_completion(
        tmp_path: Path, action: str, end: str) -> None:
    spec = tmp_path / "approval.bpmn"
    spec.write_text(CAMUNDA_FORM, encoding="utf-8")
    outcome = opspec.run(spec, script=parse_script([(5, action)]))
    assert end in _completed(outcome)
    final = _final(outcome, "approval")
    assert (final["limit"], final["status"]) == (1000, "checked")
    assert _ended(outcome) == ["process.started", "process.completed"]


# -- the format is reported honestly --------------------------------------------------------

def test_validate_and_show_report_bpmn_as_bpmn(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["validate", "--json", str(DATA / "spiff_timer.bpmn")]) == 0
    assert json.loads(capsys.readouterr().out)["version"] == "BPMN 2.0"
    assert main(["show", str(DATA / "spiff_timer.bpmn")]) == 0
    assert "(BPMN 2.0, " in capsys.readouterr().out.splitlines()[0]
    xpdl = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"
    assert main(["validate", "--json", str(xpdl)]) == 0
    assert json.loads(capsys.readouterr().out)["version"] == "2.1"
    assert main(["show", str(xpdl)]) == 0
    assert "(XPDL 2.1, " in capsys.readouterr().out.splitlines()[0]


def test_the_undefined_field_hint_follows_the_notation(tmp_path: Path) -> None:
    xpdl = tmp_path / "p.xpdl"
    xpdl.write_text("""<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p">
  <WorkflowProcesses><WorkflowProcess Id="w"><Activities>
    <Activity Id="a"><Route/></Activity><Activity Id="b"><Route/></Activity>
  </Activities><Transitions>
    <Transition Id="t" From="a" To="b"><Condition Type="CONDITION">x &gt; 1</Condition></Transition>
  </Transitions></WorkflowProcess></WorkflowProcesses>
</Package>""", encoding="utf-8")
    _package, report = validate_spec(xpdl)
    hint = next(d.hint for d in report.diagnostics if d.code == "undefined-data-field")
    assert hint == "declare a DataField 'x' or fix the name"
    # in BPMN a condition's unset variable is a run input (issue 28); a script reading one is
    # still an error, with the BPMN way to declare it
    bpmn = tmp_path / "p.bpmn"
    bpmn.write_text("""<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d">
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="s"/><bpmn:sequenceFlow id="f1" sourceRef="s" targetRef="t"/>
    <bpmn:scriptTask id="t"><bpmn:script>y = x + 1</bpmn:script></bpmn:scriptTask>
  </bpmn:process>
</bpmn:definitions>""", encoding="utf-8")
    _package, report = validate_spec(bpmn)
    hint = next(d.hint for d in report.diagnostics if d.code == "undefined-data-field")
    assert "bpmn:dataObject or bpmn:property with id 'x'" in hint
