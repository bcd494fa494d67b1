"""validate reports, at the element's file:line, every construct the registry says opspec runs
differently (warning ``runs-differently``) or refuses (error ``not-run``); values that change
behaviour are read, not defaulted in silence; the warnings reach ``opspec run``."""

from __future__ import annotations

import pytest

from opspec.cli import main
from opspec.errors import Severity
from opspec.xpdl.constructs import BPMN, CONSTRUCTS, Construct, Kind
from opspec.xpdl.loader import parse_bytes

XPDL21 = "http://www.wfmc.org/2008/XPDL2.1"

# the value each simple condition needs to hold
VALUES = {None: "x", "true": "true", "false": "false", "not-one": "2", "not-all": "One",
          "parallel": "Parallel", "present": "x"}


def _document(construct: Construct, element: str) -> bytes:
    """A file whose line 3 holds ``element`` (with the construct's attribute set so that its
    condition holds)."""
    attribute = (f' {construct.attribute}="{VALUES[construct.when]}"'
                 if construct.attribute else "")
    if construct.namespace == BPMN:
        return (f'<definitions xmlns="{BPMN}" id="d" targetNamespace="t">\n'
                f'<process id="p">\n<{element} id="e"{attribute}/>\n</process>\n'
                '</definitions>\n').encode()
    return (f'<Package xmlns="{XPDL21}" Id="pk">\n<WorkflowProcesses>\n'
            f'<{element} Id="e"{attribute}/>\n</WorkflowProcesses>\n</Package>\n').encode()


SIMPLE = [(construct, element) for construct in CONSTRUCTS if construct.kind is not Kind.RUNS
          and construct.when in VALUES for element in construct.elements]


@pytest.mark.parametrize(("construct", "element"), SIMPLE,
                         ids=[f"{c.key}:{e}" for c, e in SIMPLE])
def test_each_construct_run_differently_is_reported_at_its_line(construct, element):
    """Every WARNS / REFUSES entry whose condition is the element's presence or its value: a
    file using it gets a located diagnostic at least as severe as the registry says."""
    result = parse_bytes(_document(construct, element), path="f.xml")
    wanted = {Severity.ERROR} if construct.kind is Kind.REFUSES else {Severity.ERROR,
                                                                       Severity.WARNING}
    codes = {construct.code, *construct.reported_by}
    with_element = construct.attribute is not None and construct.when is None
    found = [d for d in result.diagnostics if d.location.line == 3 and d.severity in wanted
             and (d.code in codes or with_element)]
    assert found, [str(d) for d in result.diagnostics]
    own = [d for d in found if d.code == construct.code]
    if own and not (construct.attribute and construct.when is None):
        # (an attribute ignored with its element is said once, by the element's diagnostic)
        assert any(construct.text in d.message for d in own)


def _bpmn(body: str, *, top: str = "") -> bytes:
    return (f'<definitions xmlns="{BPMN}" id="d" targetNamespace="t">\n{top}'
            f'<process id="p" isExecutable="true">\n{body}</process>\n</definitions>\n').encode()


def _gate(data: bytes) -> list[tuple[int | None, str, str]]:
    result = parse_bytes(data, path="f.bpmn")
    return [(d.location.line, d.code, d.message) for d in result.diagnostics
            if d.code in ("runs-differently", "not-run")]


def _line(data: bytes, text: str) -> int:
    return data.decode()[:data.decode().index(text)].count("\n") + 1


def test_quantities_run_and_are_not_reported():
    """BPMN 2.0 §13.3.5: "An inner Activity is now enabled if it has either no incoming
    Sequence Flows or there are sufficiently many tokens on its incoming Sequence Flows (as
    specified through startQuantity)." opspec runs startQuantity and completionQuantity as
    written (tests/standard_constructs runs it; the gate is quiet)."""
    assert _gate(_bpmn('<task id="a" startQuantity="1" completionQuantity="1"/>\n')) == []
    assert _gate(_bpmn('<task id="a" startQuantity="2" completionQuantity="3"/>\n')) == []


def test_terminate_end_event_in_a_sub_process_is_not_reported():
    """BPMN 2.0 §13.5.6: "For a “terminate” End Event, the Sub-Process is abnormally
    terminated. [...] no other ongoing Sub-Process instances or higher-level Sub-Process or
    Process instances are affected." opspec ends the sub-process only (tests/standard_constructs runs it; the gate is quiet)."""
    data = _bpmn('<startEvent id="s"/>\n<subProcess id="sub">\n'
                 '<endEvent id="inner"><terminateEventDefinition id="t1"/></endEvent>\n'
                 '</subProcess>\n'
                 '<endEvent id="outer"><terminateEventDefinition id="t2"/></endEvent>\n')
    assert _gate(data) == []


