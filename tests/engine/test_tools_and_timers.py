"""Tools, script tool agents, activity priorities and timers, run from real XPDL text.

Each test loads a small XPDL file as an editor would write it and checks the trace a user
would expect (issue 16: every Tool runs in order; JaWE JavaScript tool agents run; the
activity Priority orders the pooled queue; TimeDate and ISO 8601 repeating intervals)."""

from __future__ import annotations

from typing import Any

import pytest

from opspec.engine.builtin_performers import CallablePerformer, SimulatedDevice
from opspec.engine.config import EngineConfig
from opspec.engine.simulation import Simulation
from opspec.errors import SpecError
from opspec.model import Package
from opspec.xpdl.loader import parse_bytes

XPDL10 = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2002/XPDL1.0" Id="p" Name="p">
  <PackageHeader><XPDLVersion>1.0</XPDLVersion><Vendor>t</Vendor><Created>2024</Created></PackageHeader>
  <Applications>{apps}</Applications>
  <WorkflowProcesses>
    <WorkflowProcess Id="w" Name="w">
      <ProcessHeader/>
      <DataFields>{fields}</DataFields>
      <Activities>{acts}</Activities>
      <Transitions>{trans}</Transitions>
    </WorkflowProcess>
  </WorkflowProcesses>
</Package>
"""

XPDL21 = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="p" Name="p">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2024</Created></PackageHeader>
  <WorkflowProcesses>{processes}</WorkflowProcesses>
</Package>
"""

SCRIPT_APP = """
  <Application Id="{id}">
    <FormalParameters>{formals}</FormalParameters>
    <ExtendedAttributes>
      <ExtendedAttribute Name="ToolAgentClass" Value="org.enhydra.shark.toolagent.JavaScriptToolAgent"/>
      <ExtendedAttribute Name="Script" Value="{script}"/>
    </ExtendedAttributes>
  </Application>"""


def formal(id: str, mode: str, kind: str = "INTEGER") -> str:
    return (f'<FormalParameter Id="{id}" Mode="{mode}"><DataType><BasicType Type="{kind}"/>'
            "</DataType></FormalParameter>")


def field(id: str, initial: str, kind: str = "INTEGER") -> str:
    return (f'<DataField Id="{id}" IsArray="FALSE"><DataType><BasicType Type="{kind}"/></DataType>'
            f"<InitialValue>{initial}</InitialValue></DataField>")


def tool(app: str, *actuals: str) -> str:
    params = "".join(f"<ActualParameter>{a}</ActualParameter>" for a in actuals)
    return f'<Tool Id="{app}" Type="PROCEDURE"><ActualParameters>{params}</ActualParameters></Tool>'


def activity(id: str, body: str = "<Implementation><No/></Implementation>", extra: str = "") -> str:
    return f'<Activity Id="{id}" Name="{id}">{body}{extra}</Activity>'


def tools(id: str, *calls: str, extra: str = "") -> str:
    return activity(id, f"<Implementation>{''.join(calls)}</Implementation>", extra)


def load(text: str) -> Package:
    result = parse_bytes(text.encode(), path="spec.xpdl")
    assert result.package is not None and result.ok, [str(d) for d in result.diagnostics]
    return result.package


def run(package: Package, until: float = 100.0, config: EngineConfig | None = None,
        performers: Any = None) -> Any:
    return Simulation(package, config, performers=performers, keep_trace=True).run(until=until)


def trail(result: Any, kind: str = "activity.completed") -> list[str]:
    return [e.activity for e in result.trace if e.kind == kind and e.activity]


def data_changes(result: Any) -> list[tuple[str, dict[str, Any]]]:
    return [(e.activity, dict(e.data)) for e in result.trace if e.kind == "data.changed"]


COUNTERS = "".join([
    SCRIPT_APP.format(id="ResetCounter", formals=formal("counter", "OUT"), script="counter = 0;"),
    SCRIPT_APP.format(id="IncrementCounter", formals=formal("counter", "INOUT"),
                      script="counter = counter + 1;"),
    SCRIPT_APP.format(id="SetCounter", formals=formal("value", "IN") + formal("counter", "OUT"),
                      script="counter = value;"),
])


