"""Building the model: XPDL 1.0 and 2.x spellings give the same model, every construct of
issue 2 item 3 has a home, and problems become located diagnostics."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from opspec.errors import Severity, SpecError
from opspec.model import (
    Activity,
    BlockActivity,
    ConditionKind,
    Event,
    EventPosition,
    Execution,
    GatewayType,
    LoopKind,
    Mode,
    NoImplementation,
    Package,
    Route,
    SubFlow,
    Task,
    TaskKind,
    TriggerKind,
)
from opspec.xpdl import LoadResult, load_spec, parse_bytes

DATA = Path(__file__).parent / "data"
NS = {"1.0": "http://www.wfmc.org/2002/XPDL1.0", "2.1": "http://www.wfmc.org/2008/XPDL2.1"}


def load(body: str, version: str = "2.1", extra: str = "") -> LoadResult:
    text = (f'<?xml version="1.0"?>\n<Package xmlns="{NS[version]}" '
            f'xmlns:v="urn:vendor" xmlns:opspec="urn:opspec:sisarl:1" Id="pkg"{extra}>'
            f"{body}</Package>")
    return parse_bytes(text.encode(), path="t.xpdl")


def package(body: str, version: str = "2.1") -> Package:
    result = load(body, version)
    assert result.package is not None, [str(d) for d in result.diagnostics]
    return result.package


def process_xml(activities: str, transitions: str = "", extra: str = "") -> str:
    return (f'<WorkflowProcesses><WorkflowProcess Id="p">{extra}<Activities>{activities}'
            f"</Activities><Transitions>{transitions}</Transitions></WorkflowProcess>"
            "</WorkflowProcesses>")


V10 = process_xml(
    """
    <Activity Id="tool"><Implementation><Tool Id="app" Type="APPLICATION">
      <ActualParameters><ActualParameter>x</ActualParameter></ActualParameters></Tool>
      </Implementation><Performer>clerk</Performer>
      <StartMode><Manual/></StartMode><FinishMode><Automatic/></FinishMode>
      <Deadline Execution="SYNCHR"><DeadlineCondition>PT5M</DeadlineCondition>
        <ExceptionName>late</ExceptionName></Deadline>
      <TransitionRestrictions><TransitionRestriction><Join Type="AND"/>
        <Split Type="XOR"><TransitionRefs><TransitionRef Id="t2"/><TransitionRef Id="t1"/>
        </TransitionRefs></Split></TransitionRestriction></TransitionRestrictions></Activity>
    <Activity Id="block"><BlockActivity BlockId="set1"/></Activity>
    <Activity Id="r"><Route/></Activity>
    """,
    """<Transition Id="t1" From="tool" To="block"><Condition Type="CONDITION">x == 1</Condition></Transition>
       <Transition Id="t2" From="tool" To="r"><Condition Type="OTHERWISE"/></Transition>""",
)
V21 = process_xml(
    """
    <Activity Id="tool" StartMode="Manual" FinishMode="Automatic"><Implementation><Task>
      <TaskApplication Id="app"><ActualParameters><ActualParameter>x</ActualParameter>
      </ActualParameters></TaskApplication></Task></Implementation>
      <Performers><Performer>clerk</Performer></Performers>
      <Deadline Execution="SYNCHR"><DeadlineDuration>PT5M</DeadlineDuration>
        <ExceptionName>late</ExceptionName></Deadline>
      <TransitionRestrictions><TransitionRestriction><Join Type="Parallel"/>
        <Split Type="Exclusive"><TransitionRefs><TransitionRef Id="t2"/><TransitionRef Id="t1"/>
        </TransitionRefs></Split></TransitionRestriction></TransitionRestrictions></Activity>
    <Activity Id="block"><BlockActivity ActivitySetId="set1"/></Activity>
    <Activity Id="r"><Route GatewayType="Exclusive"/></Activity>
    """,
    """<Transition Id="t1" From="tool" To="block"><Condition Type="CONDITION">
         <Expression>x == 1</Expression></Condition></Transition>
       <Transition Id="t2" From="tool" To="r"><Condition Type="OTHERWISE"/></Transition>""",
)


def _strip(value: object) -> object:
    """The value with every ``location`` field set to None (for comparing across files)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        changes = {f.name: _strip(getattr(value, f.name)) for f in dataclasses.fields(value)}
        if "location" in changes:
            changes["location"] = None
        return dataclasses.replace(value, **changes)
    if isinstance(value, tuple):
        return tuple(_strip(v) for v in value)
    return value


