"""The BPMN drawing of the medication dispenser (specs/medication_dispenser.bpmn) is the same
specification as the XPDL one: the same evaluation numbers for the same seed, the same
workflows, activities, user lane and metrics, and a diagram bpmn.io can draw."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
from lxml import etree

from opspec.cli import main
from opspec.engine.compiled import compile_package
from opspec.engine.lanes import user_lane
from opspec.model.activities import Deadline, Event, EventPosition, TriggerKind
from opspec.model.process import ConditionKind
from opspec.xpdl.loader import load_package

SPECS = Path(__file__).resolve().parents[2] / "specs"
BPMN_SPEC = SPECS / "medication_dispenser.bpmn"
XPDL_SPEC = SPECS / "medication_dispenser.xpdl"
BPMN_NS = "http://www.omg.org/spec/BPMN/20100524/MODEL"
DI_NS = "http://www.omg.org/spec/BPMN/20100524/DI"


def _evaluate(spec: Path, out: Path, capsys: pytest.CaptureFixture[str], *,
              report: bool = True) -> dict[str, object]:
    with pytest.MonkeyPatch.context() as patch:
        if not report:      # the XPDL spec's report is drawn and read by tests/evaluation
            patch.setattr("opspec.evaluation.report.write_report",
                          lambda store, *_args, **_kwargs: store.folder / "report.html")
        code = main(["evaluate", str(spec), "--users", "50", "--days", "7", "--seed", "3",
                     "--workers", "1", "--out", str(out), "--json", "--quiet"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    return json.loads(captured.out)


def test_evaluation_gives_the_numbers_of_the_xpdl_spec(tmp_path: Path,
                                                        capsys: pytest.CaptureFixture[str]
                                                        ) -> None:
    xpdl = _evaluate(XPDL_SPEC, tmp_path / "xpdl", capsys, report=False)
    bpmn = _evaluate(BPMN_SPEC, tmp_path / "bpmn", capsys)
    # both used the companion user model (specs/medication_dispenser.users.toml)
    assert str(bpmn["user_model"]).endswith("medication_dispenser.users.toml")
    assert bpmn["user_model"] == xpdl["user_model"]
    assert bpmn["failed"] == xpdl["failed"] == []
    assert set(bpmn["metrics"]) == set(xpdl["metrics"])       # no metric left behind
    for name, values in xpdl["metrics"].items():
        assert bpmn["metrics"][name] == values, name
    # the numbers are those of a real run: doses were due, taken and some missed
    metrics = bpmn["metrics"]
    assert metrics["doses_due"]["total"] == 50 * 7 * 4
    assert 0 < metrics["doses_missed"]["total"] < metrics["doses_taken"]["total"]
    assert bpmn["monitors"] == xpdl["monitors"]


def _bare(value: object) -> object:
    """``value`` with every ``location`` dropped (the two files place things differently)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return tuple((f.name, _bare(getattr(value, f.name)))
                     for f in dataclasses.fields(value) if f.name != "location")
    if isinstance(value, tuple):
        return tuple(_bare(v) for v in value)
    return value


def _packages():
    bpmn = load_package(BPMN_SPEC)
    xpdl = load_package(XPDL_SPEC)
    assert bpmn.ok, bpmn.diagnostics
    assert bpmn.package is not None and xpdl.package is not None
    return bpmn.package, xpdl.package


def test_the_same_workflows_activities_and_flows() -> None:
    bpmn, xpdl = _packages()
    assert [p.id for p in bpmn.processes] == [p.id for p in xpdl.processes]
    for ours, theirs in zip(bpmn.processes, xpdl.processes, strict=True):
        boundary = {a.id for a in ours.activities
                    if isinstance(a.body, Event) and a.body.position is EventPosition.INTERMEDIATE
                    and any(t.target == a.id and t.condition.kind in (
                        ConditionKind.EXCEPTION, ConditionKind.DEFAULTEXCEPTION)
                        for t in ours.transitions)}
        # every XPDL activity is there under its id; the only others are boundary events
        assert {a.id for a in ours.activities} - boundary == {a.id for a in theirs.activities}
        assert _bare(ours.directives) == _bare(theirs.directives)
        assert {f.id: f.initial for f in ours.data_fields} == {
            f.id: f.initial for f in theirs.data_fields}
        assert [(f.id, f.mode) for f in ours.formal_parameters] == [
            (f.id, f.mode) for f in theirs.formal_parameters]
        # a sequence flow for every transition between the same activities
        normal = {(t.id, t.source, t.target) for t in ours.transitions
                  if t.source not in boundary and t.target not in boundary}
        xpdl_normal = {(t.id, t.source, t.target) for t in theirs.transitions
                       if t.condition.kind not in (ConditionKind.EXCEPTION,
                                                   ConditionKind.DEFAULTEXCEPTION)}
        assert normal == xpdl_normal
    assert _bare(bpmn.metrics) == _bare(xpdl.metrics)
    assert _bare(bpmn.applications) == _bare(xpdl.applications)