# ---------------------------------------------------------------- tools and scripts

def test_every_tool_runs_in_order_with_its_own_parameters() -> None:
    """Three Tools on one activity (the JaWE discriminator's reset step does this): each runs
    with its own actual parameters, in order, and the activity completes after the last."""
    spec = XPDL10.format(
        apps=COUNTERS,
        fields=field("a", "7") + field("b", "7"),
        acts=tools("reset", tool("SetCounter", "5", "a"), tool("ResetCounter", "b"),
                   tool("IncrementCounter", "a")) + activity("after"),
        trans='<Transition Id="t1" From="reset" To="after"/>')
    result = run(load(spec))
    assert data_changes(result) == [("reset", {"a": 5}), ("reset", {"b": 0}),
                                     ("reset", {"a": 6})]
    assert trail(result) == ["reset", "after"]


def test_a_counting_loop_leaves_when_the_script_counter_says_so() -> None:
    """A loop whose exit condition reads a counter incremented by a JavaScript tool agent
    (the construct WfABSP4/5 of the JaWE patterns file count branches with) ends."""
    spec = XPDL10.format(
        apps=COUNTERS,
        fields=field("n", "0"),
        acts=(activity("start", "<Route/>")
              + tools("count", tool("IncrementCounter", "n"),
                      extra='<TransitionRestrictions><TransitionRestriction><Join Type="XOR"/>'
                      '<Split Type="XOR"><TransitionRefs><TransitionRef Id="again"/>'
                      '<TransitionRef Id="out"/></TransitionRefs></Split>'
                      "</TransitionRestriction></TransitionRestrictions>")
              + activity("done")),
        trans=('<Transition Id="t0" From="start" To="count"/>'
               '<Transition Id="again" From="count" To="count">'
               '<Condition Type="CONDITION">n &lt; 3</Condition></Transition>'
               '<Transition Id="out" From="count" To="done"><Condition Type="OTHERWISE"/>'
               "</Transition>"))
    result = run(load(spec))
    assert trail(result) == ["start", "count", "count", "count", "done"]
    assert [d["n"] for _, d in data_changes(result)] == [1, 2, 3]
    assert [e.kind for e in result.trace if e.kind.startswith("process.")] == [
        "process.started", "process.completed"]


def test_a_bound_performer_takes_each_tool_in_turn_and_scripts_run_between() -> None:
    """Tools whose application is bound to a performer are offered to it one at a time
    (each work item names its application and carries its own inputs); an unbound script
    tool runs as a built-in between them."""
    calls: list[tuple[str, dict[str, Any]]] = []

    def double(inputs: Any) -> dict[str, Any]:
        calls.append(("Double", dict(inputs)))
        return {"counter": inputs["counter"] * 2}

    apps = COUNTERS + (
        '<Application Id="Double"><FormalParameters>' + formal("counter", "INOUT")
        + "</FormalParameters></Application>")
    spec = XPDL10.format(
        apps=apps, fields=field("x", "1"),
        acts=tools("work", tool("Double", "x"), tool("IncrementCounter", "x"), tool("Double", "x")),
        trans="")
    performer = CallablePerformer({"Double": double})
    result = run(load(spec), performers={"device": performer})
    assert calls == [("Double", {"counter": 1}), ("Double", {"counter": 3})]
    assert [d["x"] for _, d in data_changes(result)] == [2, 3, 6]
    assert trail(result) == ["work"]


def test_a_script_outside_the_subset_is_a_located_error() -> None:
    spec = XPDL10.format(
        apps=SCRIPT_APP.format(id="Bad", formals=formal("c", "INOUT"),
                               script="if (c &gt; 1) { c = 0; }"),
        fields=field("x", "1"), acts=tools("a", tool("Bad", "x")), trans="")
    result = parse_bytes(spec.encode(), path="spec.xpdl")
    errors = [d for d in result.diagnostics if d.code == "bad-script"]
    assert len(errors) == 1
    assert str(errors[0]).startswith("spec.xpdl:9: error:")
    assert "Bad" in errors[0].message and "not supported" in errors[0].message


