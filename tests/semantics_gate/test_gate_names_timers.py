"""Part of the gate that is not a construct: misspelt message names, sequence flows without an
id, and timers on which validate and run must agree."""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec.errors import OpspecError, Severity
from opspec.xpdl.validate import FileReport, validate_file

BPMN = "http://www.omg.org/spec/BPMN/20100524/MODEL"


def _bpmn(tmp_path: Path, body: str, top: str = "", name: str = "f.bpmn") -> Path:
    path = tmp_path / name
    path.write_text(f'<definitions xmlns="{BPMN}" id="d" targetNamespace="t">\n{top}'
                    f'<process id="p" isExecutable="true">\n{body}</process>\n'
                    '</definitions>\n', encoding="utf-8")
    return path


MESSAGES = ('<message id="m1" name="report"/>\n<message id="m2" name="reprot"/>\n')


def test_a_misspelt_message_names_the_closest_name(tmp_path):
    """BPMN 2.0 §10.4.5 (Message Event): "A Message arrives from a participant and triggers
    the start of the Process or continues the Process". A message thrown as 'report' and
    awaited as 'reprot' never meets its catcher: validate warns at both lines, naming the
    other spelling."""
    path = _bpmn(tmp_path, '<startEvent id="s"/>\n'
                 '<intermediateThrowEvent id="send"><messageEventDefinition messageRef="m1"/>'
                 '</intermediateThrowEvent>\n'
                 '<intermediateCatchEvent id="wait"><messageEventDefinition messageRef="m2"/>'
                 '</intermediateCatchEvent>\n'
                 '<sequenceFlow id="f1" sourceRef="s" targetRef="send"/>\n'
                 '<sequenceFlow id="f2" sourceRef="send" targetRef="wait"/>\n', top=MESSAGES)
    found = {d.code: d for d in validate_file(path).diagnostics
             if d.code.startswith("trigger-not")}
    assert found["trigger-not-caught"].location.line == 6
    assert "throws message 'report'" in found["trigger-not-caught"].message
    assert "did you mean 'reprot'?" in found["trigger-not-caught"].message
    assert found["trigger-not-thrown"].location.line == 7
    assert "did you mean 'report'?" in found["trigger-not-thrown"].message
    assert all(d.severity is Severity.WARNING for d in found.values())


def test_a_message_thrown_and_caught_is_quiet(tmp_path):
    """The same diagram with one spelling: nothing to say."""
    path = _bpmn(tmp_path, '<startEvent id="s"/>\n'
                 '<intermediateThrowEvent id="send"><messageEventDefinition messageRef="m1"/>'
                 '</intermediateThrowEvent>\n'
                 '<intermediateCatchEvent id="wait"><messageEventDefinition messageRef="m1"/>'
                 '</intermediateCatchEvent>\n'
                 '<sequenceFlow id="f1" sourceRef="s" targetRef="send"/>\n'
                 '<sequenceFlow id="f2" sourceRef="send" targetRef="wait"/>\n', top=MESSAGES)
    assert not [d for d in validate_file(path).diagnostics if d.code.startswith("trigger-not")]


def test_sequence_flows_without_an_id_load_and_route(tmp_path):
    """BPMN 2.0 Semantic.xsd declares tBaseElement's id optional (use="optional"), so a
    sequence flow nothing refers to may have none. Such flows load, and an exclusive
    gateway's two id-less flows stay two (each is tested: BPMN §13.4.2, "the first condition
    that evaluates to true" decides)."""
    path = _bpmn(tmp_path, '<dataObject id="x"/>\n<startEvent id="s"/>\n'
                 '<scriptTask id="set" scriptFormat="python"><script>x = 2</script></scriptTask>\n'
                 '<exclusiveGateway id="g"/>\n<task id="low"/>\n<task id="high"/>\n'
                 '<sequenceFlow sourceRef="s" targetRef="set"/>\n'
                 '<sequenceFlow sourceRef="set" targetRef="g"/>\n'
                 '<sequenceFlow sourceRef="g" targetRef="low">'
                 '<conditionExpression>x &lt; 1</conditionExpression></sequenceFlow>\n'
                 '<sequenceFlow sourceRef="g" targetRef="high">'
                 '<conditionExpression>x &gt;= 1</conditionExpression></sequenceFlow>\n')
    report = validate_file(path)
    assert report.ok, report.lines()
    outcome = opspec.run(path, days=1)
    done = [e.activity for e in outcome.trace if e.kind == "activity.completed"]
    assert "high" in done and "low" not in done