def test_xpdl_1_0_and_2_1_spellings_give_the_same_model() -> None:
    old = package(V10, "1.0").processes[0]
    new = package(V21, "2.1").processes[0]
    assert _strip(old.activities) == _strip(new.activities)
    assert _strip(old.transitions) == _strip(new.transitions)
    tool = new.activities[0]
    assert tool.body == Task(kind=TaskKind.APPLICATION, applications=tool.body.applications)  # type: ignore[union-attr]
    assert tool.performers == ("clerk",)
    assert tool.start_mode is Mode.MANUAL and tool.is_manual
    assert tool.join is not None and tool.join.type is GatewayType.AND
    assert tool.split is not None and tool.split.type is GatewayType.XOR
    assert tool.split.transition_refs == ("t2", "t1")
    assert tool.deadlines[0].duration_text == "PT5M" and tool.deadlines[0].duration is not None
    assert tool.deadlines[0].exception_name == "late"
    assert tool.deadlines[0].execution is Execution.SYNCHR
    assert new.activities[1].body == BlockActivity(activity_set="set1")
    assert new.transitions[0].condition.kind is ConditionKind.CONDITION
    assert new.transitions[0].condition.expression is not None
    assert new.transitions[1].condition.kind is ConditionKind.OTHERWISE


@pytest.mark.parametrize(
    ("route", "restriction", "gateway"),
    [
        ("<Route/>", "", GatewayType.XOR),
        ("<Route/>", '<Split Type="Parallel"/>', GatewayType.AND),
        ("<Route/>", '<Join Type="AND"/>', GatewayType.AND),
        ('<Route GatewayType="Inclusive"/>', "", GatewayType.OR),
        ('<Route GatewayType="Complex"/>', "", GatewayType.COMPLEX),
        ('<Route GatewayType="EventBasedXOR"/>', "", GatewayType.EVENT),
        ('<Route GatewayType="Exclusive" ExclusiveType="Event"/>', "", GatewayType.EVENT),
        ('<Route GatewayType="AND"/>', "", GatewayType.AND),
    ],
    ids=["bizagi-bare", "bare-parallel-split", "bare-and-join", "inclusive", "complex",
         "event-based", "exclusive-event", "2.0-and"],
)
def test_route_gateway_type_in_every_spelling(route: str, restriction: str, gateway: GatewayType) -> None:
    restrictions = (f"<TransitionRestrictions><TransitionRestriction>{restriction}"
                    "</TransitionRestriction></TransitionRestrictions>") if restriction else ""
    activity = package(process_xml(f'<Activity Id="g">{route}{restrictions}</Activity>')).processes[0].activities[0]
    assert activity.body == Route(gateway=gateway)


def _event(xml: str) -> Activity:
    return package(process_xml(f'<Activity Id="e"><Event>{xml}</Event></Activity>')).processes[0].activities[0]


def test_message_start_event_carries_the_message_name() -> None:
    body = _event('<StartEvent Trigger="Message"><TriggerResultMessage><Message Id="m" Name="alarm"/>'
                  "</TriggerResultMessage></StartEvent>").body
    assert isinstance(body, Event) and body.position is EventPosition.START
    assert body.trigger.kind is TriggerKind.MESSAGE and body.trigger.name == "alarm"


def test_boundary_timer_event_is_attached_to_its_activity() -> None:
    body = _event('<IntermediateEvent Trigger="Timer" Target="task"><TriggerTimer>'
                  "<TimeCycle>PT10S</TimeCycle></TriggerTimer></IntermediateEvent>").body
    assert isinstance(body, Event)
    assert body.trigger.kind is TriggerKind.TIMER and body.trigger.attached_to == "task"
    assert body.trigger.time_cycle == "PT10S" and body.trigger.duration is not None


def test_xpdl_2_0_rule_trigger_is_a_conditional_trigger() -> None:
    body = _event('<StartEvent Trigger="Rule"><TriggerRule RuleName="low"/></StartEvent>').body
    assert isinstance(body, Event) and body.trigger.kind is TriggerKind.RULE
    assert body.trigger.name == "low"