def test_inclusive_join_and_split_are_not_reported():
    """BPMN 2.0 Table 13.3 (Inclusive Gateway): "Upon execution, a token is consumed from
    each incoming Sequence Flow that has a token." opspec's OR join does so (tests/standard_constructs runs it; the gate is quiet)."""
    join = _bpmn('<task id="a"/>\n<task id="b"/>\n<inclusiveGateway id="g"/>\n'
                 '<sequenceFlow id="f1" sourceRef="a" targetRef="g"/>\n'
                 '<sequenceFlow id="f2" sourceRef="b" targetRef="g"/>\n')
    assert _gate(join) == []


def test_several_none_start_events_are_reported():
    """BPMN 2.0 §10.4.2 (Start Event): "There MAY be multiple Start Events for a given
    Process level. Each Start Event is an independent Event. That is, a Process instance
    SHALL be generated when the Start Event is triggered." A triggered start event and a
    none one run so (tests/standard_constructs/test_several_start_events.py): quiet. Several
    none start events opspec starts together, in one instance, which BPMN does not say
    (it says a called process triggers only one of them): each is said; one is quiet."""
    mixed = _bpmn('<startEvent id="s1"><timerEventDefinition><timeCycle>R/PT1H</timeCycle>'
                  '</timerEventDefinition></startEvent>\n<startEvent id="s2"/>\n')
    assert _gate(mixed) == []
    nones = _bpmn('<startEvent id="s1"/>\n<startEvent id="s2"/>\n'
                  '<startEvent id="s3"><messageEventDefinition/></startEvent>\n')
    found = [(line, code) for line, code, _m in _gate(nones)]
    assert found == [(3, "runs-differently"), (4, "runs-differently")]
    assert "in one instance" in _gate(nones)[0][2]
    assert _gate(_bpmn('<startEvent id="s1"/>\n')) == []


def test_a_cycle_on_a_boundary_is_not_reported():
    """BPMN 2.0 Table 10.101: a timeCycle is a recurring time interval; a non-interrupting
    boundary timer recurs while its activity runs, an interrupting one ends it at its first
    firing (§13.5.3). opspec runs both so (tests/standard_constructs runs it; the gate is quiet)."""
    body = ('<task id="a"/>\n<boundaryEvent id="b" attachedToRef="a" cancelActivity="{c}">'
            '<timerEventDefinition><timeCycle>R3/PT10M</timeCycle></timerEventDefinition>'
            '</boundaryEvent>\n')
    assert _gate(_bpmn(body.format(c="false"))) == []
    assert _gate(_bpmn(body.format(c="true"))) == []


def test_multi_instance_completion_condition_is_not_reported():
    """BPMN 2.0 Table 10.27: "completionCondition: This attribute defines a Boolean
    Expression that when evaluated to true, cancels the remaining Activity instances and
    produces a token." opspec cancels them (tests/standard_constructs runs it; the gate is quiet)."""
    data = _bpmn('<dataObject id="n"/>\n<task id="a"><multiInstanceLoopCharacteristics>'
                 '<loopCardinality>3</loopCardinality>\n'
                 '<completionCondition>n == 1</completionCondition>'
                 '</multiInstanceLoopCharacteristics></task>\n')
    assert _gate(data) == []


def test_event_sub_process_is_refused_unless_opspec_runs_it():
    """BPMN 2.0 §13.5.4: "Event Sub-Processes allow to handle an Event within the context of
    a given Sub-Processes or Process." opspec runs one with a timer or message start event
    (tests/standard_constructs/test_event_sub_process.py): quiet. One with a signal start
    event it does not run, and ignoring it while the rest runs would run something else:
    the file is refused at its line."""
    body = ('<startEvent id="s"/>\n<subProcess id="e" triggeredByEvent="true">\n'
            '<startEvent id="es" isInterrupting="false"><{kind}EventDefinition/>'
            '</startEvent>\n</subProcess>\n')
    runs = parse_bytes(_bpmn(body.format(kind="message")), path="f.bpmn")
    assert [d for d in runs.diagnostics if d.code in ("not-run", "runs-differently")] == []
    result = parse_bytes(_bpmn(body.format(kind="signal")), path="f.bpmn")
    errors = [d for d in result.diagnostics if d.severity is Severity.ERROR]
    assert any(d.location.line == 4 and d.code == "not-run" for d in errors)
    assert not result.ok


