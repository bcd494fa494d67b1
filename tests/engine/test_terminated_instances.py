"""A terminated instance does nothing more: it starts, raises and pushes nothing after its
termination, and its open work items are withdrawn (XPDL 2.1 §7.6: a terminated process
instance ends every activity instance it has; BPMN 2.0 §13.5.6 terminate end event)."""

from __future__ import annotations

from pathlib import Path

from opspec.engine.performers import PerformerSession, WorkItem
from opspec.engine.simulation import RunResult, Simulation
from opspec.xpdl.loader import load_spec

NS = "http://www.wfmc.org/2008/XPDL2.1"


def package(tmp_path: Path, processes: str, fields: str = "", after: str = "") -> Path:
    path = tmp_path / "lifecycle.xpdl"
    path.write_text(
        f'<?xml version="1.0" encoding="UTF-8"?>\n<Package xmlns="{NS}" Id="life">'
        "<PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2026"
        "</Created></PackageHeader>"
        '<Participants><Participant Id="user"><ParticipantType Type="HUMAN"/></Participant>'
        "</Participants>"
        f"<DataFields>{fields}</DataFields><WorkflowProcesses>{processes}</WorkflowProcesses>"
        f"{after}</Package>")
    return path


def field(fid: str, initial: str) -> str:
    return (f'<DataField Id="{fid}"><DataType><BasicType Type="INTEGER"/></DataType>'
            f"<InitialValue>{initial}</InitialValue></DataField>")


def directives(**values: str) -> str:
    return ("<ExtendedAttributes>" + "".join(
        f'<ExtendedAttribute Name="opspec:{k}" Value="{v}"/>' for k, v in values.items())
        + "</ExtendedAttributes>")


def run(path: Path, performers: dict[str, object] | None = None) -> RunResult:
    sim = Simulation(load_spec(path), keep_trace=True, performers=performers)  # type: ignore[arg-type]
    return sim.run(until=100)


def kinds(result: RunResult, *wanted: str) -> list[tuple[str, str | None, str | None]]:
    assert result.trace is not None
    return [(e.kind, e.process, e.activity) for e in result.trace if e.kind in wanted]


def test_an_end_trigger_fired_by_a_start_assignment_stops_the_instance_there(
        tmp_path: Path) -> None:
    """The start assignment of `stop_now` makes the workflow's end rule true: its
    asynchronous subflow call must not start `child`, and the message it raises at the end
    must not be raised."""
    processes = (
        '<WorkflowProcess Id="main"><ProcessHeader/><Activities>'
        '<Activity Id="stop_now"><Implementation><SubFlow Id="child" Execution="ASYNCHR"/>'
        '</Implementation>'
        f'{directives(Raises="message:too_late")}'
        '<Assignments><Assignment AssignTime="Start"><Target>stop</Target>'
        "<Expression>1</Expression></Assignment></Assignments></Activity>"
        '<Activity Id="after"><Implementation><No/></Implementation></Activity>'
        '</Activities><Transitions><Transition Id="t1" From="stop_now" To="after"/>'
        f'</Transitions>{directives(EndTrigger="rule:stop &gt; 0")}</WorkflowProcess>'
        '<WorkflowProcess Id="child"><ProcessHeader/><Activities>'
        '<Activity Id="c"><Implementation><No/></Implementation></Activity></Activities>'
        "</WorkflowProcess>")
    result = run(package(tmp_path, processes, field("stop", "0")))
    assert kinds(result, "process.started", "process.terminated", "trigger.raised",
                 "activity.completed") == [
        ("process.started", "main", None), ("process.terminated", "main", None)]


def test_a_mode_change_that_ends_its_own_workflow_runs_nothing_after_it(
        tmp_path: Path) -> None:
    processes = (
        '<WorkflowProcess Id="day"><ProcessHeader/><Activities>'
        '<Activity Id="go_night"><Implementation><No/></Implementation>'
        '<ExtendedAttributes><ExtendedAttribute Name="opspec:BuiltIn">'
        '<opspec:ModeChange xmlns:opspec="urn:opspec:sisarl:1" To="night"/>'
        "</ExtendedAttribute></ExtendedAttributes></Activity>"
        f'<Activity Id="after"><Implementation><No/></Implementation>'
        f'{directives(Raises="message:too_late")}</Activity>'
        '</Activities><Transitions><Transition Id="t1" From="go_night" To="after"/>'
        f'</Transitions>{directives(Mode="day")}</WorkflowProcess>'
        '<WorkflowProcess Id="night_work"><ProcessHeader/><Activities>'
        '<Activity Id="n"><Implementation><No/></Implementation></Activity></Activities>'
        f'{directives(Mode="night")}</WorkflowProcess>')
    modes = ('<ExtendedAttributes><ExtendedAttribute Name="opspec:Modes" xmlns:opspec='
             '"urn:opspec:sisarl:1"><opspec:Mode Id="day" Initial="true"/>'
             '<opspec:Mode Id="night"/></ExtendedAttribute></ExtendedAttributes>')
    result = run(package(tmp_path, processes, after=modes))
    trace = kinds(result, "activity.started", "trigger.raised", "process.terminated")
    assert ("activity.started", "day", "after") not in trace
    assert ("trigger.raised", "day", "after") not in trace
    assert ("process.terminated", "day", None) in trace
    assert ("activity.started", "night_work", "n") in trace


class Holder:
    """A performer that keeps every work item it is offered and records withdrawals."""

    def __init__(self) -> None:
        self.withdrawn: list[tuple[str, str]] = []

    def attach(self, session: PerformerSession) -> None:
        self.session = session

    def offer(self, item: WorkItem) -> None:
        pass

    def withdraw(self, item: WorkItem, reason: str) -> None:
        self.withdrawn.append((item.activity, reason))


def test_a_terminated_instance_withdraws_its_open_work_items(tmp_path: Path) -> None:
    processes = (
        '<WorkflowProcess Id="main"><ProcessHeader/><Activities>'
        '<Activity Id="start"><Implementation><No/></Implementation></Activity>'
        '<Activity Id="press"><Implementation><No/></Implementation>'
        "<Performers><Performer>user</Performer></Performers></Activity>"
        f'<Activity Id="stopper"><Implementation><No/></Implementation>'
        f'{directives(Duration="ConstantParameter(5)")}</Activity>'
        '<Activity Id="end"><Event><EndEvent Result="Terminate"/></Event></Activity>'
        '</Activities><Transitions><Transition Id="t1" From="start" To="press"/>'
        '<Transition Id="t2" From="start" To="stopper"/>'
        '<Transition Id="t3" From="stopper" To="end"/></Transitions></WorkflowProcess>')
    holder = Holder()
    result = run(package(tmp_path, processes), {"user": holder})
    assert holder.withdrawn == [("press", "end event 'end'")]
    assert kinds(result, "activity.withdrawn") == [("activity.withdrawn", "main", "press")]
    assert result.summary["instances"]["terminated"] == 1