@pytest.mark.parametrize(
    ("xml", "kind", "name"),
    [
        ('<EndEvent Result="Terminate"/>', TriggerKind.TERMINATE, None),
        ('<EndEvent Result="Error"><ResultError ErrorCode="E1"/></EndEvent>', TriggerKind.ERROR, "E1"),
        ('<EndEvent Result="Signal"><TriggerResultSignal Name="s" CatchThrow="THROW"/></EndEvent>',
         TriggerKind.SIGNAL, "s"),
        ('<IntermediateEvent Trigger="Link"><TriggerResultLink Name="l"/></IntermediateEvent>',
         TriggerKind.LINK, "l"),
        ('<IntermediateEvent Trigger="Cancel" Target="x"/>', TriggerKind.CANCEL, None),
        (('<StartEvent Trigger="Conditional"><TriggerConditional><Expression>level &lt; 3</Expression>'
         "</TriggerConditional></StartEvent>"), TriggerKind.RULE, None),
    ],
    ids=["terminate", "error", "signal", "link", "cancel", "conditional"],
)
def test_event_triggers_and_results(xml: str, kind: TriggerKind, name: str | None) -> None:
    body = _event(xml).body
    assert isinstance(body, Event) and body.trigger.kind is kind and body.trigger.name == name


def test_unknown_trigger_is_a_warning_not_a_crash() -> None:
    result = load(process_xml('<Activity Id="e"><Event><StartEvent Trigger="Telepathy"/></Event></Activity>'))
    assert [d.code for d in result.diagnostics] == ["unknown-trigger"]
    assert result.diagnostics[0].location.line == 2


@pytest.mark.parametrize(
    ("task", "kind"),
    [
        ('<TaskScript><Script>x = 1</Script></TaskScript>', TaskKind.SCRIPT),
        ('<TaskSend><Message Id="m" Name="ping"/></TaskSend>', TaskKind.SEND),
        ('<TaskReceive><Message Id="m" Name="ping"/></TaskReceive>', TaskKind.RECEIVE),
        ('<TaskService Implementation="WebService"/>', TaskKind.SERVICE),
        ('<TaskUser Implementation="Unspecified"/>', TaskKind.USER),
        ("<TaskManual/>", TaskKind.MANUAL),
        ("<TaskReference/>", TaskKind.REFERENCE),
        ("<TaskBusinessRule/>", TaskKind.BUSINESS_RULE),
    ],
    ids=lambda v: getattr(v, "value", "xml"),
)
def test_every_task_kind(task: str, kind: TaskKind) -> None:
    activity = package(process_xml(f'<Activity Id="t"><Implementation><Task>{task}</Task>'
                                   "</Implementation></Activity>")).processes[0].activities[0]
    assert isinstance(activity.body, Task) and activity.body.kind is kind
    if kind in (TaskKind.SEND, TaskKind.RECEIVE):
        assert activity.body.message == "ping"
    if kind is TaskKind.SCRIPT:
        assert activity.body.script == "x = 1"


def test_async_subflow_with_package_ref_and_parameters() -> None:
    activity = package(process_xml(
        '<Activity Id="s"><Implementation><SubFlow Id="other" Execution="ASYNCHR" PackageRef="lib">'
        "<ActualParameters><ActualParameter>a + 1</ActualParameter></ActualParameters>"
        "</SubFlow></Implementation></Activity>")).processes[0].activities[0]
    assert isinstance(activity.body, SubFlow)
    assert activity.body.execution is Execution.ASYNCHR and activity.body.package_ref == "lib"
    assert activity.body.actual_parameters[0].text == "a + 1"
    assert activity.body.actual_parameters[0].expression is not None


def test_activity_without_implementation_is_no_implementation() -> None:
    assert package(process_xml('<Activity Id="a"/>')).processes[0].activities[0].body == NoImplementation()