def test_timer_on_a_multi_instance_activity_is_not_reported():
    """BPMN 2.0 §13.5.3: "the Activity the Event is attached to is then cancelled (in case
    of a multi-instance, all its instances are cancelled)": the boundary event belongs to the
    activity as a whole; opspec arms it once (tests/standard_constructs runs it; the gate is quiet)."""
    data = _bpmn('<task id="a"><multiInstanceLoopCharacteristics><loopCardinality>2'
                 '</loopCardinality></multiInstanceLoopCharacteristics></task>\n'
                 '<boundaryEvent id="b" attachedToRef="a"><timerEventDefinition>'
                 '<timeDuration>PT1M</timeDuration></timerEventDefinition></boundaryEvent>\n')
    assert _gate(data) == []


XPDL_ROLE = f'''<Package xmlns="{XPDL21}" Id="pk">
<Participants><Participant Id="nurse"><ParticipantType Type="{{kind}}"/></Participant>
</Participants>
<WorkflowProcesses><WorkflowProcess Id="w"><Activities>
<Activity Id="a"{{mode}}><Implementation><No/></Implementation>
<Performers><Performer>nurse</Performer></Performers></Activity>
</Activities></WorkflowProcess></WorkflowProcesses>
</Package>
'''



def test_role_activity_without_implementation_is_quiet():
    """XPDL 2.1 §7.6.5.1: an activity with no implementation is "implemented by manual
    procedures". opspec runs a ROLE or HUMAN participant's such activity as manual work
    (tests/standard_constructs/test_manual_without_implementation.py), as the standard says,
    so validate has nothing to say about it, whatever its StartMode."""
    def found(kind: str, mode: str = "") -> list[int | None]:
        data = XPDL_ROLE.format(kind=kind, mode=mode).encode()
        return [d.location.line for d in parse_bytes(data, path="f.xpdl").diagnostics
                if d.code == "runs-differently"]

    assert found("ROLE") == []
    assert found("HUMAN") == []
    assert found("ROLE", ' StartMode="Manual"') == []


def test_warnings_reach_run(tmp_path, capsys):
    """Every front door uses validate's gate: ``opspec run`` prints the warning, with its
    file:line, before it runs."""
    spec = tmp_path / "q.bpmn"
    spec.write_bytes(_bpmn('<startEvent id="s"/>\n<task id="a" isForCompensation="true"/>\n'
                           '<sequenceFlow id="f" sourceRef="s" targetRef="a"/>\n'))
    status = main(["run", str(spec), "--timeline", "none"])
    captured = capsys.readouterr()
    assert status == 0
    assert f"{spec}:4: warning: bpmn:task 'a' isForCompensation='true' does not run" in \
        captured.err


def test_strict_refuses_a_file_that_runs_differently(tmp_path, capsys):
    """``opspec validate --strict`` turns what runs differently into errors (exit status 1)."""
    spec = tmp_path / "q.bpmn"
    spec.write_bytes(_bpmn('<startEvent id="s"/>\n<task id="a" isForCompensation="true"/>\n'
                           '<sequenceFlow id="f" sourceRef="s" targetRef="a"/>\n'))
    assert main(["validate", str(spec)]) == 0
    assert main(["validate", "--strict", str(spec)]) == 1
    assert "error: bpmn:task 'a' isForCompensation='true'" in capsys.readouterr().out


def test_a_node_fed_only_by_an_ignored_boundary_event_is_not_reported():
    """BPMN 2.0 §10.4.2: "All Flow Objects that do not have an incoming Sequence Flow [...]
    SHALL be instantiated when the Process is instantiated." A task whose only incoming flow
    leaves a compensation boundary event has one, so it waits for a token; opspec keeps the
    flow (the event never fires) (tests/standard_constructs runs it; the gate is quiet)."""
    data = _bpmn('<startEvent id="s"/>\n<task id="a"/>\n'
                 '<boundaryEvent id="b" attachedToRef="a"><compensateEventDefinition/>'
                 '</boundaryEvent>\n<task id="undo"/>\n'
                 '<sequenceFlow id="f0" sourceRef="s" targetRef="a"/>\n'
                 '<sequenceFlow id="f1" sourceRef="b" targetRef="undo"/>\n')
    found = [(line, code) for line, code, _m in _gate(data)]
    assert (_line(data, '<task id="undo"'), "runs-differently") not in found