def test_a_script_reading_a_name_that_is_no_formal_is_refused_at_compile_time() -> None:
    spec = XPDL10.format(
        apps=SCRIPT_APP.format(id="Leaky", formals=formal("c", "OUT"), script="c = other + 1;"),
        fields=field("x", "1"), acts=tools("a", tool("Leaky", "x")), trans="")
    with pytest.raises(SpecError, match="'other', which is neither a formal parameter"):
        Simulation(load(spec))


def test_the_jawe_patterns_file_counts_its_discriminator_branches() -> None:
    """The JaWE workflow_patterns file in the corpus: its discriminator resets and counts
    its branches with JavaScript tool agents and completes. Its work items (no
    implementation, the ROLE participant "test") are manual work (XPDL 2.1 §7.6.5.1:
    "implemented by manual procedures"): a performer bound to "test" completes each at once."""
    from pathlib import Path

    path = Path(__file__).parents[2].parent / "shared/corpus/xpdl/jawe10__workflow_patterns.xpdl"
    if not path.exists():
        pytest.skip("corpus not available")
    import dataclasses

    result = parse_bytes(path.read_bytes(), path=str(path))
    assert result.package is not None
    package = dataclasses.replace(result.package, processes=tuple(
        p for p in result.package.processes if p.id == "WfABSP4_Discriminator"))
    run_result = run(package, performers={"test": SimulatedDevice()})
    changes = data_changes(run_result)
    assert changes[:2] == [("ResetDiscriminator", {"availableBranchesToAccessE": 1}),
                           ("ResetDiscriminator", {"openedBranchesAfterA": 0})]
    assert ("UpdateTriggeredBranchesForB", {"openedBranchesAfterA": 1}) in changes
    assert trail(run_result)[-2:] == ["E", "End"]
    assert [e.kind for e in run_result.trace if e.kind.startswith("process.")] == [
        "process.started", "process.completed"]


# ---------------------------------------------------------------- priority

def test_the_activity_priority_orders_the_pooled_queue() -> None:
    """One worker, busy; three activities become ready meanwhile: the pooled model serves
    the one whose XPDL Priority is highest first (the workflow's priority, 2, for the one
    without a Priority)."""
    acts = '<Activity Id="fork"><Route GatewayType="Parallel"/></Activity>' + "".join(
        f'<Activity Id="{a}"><Implementation><No/></Implementation>'
        + (f"<Priority>{p}</Priority>" if p is not None else "")
        + '<ExtendedAttributes><ExtendedAttribute Name="opspec:CpuDemand" Value="1s"/>'
        "</ExtendedAttributes></Activity>"
        for a, p in (("busy", 9), ("low", 1), ("mid", None), ("high", 5)))
    trans = "".join(f'<Transition Id="t{n}" From="fork" To="{a}"/>'
                    for n, a in enumerate(("busy", "low", "mid", "high")))
    processes = f"""
      <WorkflowProcess Id="w"><ProcessHeader><Priority>2</Priority></ProcessHeader>
        <Activities>{acts}</Activities><Transitions>{trans}</Transitions>
      </WorkflowProcess>"""
    package = load(XPDL21.format(processes=processes))
    config = EngineConfig(processor_model="pooled", workers=1, switch_cost=0.0)
    result = run(package, config=config)
    assert [(e.activity, e.time) for e in result.trace if e.kind == "activity.completed"
            and e.activity != "fork"] == [("busy", 1.0), ("high", 2.0), ("mid", 3.0),
                                          ("low", 4.0)]
    queued = {e.activity: e.data["priority"] for e in result.trace if e.kind == "activity.queued"}
    assert queued == {"low": 1, "mid": 2, "high": 5}


# ---------------------------------------------------------------- timers

def _start_timer(timer: str, process: str = "w") -> str:
    return f"""
      <WorkflowProcess Id="{process}"><ProcessHeader/>
        <Activities>
          <Activity Id="tick"><Event><StartEvent Trigger="Timer"><TriggerTimer>{timer}</TriggerTimer>
          </StartEvent></Event></Activity>
          <Activity Id="work"><Implementation><No/></Implementation></Activity>
        </Activities>
        <Transitions><Transition Id="t" From="tick" To="work"/></Transitions>
      </WorkflowProcess>"""