def test_loops_standard_and_multi_instance() -> None:
    acts = package(process_xml(
        '<Activity Id="a"><Loop LoopType="Standard"><LoopStandard LoopCondition="n &lt; 3" '
        'LoopMaximum="5" TestTime="Before"/></Loop></Activity>'
        '<Activity Id="b"><Loop LoopType="MultiInstance"><LoopMultiInstance MI_Condition="3"/></Loop>'
        '</Activity><Activity Id="c"><Loop LoopType="None"/></Activity>')).processes[0].activities
    assert acts[0].loop is not None and acts[0].loop.kind is LoopKind.STANDARD
    assert acts[0].loop.maximum == 5 and acts[0].loop.test_before and acts[0].loop.condition is not None
    assert acts[1].loop is not None and acts[1].loop.kind is LoopKind.MULTI_INSTANCE
    assert acts[2].loop is None


def test_activity_lane_priority_and_assignments() -> None:
    activity = package(process_xml(
        '<Activity Id="a"><Priority>3</Priority><Assignments><Assignment AssignTime="Start">'
        "<Target>n</Target><Expression>n + 1</Expression></Assignment></Assignments>"
        '<NodeGraphicsInfos><NodeGraphicsInfo LaneId="lane1"/></NodeGraphicsInfos></Activity>'
    )).processes[0].activities[0]
    assert activity.priority == 3 and activity.lane == "lane1"
    assert activity.assignments[0].target == "n" and activity.assignments[0].assign_time == "Start"
    assert activity.assignments[0].expression is not None


def test_exception_transitions_name_their_exception() -> None:
    proc = package(process_xml(
        '<Activity Id="a"/><Activity Id="b"/>',
        '<Transition Id="t" From="a" To="b"><Condition Type="EXCEPTION">late</Condition></Transition>'
        '<Transition Id="u" From="a" To="b"><Condition Type="DEFAULTEXCEPTION"/></Transition>'
        '<Transition Id="v" From="a" To="b"/>'), "1.0").processes[0]
    kinds = [t.condition.kind for t in proc.transitions]
    assert kinds == [ConditionKind.EXCEPTION, ConditionKind.DEFAULTEXCEPTION, ConditionKind.NONE]
    assert proc.transitions[0].condition.exception_name == "late"


def test_unparseable_condition_is_an_error_at_its_line() -> None:
    from opspec.xpdl import load_package

    result = load_package(DATA / "bad_condition.xpdl")
    assert result.package is not None and not result.ok
    [diagnostic] = result.errors
    assert diagnostic.code == "bad-condition"
    assert diagnostic.location.line == 11
    assert "x == == 3" in diagnostic.message


def test_load_spec_raises_spec_error_naming_file_and_line() -> None:
    with pytest.raises(SpecError, match=r"bad_condition\.xpdl:11: transition condition"):
        load_spec(DATA / "bad_condition.xpdl")


def test_extended_attributes_are_kept_verbatim() -> None:
    pkg = package('<ExtendedAttributes><ExtendedAttribute Name="v:a" Value="1"/>'
                  '<ExtendedAttribute Name="v:b">free text</ExtendedAttribute>'
                  '<ExtendedAttribute Name="v:c"><v:Thing k="x"><v:Sub/></v:Thing>'
                  '<Activity Id="not-really"/></ExtendedAttribute></ExtendedAttributes>')
    a, b, c = pkg.extended_attributes
    assert (a.name, a.value, a.text) == ("v:a", "1", None)
    assert b.text == "free text"
    assert c.raw_xml is not None
    assert '<v:Thing xmlns:v="urn:vendor" k="x"><v:Sub/></v:Thing>' in c.raw_xml
    # XPDL-named elements inside an ExtendedAttribute keep their original namespace.
    assert 'xmlns="http://www.wfmc.org/2008/XPDL2.1"' in c.raw_xml
    assert c.location is not None and c.location.line == 2


def test_data_fields_have_typed_initial_values() -> None:
    fields = package(
        "<DataFields>"
        '<DataField Id="n"><DataType><BasicType Type="INTEGER"/></DataType><InitialValue>3</InitialValue></DataField>'
        '<DataField Id="f"><DataType><BasicType Type="FLOAT"/></DataType><InitialValue>2.5</InitialValue></DataField>'
        '<DataField Id="b"><DataType><BasicType Type="BOOLEAN"/></DataType><InitialValue>true</InitialValue></DataField>'
        '<DataField Id="s"><DataType><BasicType Type="STRING"/></DataType><InitialValue>"hi"</InitialValue></DataField>'
        '<DataField Id="e"><DataType><EnumerationType><EnumerationValue Name="x"/></EnumerationType></DataType></DataField>'
        "</DataFields>").data_fields
    assert [f.initial for f in fields] == [3, 2.5, True, "hi", None]
    assert fields[0].initial_value == "3"