def test_a_non_executable_process_is_run_and_said_to_be():
    """BPMN 2.0 Table 10.1 (isExecutable): "A non-executable Process is a private Process that
    has been modeled for the purpose of documenting Process behavior at a modeler-defined
    level of detail." The standard runs no such process; opspec simulates it as drawn, and
    says so at the process's line. An executable process, or one that does not say, is quiet
    (the attribute is optional)."""
    body = '<startEvent id="s"/>\n<endEvent id="e"/>\n<sequenceFlow id="f" sourceRef="s" targetRef="e"/>\n'
    documented = _bpmn(body).replace(b'isExecutable="true"', b'isExecutable="false"')
    found = _gate(documented)
    assert [(line, code) for line, code, _m in found] == [
        (_line(documented, '<process id="p"'), "runs-differently")]
    assert "isExecutable='false'" in found[0][2] and "opspec runs it" in found[0][2]
    assert _gate(_bpmn(body)) == []
    assert _gate(_bpmn(body).replace(b' isExecutable="true"', b"")) == []


def _xpdl(activities: str, transitions: str = "", sets: str = "") -> bytes:
    return (f'<Package xmlns="{XPDL21}" Id="pk">\n<WorkflowProcesses>\n'
            f'<WorkflowProcess Id="w">{sets}<Activities>\n{activities}</Activities>\n'
            f'<Transitions>{transitions}</Transitions></WorkflowProcess>\n'
            '</WorkflowProcesses>\n</Package>\n').encode()


def _xpdl_gate(data: bytes) -> list[tuple[int | None, str, str]]:
    result = parse_bytes(data, path="f.xpdl")
    return [(d.location.line, d.code, d.message) for d in result.diagnostics
            if d.code in ("runs-differently", "not-run")]


@pytest.mark.parametrize(("unit", "value", "said"), [
    ("h", "2", True), ("D", " 30 ", True), ("m", "1.5", True),
    ("s", "2", False), (None, "2", False),
    ("h", "PT2H", False), ("h", "2 h", False), ("h", "timeout * 60", False)])
def test_a_bare_number_in_another_duration_unit_is_said(unit, value, said):
    """XPDL's Process Header, DurationUnit: "Describes the default unit to be applied to an
    integer duration value that has no unit tag." opspec reads a bare number as seconds
    (docs/sisarl-xpdl.md), so a DeadlineDuration or TimeCycle of ``2`` under
    ``DurationUnit="h"`` is said at its line; one with its unit, an expression, or a header
    in seconds (or none) is quiet."""
    header = f'<ProcessHeader DurationUnit="{unit}"/>' if unit else "<ProcessHeader/>"
    deadline = (f'<Activity Id="a"><Deadline Execution="SYNCHR"><DeadlineDuration>{value}'
                '</DeadlineDuration><ExceptionName>late</ExceptionName></Deadline></Activity>\n')
    timer = (f'<Activity Id="t"><Event><IntermediateEvent Trigger="Timer"><TriggerTimer>'
             f'<TimeCycle>{value}</TimeCycle></TriggerTimer></IntermediateEvent></Event>'
             '</Activity>\n')
    data = _xpdl(deadline + timer, sets=header)
    found = {(line, code) for line, code, message in _xpdl_gate(data)
             if "DurationUnit" in message}
    expected = {(_line(data, "<DeadlineDuration>"), "runs-differently"),
                (_line(data, "<TimeCycle>"), "runs-differently")}
    assert found == (expected if said else set())


def test_xpdl_several_start_events_are_not_reported():
    """BPMN 2.0 §10.4.2, which XPDL 2.1's events follow: "Each Start Event is an independent
    Event." opspec starts an instance per triggered start event (tests/standard_constructs runs it; the gate is quiet)."""
    one = '<Activity Id="s1"><Event><StartEvent Trigger="None"/></Event></Activity>\n'
    two = one + '<Activity Id="s2"><Event><StartEvent Trigger="None"/></Event></Activity>\n'
    assert _xpdl_gate(_xpdl(one)) == [] and _xpdl_gate(_xpdl(two)) == []