def _validate_and_run(path: Path) -> tuple[FileReport, bool]:
    """What ``opspec validate`` says (with the engine's checks, as the command runs them) and
    whether ``opspec.run`` runs the spec."""
    from opspec.commands.validate import engine_checks

    report = validate_file(path, extra=engine_checks)
    try:
        opspec.run(path, days=1)
    except OpspecError:
        return report, False
    return report, True


TIMERS = ["PT5M", "R3/PT10M", "2026-01-01T08:00:00", "every day", "0 0/5 * * * ?", "",
          "R3/2026-13-45T00:00:00/PT1S", "delay", "delay * 2"]


@pytest.mark.parametrize("text", TIMERS)
@pytest.mark.parametrize("kind", ["timeDuration", "timeCycle", "timeDate"])
def test_validate_and_run_agree_about_every_timer(tmp_path, kind, text):
    """BPMN 2.0 Table 10.101: timeDate, timeCycle and timeDuration "MUST conform to the
    ISO-8601 format" (for date and time, recurring time interval, time interval
    representations). Whatever the text, validate accepts the timer exactly when run runs
    it: a timer validate passes is never refused by run, and one it refuses run refuses."""
    field = ('<extensionElements><opspec:DataField xmlns:opspec="urn:opspec:sisarl:1" '
             'Id="delay" Type="FLOAT" InitialValue="3"/></extensionElements>\n')
    path = _bpmn(tmp_path, f'{field}<startEvent id="s"/>\n'
                 f'<intermediateCatchEvent id="w"><timerEventDefinition><{kind}>{text}'
                 f'</{kind}></timerEventDefinition></intermediateCatchEvent>\n'
                 '<sequenceFlow id="f1" sourceRef="s" targetRef="w"/>\n')
    report, ran = _validate_and_run(path)
    assert report.ok == ran, report.lines()
    if not report.ok:
        assert any(d.location.line == 5 for d in report.diagnostics
                   if d.severity is Severity.ERROR), report.lines()


@pytest.mark.parametrize("text", TIMERS)
@pytest.mark.parametrize("kind", ["TimeCycle", "TimeDate"])
def test_validate_and_run_agree_about_every_xpdl_timer(tmp_path, kind, text):
    """XPDL 2.1 TriggerTimer (TimeDate, TimeCycle): as for BPMN, validate accepts a timer
    exactly when run runs it, and says where when it does not."""
    path = tmp_path / "t.xpdl"
    path.write_text(
        '<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="pk">\n<WorkflowProcesses>\n'
        '<WorkflowProcess Id="w"><DataFields><DataField Id="delay"><DataType>'
        '<BasicType Type="FLOAT"/></DataType><InitialValue>3</InitialValue></DataField>'
        '</DataFields><Activities>\n'
        f'<Activity Id="t"><Event><IntermediateEvent Trigger="Timer"><TriggerTimer><{kind}>'
        f'{text}</{kind}></TriggerTimer></IntermediateEvent></Event></Activity>\n'
        '</Activities></WorkflowProcess>\n</WorkflowProcesses>\n</Package>\n',
        encoding="utf-8")
    report, ran = _validate_and_run(path)
    assert report.ok == ran, report.lines()


@pytest.mark.parametrize("timer", ["<timeDate/>", "<timeDuration>  </timeDuration>", ""])
def test_a_timer_without_a_time_is_said_to_fire_at_once(tmp_path, timer):
    """A timer with no time (bpmn.io draws them so) runs, and fires at once: validate says so
    at its line instead of "never fires", and run does exactly that."""
    path = _bpmn(tmp_path, '<startEvent id="s"/>\n'
                 f'<intermediateCatchEvent id="w"><timerEventDefinition>{timer}'
                 '</timerEventDefinition></intermediateCatchEvent>\n<task id="a"/>\n'
                 '<sequenceFlow id="f1" sourceRef="s" targetRef="w"/>\n'
                 '<sequenceFlow id="f2" sourceRef="w" targetRef="a"/>\n')
    report, ran = _validate_and_run(path)
    [said] = [d for d in report.diagnostics if d.code == "bad-timer"]
    assert said.severity is Severity.WARNING and "fires" in said.message and "at once" in \
        said.message and said.location.line == 4
    assert ran
    done = {e.activity: e.time for e in opspec.run(path, days=1).trace
            if e.kind == "activity.completed"}
    assert done["a"] == 0