def test_bad_initial_value_is_a_warning_with_its_line() -> None:
    result = load('<DataFields><DataField Id="n"><DataType><BasicType Type="INTEGER"/></DataType>'
                  "\n<InitialValue>many</InitialValue></DataField></DataFields>")
    assert [(d.code, d.location.line) for d in result.diagnostics] == [("bad-initial-value", 3)]
    assert result.package is not None and result.package.data_fields[0].initial is None


def test_lanes_nest_by_parent_lane_and_nested_lane() -> None:
    pkg = package(
        '<Pools><Pool Id="pool" Process="p"><Lanes>'
        '<Lane Id="a"><Performers><Performer>user</Performer></Performers></Lane>'
        '<Lane Id="b" ParentLane="a"/><Lane Id="c" ParentLane="pool"/>'
        '<Lane Id="d"><NestedLane LaneId="e"/></Lane><Lane Id="e"/>'
        "</Lanes></Pool></Pools>")
    pool = pkg.pools[0]
    assert [lane.id for lane in pool.lanes] == ["a", "c", "d"]
    assert pool.lanes[0].lanes[0].id == "b" and pool.lanes[0].performers == ("user",)
    assert pool.lanes[2].lanes[0].id == "e"
    assert [lane.id for lane in pool.all_lanes()] == ["a", "b", "c", "d", "e"]


def test_activity_ids_are_scoped_per_process_and_activity_set() -> None:
    pkg = package(
        '<WorkflowProcesses><WorkflowProcess Id="p1"><ActivitySets><ActivitySet Id="s">'
        '<Activities><Activity Id="a"/></Activities></ActivitySet></ActivitySets>'
        '<Activities><Activity Id="a"/></Activities></WorkflowProcess>'
        '<WorkflowProcess Id="p2"><Activities><Activity Id="a"/></Activities></WorkflowProcess>'
        "</WorkflowProcesses>")
    assert [len(p.all_activities()) for p in pkg.processes] == [2, 1]
    assert pkg.processes[0].activity_set("s") is not None


def test_package_level_resources_and_headers() -> None:
    pkg = package(
        "<PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>me</Vendor></PackageHeader>"
        '<ConformanceClass GraphConformance="NON_BLOCKED"/><Script Type="text/javascript"/>'
        '<TypeDeclarations><TypeDeclaration Id="T"><RecordType><Member><BasicType Type="STRING"/>'
        "</Member></RecordType></TypeDeclaration></TypeDeclarations>"
        '<Participants><Participant Id="u"><ParticipantType Type="HUMAN"/></Participant></Participants>'
        '<Applications><Application Id="app"><FormalParameters><FormalParameter Id="x" Mode="OUT">'
        '<DataType><DeclaredType Id="T"/></DataType></FormalParameter></FormalParameters></Application>'
        "</Applications>")
    assert pkg.header.vendor == "me" and pkg.conformance_class == "NON_BLOCKED"
    assert pkg.script_language == "text/javascript"
    assert pkg.participants[0].is_human
    assert pkg.applications[0].formal_parameters[0].mode.value == "OUT"
    assert pkg.type_declarations[0].id == "T"


def test_strict_mode_turns_warnings_into_errors() -> None:
    xml = process_xml('<Activity Id="e"><Event><StartEvent Trigger="Telepathy"/></Event></Activity>')
    text = f'<Package xmlns="{NS["2.1"]}" Id="pkg">{xml}</Package>'.encode()
    assert parse_bytes(text, path="s.xpdl").ok
    strict = parse_bytes(text, path="s.xpdl", strict=True)
    assert not strict.ok and strict.diagnostics[0].severity is Severity.ERROR


def test_missing_ids_and_transition_ends_are_reported_not_fatal() -> None:
    result = load(process_xml("<Activity/>", '<Transition Id="t" From="a"/>'))
    assert result.package is not None
    assert sorted(d.code for d in result.errors) == ["missing-id", "missing-transition-end"]