def test_xpdl_terminate_inside_an_activity_set_is_not_reported():
    """BPMN 2.0 §13.5.6: "For a “terminate” End Event, the Sub-Process is abnormally
    terminated." An XPDL activity set is its block activity's embedded sub-process; opspec
    ends that block only (tests/standard_constructs runs it; the gate is quiet)."""
    sets = ('<ActivitySets><ActivitySet Id="set"><Activities>\n'
            '<Activity Id="inner"><Event><EndEvent Result="Terminate"/></Event></Activity>\n'
            '</Activities></ActivitySet></ActivitySets>')
    data = _xpdl('<Activity Id="outer"><Event><EndEvent Result="Terminate"/></Event>'
                 '</Activity>\n', sets=sets)
    assert _xpdl_gate(data) == []


def test_xpdl_inclusive_join_and_attached_cycle_and_mi_deadline_are_not_reported():
    """BPMN 2.0 Table 13.3 (the OR join), Table 10.101 (a recurring timeCycle) and §13.5.3 (a
    boundary event belongs to a multi-instance activity as a whole): the XPDL counterparts
    run so (tests/standard_constructs runs it; the gate is quiet)."""
    data = _xpdl(
        '<Activity Id="j"><Route GatewayType="Inclusive"/><TransitionRestrictions>'
        '<TransitionRestriction><Join Type="Inclusive"/></TransitionRestriction>'
        '</TransitionRestrictions></Activity>\n'
        '<Activity Id="t"><Event><IntermediateEvent Trigger="Timer" Target="m" '
        'Interrupting="false"><TriggerTimer>'
        '<TimeCycle>R/PT1M</TimeCycle></TriggerTimer></IntermediateEvent></Event></Activity>\n'
        '<Activity Id="m"><Implementation><No/></Implementation><Loop LoopType="MultiInstance">'
        '<LoopMultiInstance MI_Condition="2"/></Loop><Deadline Execution="SYNCHR">'
        '<DeadlineDuration>PT1M</DeadlineDuration><ExceptionName>late</ExceptionName>'
        '</Deadline></Activity>\n')
    assert _xpdl_gate(data) == []


def test_warnings_reach_the_walkthrough(tmp_path):
    """The walkthrough loads through the same gate and shows the warnings as notes on its
    screen (load_any_spec hands them over)."""
    from opspec.commands._spec import load_any_spec

    spec = tmp_path / "q.bpmn"
    spec.write_bytes(_bpmn('<startEvent id="s"/>\n<task id="a" isForCompensation="true"/>\n'
                           '<sequenceFlow id="f" sourceRef="s" targetRef="a"/>\n'))
    shown: list[str] = []
    load_any_spec(spec, warnings=shown)
    assert any(f"{spec}:4: warning: bpmn:task 'a' isForCompensation='true'" in s for s in shown)


def test_check_says_where_it_runs_differently(tmp_path, capsys):
    """`opspec check` judges soundness of what opspec runs; a construct that runs differently
    from its standard is said beside the verdict, not passed over."""
    spec = tmp_path / "q.bpmn"
    spec.write_bytes(_bpmn('<startEvent id="s"/>\n<task id="a" isForCompensation="true"/>\n'
                           '<sequenceFlow id="f" sourceRef="s" targetRef="a"/>\n'))
    main(["check", str(spec)])
    captured = capsys.readouterr()
    assert f"opspec check: {spec}:4: warning: bpmn:task 'a' isForCompensation='true'" in captured.err


def test_a_group_is_reported_once_at_its_outermost_element():
    """InputSets/InputSet/Input all fall under one entry: the outermost element says it, so a
    vendor export's input sets give one warning each, not one per nested element."""
    data = _xpdl('<Activity Id="a"><Implementation><No/></Implementation>\n<InputSets>'
                 '<InputSet>\n<Input ArtifactId="x"/>\n</InputSet></InputSets></Activity>\n')
    assert [line for line, _c, _m in _xpdl_gate(data)] == [5]


def test_a_time_date_that_is_no_date_is_reported():
    """BPMN 2.0 Table 10.101: "The return type of the attribute timeDate MUST conform to the
    ISO-8601 format for date and time representations." An XPDL TimeDate naming a data field
    is read by opspec as a delay in seconds, not as the date the field holds: said at its
    line; a TimeDate that is a date is quiet."""
    timer = ('<Activity Id="t"><Event><IntermediateEvent Trigger="Timer"><TriggerTimer>'
             '<TimeDate>{}</TimeDate></TriggerTimer></IntermediateEvent></Event></Activity>\n')
    assert _xpdl_gate(_xpdl(timer.format("2026-01-01T08:00:00"))) == []
    [(line, code, message)] = _xpdl_gate(_xpdl(timer.format("when")))
    assert (line, code) == (4, "runs-differently") and "not as a date" in message
