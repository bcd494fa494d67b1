"""A flow node no sequence flow leads to, in a process whose instances start at start events
with a trigger, never runs in those instances: `run` runs only the triggered start event's path
(docs/semantics.md). `validate` says so at the node's line, and `check` reports it dead,
instead of calling the process sound.

BPMN 2.0 §10.4.2 (Start Event): "All Flow Objects that do not have an incoming Sequence Flow
(i.e., are not a target of a Sequence Flow) SHALL be instantiated when the Process is
instantiated." and "Each Start Event is an independent Event. That is, a Process instance
SHALL be generated when the Start Event is triggered." XPDL 2.1 takes its events from BPMN.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.errors import Severity
from opspec.xpdl.validate import validate_spec

from .conftest import DATA, instances, run

QUOTE = ("All Flow Objects that do not have an incoming Sequence Flow (i.e., are not a target "
         "of a Sequence Flow) SHALL be instantiated when the Process is instantiated")


def _gate_warnings(path: Path) -> list[tuple[int | None, str]]:
    _package, report = validate_spec(path)
    return [(d.location.line, d.message) for d in report.diagnostics
            if d.severity is Severity.WARNING and d.code == "runs-differently"]


def _line(path: Path, marker: str) -> int:
    return next(n for n, text in enumerate(path.read_text().splitlines(), 1) if marker in text)


def _check(path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, dict]:
    status = main(["check", "--json", str(path)])
    return status, json.loads(capsys.readouterr().out.splitlines()[-1])


@pytest.mark.parametrize("name", ["unstarted_beside_timer.bpmn", "unstarted_beside_timer.xpdl"])
def test_run_never_runs_it_in_the_instances_a_timer_start_makes(name: str) -> None:
    """The timer start makes an instance at 1 h and at 2 h; each runs "hourly" only: "report"
    (no incoming flow) runs in none of them, and no other instance is made."""
    outcome = run(name, until=7300)
    assert instances(outcome) == [["every_hour", "hourly", "end_hourly"]] * 2


@pytest.mark.parametrize("name", ["unstarted_beside_timer.bpmn", "unstarted_beside_timer.xpdl"])
def test_validate_says_at_its_line_what_opspec_does(name: str) -> None:
    """The difference is not silent: a `runs-differently` warning at the line of "report",
    quoting the standard, saying where it runs and what to do. Its end event has an incoming
    flow and the start event is a start event: nothing else is reported."""
    path = DATA / name
    warnings = _gate_warnings(path)
    assert [line for line, _ in warnings] == [_line(path, 'd="report"')]
    message = warnings[0][1]
    assert QUOTE in message
    assert "never runs in those instances" in message
    _package, report = validate_spec(path)
    hint = next(d.hint for d in report.diagnostics if d.code == "runs-differently")
    assert "add a" in hint and "remove it" in hint


@pytest.mark.parametrize("name", ["unstarted_beside_timer.bpmn", "unstarted_beside_timer.xpdl"])
def test_check_reports_it_dead_instead_of_sound(name: str,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    """`check` plays the instances `run` makes (one per triggered start event): "report" and
    the end event after it can never run. Before, both start nodes were played together in
    one instance and the process was called sound."""
    status, doc = _check(DATA / name, capsys)
    dead = sorted(p["activity"] for p in doc["problems"] if p["kind"] == "dead")
    assert dead == ["end_report", "report"]
    assert status == 1 and doc["sound"] is False
    said = next(p["message"] for p in doc["problems"] if p["activity"] == "report")
    assert "no transition leads to it" in said and "'every_hour'" in said


_NODES = {
    "task": '<bpmn:task id="x"/>',
    "userTask": '<bpmn:userTask id="x"/>',
    "exclusiveGateway": '<bpmn:exclusiveGateway id="x"/>',
    "intermediateCatchEvent": ('<bpmn:intermediateCatchEvent id="x"><bpmn:timerEventDefinition>'
                               '<bpmn:timeDuration>PT1M</bpmn:timeDuration>'
                               '</bpmn:timerEventDefinition></bpmn:intermediateCatchEvent>'),
    "intermediateThrowEvent": '<bpmn:intermediateThrowEvent id="x"/>',
    "endEvent": '<bpmn:endEvent id="x"/>',
    "subProcess": ('<bpmn:subProcess id="x"><bpmn:startEvent id="x_s"/><bpmn:task id="x_t"/>'
                   '<bpmn:sequenceFlow id="x_f" sourceRef="x_s" targetRef="x_t"/>'
                   '</bpmn:subProcess>'),
}


def _bpmn(tmp_path: Path, node: str, start: str = "timer", extra: str = "") -> Path:
    definition = {
        "timer": ("<bpmn:timerEventDefinition><bpmn:timeCycle>R/PT1H</bpmn:timeCycle>"
                  "</bpmn:timerEventDefinition>"),
        "message": '<bpmn:messageEventDefinition messageRef="m"/>',
        "none": ""}[start]
    path = tmp_path / "p.bpmn"
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" '
        'id="d" targetNamespace="urn:t">\n<bpmn:message id="m" name="m"/>\n'
        '<bpmn:process id="p" isExecutable="true">\n'
        f'<bpmn:startEvent id="s">{definition}</bpmn:startEvent>\n<bpmn:task id="a"/>\n'
        '<bpmn:sequenceFlow id="f" sourceRef="s" targetRef="a"/>\n'
        f'{extra}\n{node}\n</bpmn:process>\n</bpmn:definitions>\n')
    return path


@pytest.mark.parametrize("kind", sorted(_NODES))
def test_every_kind_of_flow_node_is_reported(kind: str, tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    """Activities, gateways, intermediate and end events, sub-processes: each is reported at
    its line by validate and dead by check."""
    path = _bpmn(tmp_path, _NODES[kind])
    assert [line for line, _ in _gate_warnings(path)] == [_line(path, 'id="x"')]
    _status, doc = _check(path, capsys)
    assert "x" in {p["activity"] for p in doc["problems"] if p["kind"] == "dead"}


def test_a_message_start_event_counts_as_a_trigger(tmp_path: Path) -> None:
    path = _bpmn(tmp_path, '<bpmn:task id="x"/>', start="message")
    assert [line for line, _ in _gate_warnings(path)] == [_line(path, 'id="x"')]


@pytest.mark.parametrize("node", [
    '<bpmn:task id="x" isForCompensation="true"/>',          # BPMN's own exception
    ('<bpmn:boundaryEvent id="x" attachedToRef="a"><bpmn:timerEventDefinition>'
     '<bpmn:timeDuration>PT1M</bpmn:timeDuration></bpmn:timerEventDefinition>'
     '</bpmn:boundaryEvent>'),                                # its host starts it
])
def test_nodes_the_standard_excepts_are_not_reported(node: str, tmp_path: Path) -> None:
    warnings = _gate_warnings(_bpmn(tmp_path, node))
    assert not [m for _, m in warnings if QUOTE in m]


def test_a_process_start_directive_starts_everything_together(tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]
                                                              ) -> None:
    """opspec:StartTrigger on the process: every instance starts at every start node (the
    engine's process-level trigger), so the node runs and nothing is reported."""
    path = _bpmn(tmp_path, '<bpmn:task id="x"/>')
    text = path.read_text().replace(
        'xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"',
        'xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" '
        'xmlns:opspec="urn:opspec:sisarl:1"').replace(
        '<bpmn:process id="p" isExecutable="true">',
        '<bpmn:process id="p" isExecutable="true"><bpmn:extensionElements>'
        '<opspec:StartTrigger Value="message:m"/></bpmn:extensionElements>')
    path.write_text(text)
    assert not _gate_warnings(path)
    _status, doc = _check(path, capsys)
    assert not [p for p in doc["problems"] if p["kind"] == "dead"]


def test_beside_none_start_events_it_runs_with_its_level_and_nothing_is_said(
        capsys: pytest.CaptureFixture[str]) -> None:
    """Beside none start events only (top level, and in a sub-process) the node starts with
    its level, as §10.4.2 says: run runs it, validate is quiet, check finds it sound."""
    path = DATA / "unstarted_beside_none_start.bpmn"
    outcome = run(path.name, until=60)
    assert sorted(instances(outcome)[0]) == sorted(
        ["begin", "report", "work", "sub_begin", "inner", "inner_report", "sub", "done"])
    assert not _gate_warnings(path)
    status, doc = _check(path, capsys)
    assert status == 0 and doc["sound"] is True


def test_beside_a_none_and_a_timer_start_it_runs_in_the_untriggered_instance(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A none start event beside the timer one: the run's auto-started instance runs the none
    start's path and the node; the timer's instances do not. Validate warns (it is not in
    every instance, as §10.4.2 says), check does not call it dead (it runs)."""
    path = _bpmn(tmp_path, '<bpmn:task id="x"/>', extra=(
        '<bpmn:startEvent id="n"/><bpmn:task id="b"/>'
        '<bpmn:sequenceFlow id="nb" sourceRef="n" targetRef="b"/>'))
    import opspec

    outcome = opspec.run(path, until=7300, seed=0)
    assert sorted(map(sorted, instances(outcome))) == [["a", "s"], ["a", "s"], ["b", "n", "x"]]
    assert [line for line, _ in _gate_warnings(path)] == [_line(path, 'id="x"')]
    _status, doc = _check(path, capsys)
    assert not [p for p in doc["problems"] if p["kind"] == "dead"]


def test_a_called_process_runs_it_and_check_agrees(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """Called from another process, the instance starts at the start nodes that are not
    triggered start events (BPMN 2.0 §13.3.4): the node runs there, so check does not call
    it dead."""
    text = (DATA / "unstarted_beside_timer.xpdl").read_text().replace(
        "  </WorkflowProcesses>",
        '    <WorkflowProcess Id="caller"><ProcessHeader/><Activities>'
        '<Activity Id="c0"><Event><StartEvent Trigger="None"/></Event></Activity>'
        '<Activity Id="call"><Implementation><SubFlow Id="p"/></Implementation></Activity>'
        '</Activities><Transitions><Transition Id="c1" From="c0" To="call"/></Transitions>'
        '</WorkflowProcess>\n  </WorkflowProcesses>')
    path = tmp_path / "called.xpdl"
    path.write_text(text)
    import opspec

    outcome = opspec.run(path, until=60, seed=0)
    assert ["report", "end_report"] in instances(outcome)
    _status, doc = _check(path, capsys)
    assert not [p for p in doc["problems"] if p["kind"] == "dead"]


def test_the_pill_box_of_opspec_new_with_its_escalation_cut_off(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The case found: `opspec new pillx`, then t_escalate sent to end_missed, so that no
    transition leads to tell_caregiver in a process started by a timer. Before: validate 0
    warnings, check "sound"."""
    assert main(["new", str(tmp_path / "pillx")]) == 0
    spec = tmp_path / "pillx" / "pillx.xpdl"
    text = spec.read_text()
    cut = re.sub(r'(<Transition Id="t_escalate" From="record_missed" To=)"tell_caregiver"',
                 r'\1"end_missed"', text)
    assert cut != text
    spec.write_text(cut)
    capsys.readouterr()
    warnings = _gate_warnings(spec)
    assert [line for line, _ in warnings] == [_line(spec, '<Activity Id="tell_caregiver"')]
    status, doc = _check(spec, capsys)
    dead = [p["activity"] for p in doc["problems"] if p["kind"] == "dead"]
    assert dead == ["tell_caregiver"] and status == 1


@pytest.mark.parametrize("name", ["start_trigger_in_sub_process.bpmn",
                                  "start_trigger_in_activity_set.xpdl"])
def test_a_start_trigger_in_a_sub_process_is_ignored_and_validate_says_so(name: str) -> None:
    """BPMN 2.0 §10.4.2: "There is only one type of Start Event for Sub-Processes in BPMN
    (…): None." A timer start event in an embedded sub-process (an XPDL
    activity set) starts with it, at once: "inner" completes at t = 0, not after the hour.
    Validate says so at the start event's line (it said nothing)."""
    from .conftest import completed

    outcome = run(name, until=7200)
    assert (0.0, "inner") in completed(outcome)
    path = DATA / name
    warnings = _gate_warnings(path)
    assert [line for line, _ in warnings] == [
        next(n for n, text in enumerate(path.read_text().splitlines(), 1)
             if 'd="sub_begin"' in text and "tartEvent" in text)]
    assert "its trigger is ignored" in warnings[0][1]


def test_an_event_sub_process_start_trigger_is_not_that_case() -> None:
    """An event sub-process's timer start event is its trigger (opspec runs it): not
    reported as ignored."""
    path = DATA / "event_sub_process_timer.bpmn"
    assert not [m for _, m in _gate_warnings(path) if "its trigger is ignored" in m]