def test_the_boundary_timer_is_the_deadline_and_errors_the_exception_paths() -> None:
    bpmn, xpdl = _packages()
    notify = bpmn.process("notify_workflow")
    assert notify is not None
    wait = notify.activity("wait_report")
    assert wait is not None and isinstance(wait.body, Event)
    assert wait.body.trigger.kind is TriggerKind.MESSAGE and wait.body.trigger.name == "trg_1"
    xpdl_wait = xpdl.process("notify_workflow").activity("wait_report")  # type: ignore[union-attr]
    (deadline,) = wait.deadlines
    assert isinstance(deadline, Deadline)
    assert (deadline.duration, deadline.execution) == (xpdl_wait.deadlines[0].duration,
                                                       xpdl_wait.deadlines[0].execution)
    exceptions = {(t.source, t.condition.kind.value, t.condition.exception_name)
                  for t in notify.transitions if t.condition.kind in (
                      ConditionKind.EXCEPTION, ConditionKind.DEFAULTEXCEPTION)}
    assert exceptions == {("wait_report", "EXCEPTION", "no_report"),
                          ("sound_alarm", "DEFAULTEXCEPTION", None),
                          ("dispense", "EXCEPTION", "DrawerJammed"),
                          ("dispense", "EXCEPTION", "DrawerEmpty"),
                          ("dispense", "DEFAULTEXCEPTION", None)}
    # the message flows are the triggers: the alarm raises trg_2, the report trg_1
    assert notify.activity("sound_alarm").directives.raises.name == "trg_2"  # type: ignore[union-attr]
    user = bpmn.process("user_workflow")
    assert user.activity("press_report").directives.raises.name == "trg_1"  # type: ignore[union-attr]


def test_the_user_lane_is_the_same() -> None:
    bpmn, xpdl = _packages()
    ours, theirs = user_lane(compile_package(bpmn)), user_lane(compile_package(xpdl))
    assert ours.manual == theirs.manual
    assert ours.choices == theirs.choices == {
        "choose_button": ("press_report", "press_wrong_button")}


def test_the_diagram_places_every_element() -> None:
    """bpmn.io draws only what BPMNDI places: every pool, lane, flow node, sequence flow and
    message flow has a shape with bounds or an edge with at least two waypoints."""
    root = etree.parse(str(BPMN_SPEC)).getroot()
    shapes = {s.get("bpmnElement"): s for s in root.iter(f"{{{DI_NS}}}BPMNShape")}
    edges = {e.get("bpmnElement"): e for e in root.iter(f"{{{DI_NS}}}BPMNEdge")}
    planes = list(root.iter(f"{{{DI_NS}}}BPMNPlane"))
    assert len(planes) == 1
    assert planes[0].get("bpmnElement") == root.find(f"{{{BPMN_NS}}}collaboration").get("id")
    drawn = 0
    for element in root.iter(f"{{{BPMN_NS}}}*"):
        name = etree.QName(element).localname
        if name in ("sequenceFlow", "messageFlow"):
            edge = edges[element.get("id")]
            assert len(edge.findall("{http://www.omg.org/spec/DD/20100524/DI}waypoint")) >= 2
            drawn += 1
        elif name in ("participant", "lane", "task", "serviceTask", "manualTask",
                      "receiveTask", "callActivity", "startEvent", "endEvent",
                      "boundaryEvent", "exclusiveGateway", "eventBasedGateway"):
            bounds = shapes[element.get("id")].find("{http://www.omg.org/spec/DD/20100524/DC}Bounds")
            assert bounds is not None and float(bounds.get("width")) > 0
            drawn += 1
    assert drawn == len(shapes) + len(edges)       # nothing drawn that is not in the model