def starts(result: Any, process: str = "w") -> list[float]:
    return [e.time for e in result.trace if e.kind == "process.started" and e.process == process]


@pytest.mark.parametrize(("timer", "expected"), [
    ("<TimeCycle>R3/PT7S</TimeCycle>", [7.0, 14.0, 21.0]),
    ("<TimeCycle>R/PT30S</TimeCycle>", [30.0, 60.0, 90.0]),
    ("<TimeCycle>PT30S</TimeCycle>", [30.0, 60.0, 90.0]),
    ("<TimeCycle>R2/T00:00:10/PT25S</TimeCycle>", [10.0, 35.0]),
    ("<TimeDate>00:01:05</TimeDate>", [65.0]),
])
def test_start_timers(timer: str, expected: list[float]) -> None:
    result = run(load(XPDL21.format(processes=_start_timer(timer))), until=100.0)
    assert starts(result) == expected


def test_calendar_dates_count_from_the_earliest_date_of_the_package_as_day_one() -> None:
    """``R5/2026-01-01T08:00:00/PT1H``: five starts from 08:00 of day 1, hourly; a TimeDate
    of the next day is on day 2 of the run."""
    processes = (_start_timer("<TimeCycle>R5/2026-01-01T08:00:00/PT1H</TimeCycle>", "hourly")
                 + _start_timer("<TimeDate>2026-01-02T09:30:00Z</TimeDate>", "once"))
    result = run(load(XPDL21.format(processes=processes)), until=3 * 86_400.0)
    assert starts(result, "hourly") == [8 * 3600.0 + k * 3600.0 for k in range(5)]
    assert starts(result, "once") == [86_400.0 + 9.5 * 3600.0]


@pytest.mark.parametrize(("timer", "waited"), [
    ("<TimeCycle>R3/PT7S</TimeCycle>", 7.0),
    ("<TimeDate>00:00:40</TimeDate>", 40.0),
    ("<TimeCycle>R/T00:00:00/PT15S</TimeCycle>", 15.0),
])
def test_intermediate_timer_events(timer: str, waited: float) -> None:
    """A token reaching an intermediate timer at t=5 s: an interval without a start waits one
    period; a TimeDate waits until its time; a dated interval until its next firing."""
    processes = f"""
      <WorkflowProcess Id="w"><ProcessHeader/>
        <Activities>
          <Activity Id="busy"><Implementation><No/></Implementation>
            <ExtendedAttributes><ExtendedAttribute Name="opspec:Duration" Value="PT5S"/></ExtendedAttributes></Activity>
          <Activity Id="wait"><Event><IntermediateEvent Trigger="Timer"><TriggerTimer>{timer}</TriggerTimer>
          </IntermediateEvent></Event></Activity>
          <Activity Id="after"><Implementation><No/></Implementation></Activity>
        </Activities>
        <Transitions><Transition Id="t1" From="busy" To="wait"/><Transition Id="t2" From="wait" To="after"/></Transitions>
      </WorkflowProcess>"""
    result = run(load(XPDL21.format(processes=processes)))
    done = {e.activity: e.time for e in result.trace if e.kind == "activity.completed"}
    expected = 5.0 + waited if "TimeCycle>R3" in timer else waited
    assert done["after"] == pytest.approx(expected)


@pytest.mark.parametrize("timer", [
    "<TimeCycle>R0/PT1S</TimeCycle>", "<TimeCycle>Rx/PT1S</TimeCycle>",
    "<TimeCycle>R/never/PT1S</TimeCycle>", "<TimeDate>2026-02-30T08:00</TimeDate>",
    "<TimeCycle>R3/PT0S</TimeCycle>",
])
def test_bad_timers_are_located_errors(timer: str) -> None:
    result = parse_bytes(XPDL21.format(processes=_start_timer(timer)).encode(), path="t.xpdl")
    errors = [d for d in result.diagnostics if d.code == "bad-timer"]
    assert errors and errors[0].location.line == 7, [str(d) for d in result.diagnostics]
