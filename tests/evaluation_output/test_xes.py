"""traces.xes: IEEE 1849-2016 XES that process-mining tools read, written case by case."""

from __future__ import annotations

import re
from collections.abc import Iterator
from datetime import UTC, datetime, timedelta, timezone
from pathlib import Path

import pytest
from lxml import etree

from opspec.engine.trace import EventKind, TraceEvent
from opspec.errors import EvaluationError
from opspec.evaluation.exporters import (
    DEFAULT_EPOCH,
    DEFAULT_XES_KINDS,
    LIFECYCLE_TRANSITIONS,
    XES_NAMESPACE,
    XesWriter,
)

NS = {"x": XES_NAMESPACE}
SCHEMA_PATH = Path(__file__).parent / "data" / "xes-1849-2016-checks.xsd"
STANDARD_TRANSITIONS = {"schedule", "assign", "withdraw", "reassign", "start", "suspend",
                        "resume", "pi_abort", "ate_abort", "complete", "autoskip",
                        "manualskip", "unknown"}


@pytest.fixture(scope="module")
def schema() -> etree.XMLSchema:
    return etree.XMLSchema(etree.parse(str(SCHEMA_PATH)))


def write_log(path: Path, cases: dict[str, list[TraceEvent]], **options: object) -> Path:
    with XesWriter(path, log_attributes={"concept:name": "dispenser"},
                   **options) as writer:  # type: ignore[arg-type]
        for number, (case_id, events) in enumerate(cases.items()):
            writer.add_case(case_id, events, {"user": number, "model": "reference"})
    return path


def attrs(element: etree._Element) -> dict[str, str]:
    """The key → value of an element's direct attribute children."""
    return {child.get("key"): child.get("value") for child in element
            if child.tag != f"{{{XES_NAMESPACE}}}event" and child.get("key") is not None}


def events_of(path: Path) -> list[dict[str, str]]:
    tree = etree.parse(str(path))
    return [attrs(e) for e in tree.iterfind(".//x:trace/x:event", NS)]


# ------------------------------------------------------------------------- schema, shape

def test_xes_of_a_real_run_validates_against_the_xes_schema(
        tmp_path: Path, dispenser_day: list[TraceEvent], schema: etree.XMLSchema) -> None:
    path = write_log(tmp_path / "traces.xes", {"user-0": dispenser_day, "user-1": dispenser_day})
    document = etree.parse(str(path))
    assert schema.validate(document), schema.error_log


def test_schema_rejects_a_broken_log(tmp_path: Path, schema: etree.XMLSchema) -> None:
    # the check above can fail: a wrongly typed value and a misplaced element are caught
    bad = tmp_path / "bad.xes"
    bad.write_text(f'<log xes.version="1849-2016" xmlns="{XES_NAMESPACE}"><trace>'
                   '<event><date key="time:timestamp" value="08:00 today"/></event></trace>'
                   '<classifier name="A" keys="concept:name"/></log>')
    assert not schema.validate(etree.parse(str(bad)))


def test_xes_log_header_declares_extensions_globals_and_classifiers(
        tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    root = etree.parse(str(write_log(tmp_path / "t.xes", {"u": dispenser_day}))).getroot()
    assert root.tag == f"{{{XES_NAMESPACE}}}log"
    assert root.get("xes.version") == "1849-2016"
    assert root.get("xes.features") == ""
    extensions = {e.get("prefix"): e.get("uri") for e in root.iterfind("x:extension", NS)}
    assert extensions == {p: f"{XES_NAMESPACE}{p}.xesext"
                          for p in ("concept", "time", "lifecycle", "org")}
    globals_ = {g.get("scope"): attrs(g) for g in root.iterfind("x:global", NS)}
    assert set(globals_["trace"]) == {"concept:name"}
    assert {"concept:name", "lifecycle:transition", "time:timestamp"} <= set(globals_["event"])
    for classifier in root.iterfind("x:classifier", NS):
        assert set(classifier.get("keys", "").split()) <= set(globals_["event"])
    log = attrs(root)
    assert log["concept:name"] == "dispenser"
    assert log["lifecycle:model"] == "standard"


def test_every_global_event_attribute_is_on_every_event(
        tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    path = write_log(tmp_path / "t.xes", {"u": dispenser_day})
    root = etree.parse(str(path)).getroot()
    declared = set(attrs(next(g for g in root.iterfind("x:global", NS)
                              if g.get("scope") == "event")))
    events = events_of(path)
    assert events
    for event in events:
        assert declared <= set(event), f"event {event} lacks a global attribute"
        assert event["lifecycle:transition"] in STANDARD_TRANSITIONS


# ---------------------------------------------------------------------- the event mapping

def test_each_case_is_one_trace_named_by_its_id_with_typed_attributes(
        tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    path = write_log(tmp_path / "t.xes", {"user-0": dispenser_day, "user-1": []})
    traces = etree.parse(str(path)).getroot().findall("x:trace", NS)
    assert [attrs(t)["concept:name"] for t in traces] == ["user-0", "user-1"]
    user = traces[1].find("x:int[@key='user']", NS)
    assert user is not None and user.get("value") == "1"
    assert traces[1].findall("x:event", NS) == []


def test_activity_life_cycle_maps_to_standard_transitions(
        tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    events = events_of(write_log(tmp_path / "t.xes", {"u": dispenser_day}))
    take_pill = [(e["opspec:kind"], e["lifecycle:transition"]) for e in events
                 if e["concept:name"] == "user_workflow/take_pill"]
    assert take_pill == [("activity.started", "start"), ("activity.offered", "assign"),
                         ("activity.completed", "complete")]
    hear = {(e["opspec:kind"], e["lifecycle:transition"]) for e in events
            if e["concept:name"] == "user_workflow/hear_alarm"}
    assert ("activity.omitted", "manualskip") in hear


def test_deadlines_are_events_and_triggers_and_data_changes_are_not(
        tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    events = events_of(write_log(tmp_path / "t.xes", {"u": dispenser_day}))
    kinds = {e["opspec:kind"] for e in events}
    assert kinds <= DEFAULT_XES_KINDS
    assert EventKind.TRIGGER_RAISED not in kinds and EventKind.DATA_CHANGED not in kinds
    deadlines = [e for e in events if e["opspec:kind"] == EventKind.DEADLINE_EXPIRED]
    assert deadlines and {e["concept:name"] for e in deadlines} == {"deadline:notify_workflow/wait_report"}
    assert all(e["opspec:exception"] == "no_report" for e in deadlines)
    expected = sum(1 for ev in dispenser_day if ev.kind in DEFAULT_XES_KINDS)
    assert len(events) == expected


def test_data_changes_are_attributes_of_the_completing_event(
        tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    path = write_log(tmp_path / "t.xes", {"u": dispenser_day})
    tree = etree.parse(str(path))
    recorded = [e for e in tree.iterfind(".//x:event", NS)
                if attrs(e).get("concept:name") == "notify_workflow/record_taken"
                and attrs(e)["lifecycle:transition"] == "complete"]
    assert len(recorded) == 1
    assert attrs(recorded[0])["outcome"] == "taken"
    alarms = [e.find("x:int[@key='alarms']", NS) for e in tree.iterfind(".//x:event", NS)
              if attrs(e).get("concept:name") == "notify_workflow/sound_alarm"
              and attrs(e)["lifecycle:transition"] == "complete"]
    assert alarms and all(a is not None for a in alarms), "alarms is written as an int"


def test_timestamps_are_simulated_seconds_after_the_epoch(
        tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    events = events_of(write_log(tmp_path / "t.xes", {"u": dispenser_day}))
    for event in events:
        stamp = datetime.fromisoformat(event["time:timestamp"])
        assert stamp.utcoffset() == timedelta(0)
        assert stamp == DEFAULT_EPOCH + timedelta(seconds=float(event["opspec:time"]))
    first_pill = next(e for e in events if e["concept:name"] == "user_workflow/take_pill"
                      and e["lifecycle:transition"] == "complete")
    assert first_pill["time:timestamp"] == "2026-01-05T08:01:50.000+00:00"


def test_epoch_is_configurable_and_keeps_its_offset(
        tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    berlin = timezone(timedelta(hours=1))
    epoch = datetime(2025, 3, 1, tzinfo=berlin)
    events = events_of(write_log(tmp_path / "t.xes", {"u": dispenser_day}, epoch=epoch))
    assert events[0]["time:timestamp"] == "2025-03-01T08:00:00.000+01:00"


def test_naive_epoch_is_refused(tmp_path: Path) -> None:
    with pytest.raises(EvaluationError, match="has no time zone"):
        XesWriter(tmp_path / "t.xes", epoch=datetime(2026, 1, 5))
    assert not list(tmp_path.iterdir())


def test_kinds_select_what_is_exported(tmp_path: Path,
                                       dispenser_day: list[TraceEvent]) -> None:
    events = events_of(write_log(tmp_path / "t.xes", {"u": dispenser_day},
                                 kinds={EventKind.ACTIVITY_COMPLETED}))
    assert events and {e["lifecycle:transition"] for e in events} == {"complete"}
    with pytest.raises(EvaluationError, match=r"cannot export event kinds trigger\.raised"):
        XesWriter(tmp_path / "u.xes", kinds={EventKind.TRIGGER_RAISED})


def test_activity_names_replace_ids_in_concept_name(tmp_path: Path,
                                                   dispenser_day: list[TraceEvent]) -> None:
    names = {("user_workflow", "take_pill"): "Take the pill"}
    events = events_of(write_log(tmp_path / "t.xes", {"u": dispenser_day},
                                 activity_names=names))
    pills = [e for e in events if e.get("opspec:activity") == "take_pill"]
    assert pills and {e["concept:name"] for e in pills} == {"Take the pill"}


def test_resource_and_group_come_from_participant_and_lane(
        tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    events = events_of(write_log(tmp_path / "t.xes", {"u": dispenser_day}))
    pill = next(e for e in events if e["concept:name"] == "user_workflow/take_pill")
    assert (pill["org:resource"], pill["org:group"]) == ("user", "user")
    assert any(e.get("org:group") == "device" for e in events)


# ------------------------------------------------------------------------ hostile values

HOSTILE = 'a "quoted" <tag> & \'apos\' \x00\x07 tab\there\nnewline \u00e9\u4e2d \U0001f600'


def test_hostile_strings_and_odd_values_stay_well_formed_and_typed(
        tmp_path: Path, schema: etree.XMLSchema) -> None:
    events = [
        TraceEvent(10.5, EventKind.ACTIVITY_COMPLETED, process="p", instance=1,
                   activity=HOSTILE, lane="user", participant=HOSTILE,
                   data={"choice": HOSTILE, "ok": True, "n": 3, "x": float("nan"),
                         "big": 2**70, "list": [1, "a"], "none": None}),
        TraceEvent(11.0, EventKind.DATA_CHANGED, process="p", instance=1, activity="b",
                   data={"bad key!": 1.5, "concept:name": "spoof"}),
        TraceEvent(12.0, EventKind.ACTIVITY_COMPLETED, process="p", instance=1, activity="b"),
    ]
    path = tmp_path / "t.xes"
    with XesWriter(path, log_attributes={"note": HOSTILE}) as writer:
        writer.add_case(HOSTILE, events, {"flag": False, HOSTILE: 1})
    document = etree.parse(str(path))
    assert schema.validate(document), schema.error_log
    root = document.getroot()
    first, second = root.findall(".//x:event", NS)
    values = attrs(first)
    cleaned = HOSTILE.replace("\x00", "\ufffd").replace("\x07", "\ufffd")
    assert values["concept:name"] == f"p/{cleaned}"       # qualified by its process
    assert values["org:resource"] == cleaned
    assert values["opspec:choice"] == cleaned
    typed = {c.get("key"): c.tag.split("}")[1] for c in first}
    assert typed["opspec:ok"] == "boolean" and typed["opspec:n"] == "int"
    assert typed["opspec:x"] == "float" and values["opspec:x"] == "NaN"
    assert typed["opspec:big"] == "string", "beyond xs:long is written as text"
    assert values["opspec:list"] == '[1, "a"]'
    assert "opspec:none" not in values
    data = attrs(second)
    assert data["concept:name"] == "p/b", "a data field cannot overwrite a standard key"
    assert data["data:concept:name"] == "spoof"
    assert data["bad_key_"] == "1.5"


# ----------------------------------------------------------------------- files and errors

def test_file_appears_only_when_closed(tmp_path: Path,
                                       dispenser_day: list[TraceEvent]) -> None:
    path = tmp_path / "traces.xes"
    writer = XesWriter(path)
    writer.add_case("u", dispenser_day)
    assert not path.exists() and (tmp_path / "traces.xes.partial").exists()
    writer.close()
    writer.close()   # a second close does nothing
    assert path.exists() and not (tmp_path / "traces.xes.partial").exists()
    etree.parse(str(path))
    with pytest.raises(EvaluationError, match="already closed"):
        writer.add_case("late", [])


def test_failure_inside_the_with_block_leaves_only_the_partial_file(tmp_path: Path) -> None:
    path = tmp_path / "traces.xes"
    path.write_text("previous export")

    def broken() -> Iterator[TraceEvent]:
        yield TraceEvent(1.0, EventKind.ACTIVITY_STARTED, process="p", instance=1,
                         activity="a")
        raise RuntimeError("simulation crashed")

    with pytest.raises(RuntimeError, match="simulation crashed"), XesWriter(path) as writer:
        writer.add_case("u", broken())
    assert path.read_text() == "previous export"
    assert (tmp_path / "traces.xes.partial").exists()


def test_case_that_fails_midway_stops_the_export(tmp_path: Path) -> None:
    def broken() -> Iterator[TraceEvent]:
        yield TraceEvent(1.0, EventKind.ACTIVITY_STARTED, process="p", instance=1,
                         activity="a")
        raise RuntimeError("replication crashed")

    writer = XesWriter(tmp_path / "traces.xes")
    with pytest.raises(RuntimeError, match="replication crashed"):
        writer.add_case("u", broken())
    with pytest.raises(EvaluationError, match="already closed"):
        writer.add_case("next", [])
    writer.close()
    assert not (tmp_path / "traces.xes").exists()


def test_unwritable_folder_is_an_evaluation_error(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(EvaluationError, match=r"cannot write the trace export .*traces\.xes"):
        XesWriter(blocker / "traces.xes")


def test_every_mapped_transition_is_a_standard_one() -> None:
    assert set(LIFECYCLE_TRANSITIONS.values()) <= STANDARD_TRANSITIONS
    assert DEFAULT_XES_KINDS == frozenset(LIFECYCLE_TRANSITIONS)


def test_epoch_default_is_documented() -> None:
    doc = (Path(__file__).resolve().parents[2] / "docs" / "xes-export.md").read_text()
    assert DEFAULT_EPOCH.isoformat() in doc
    for kind, transition in LIFECYCLE_TRANSITIONS.items():
        assert re.search(rf"`{re.escape(kind)}`.*`{transition}`", doc), kind
    assert DEFAULT_EPOCH == datetime(2026, 1, 5, tzinfo=UTC)


# ---------------------------------------------------------------- process-mining read-back

@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.filterwarnings("ignore::DeprecationWarning")
def test_pm4py_reads_the_log_back(tmp_path: Path, dispenser_day: list[TraceEvent]) -> None:
    pm4py = pytest.importorskip("pm4py", reason="pip install opspec[xes] to run this test")
    path = write_log(tmp_path / "traces.xes", {"user-0": dispenser_day,
                                               "user-1": dispenser_day})
    frame = pm4py.read_xes(str(path))
    expected = sum(1 for ev in dispenser_day if ev.kind in DEFAULT_XES_KINDS)
    assert len(frame) == 2 * expected
    assert sorted(frame["case:concept:name"].unique()) == ["user-0", "user-1"]
    assert set(frame["lifecycle:transition"]) <= STANDARD_TRANSITIONS
    assert str(frame["time:timestamp"].dt.tz) == "UTC"
    assert frame["case:user"].tolist().count(1) == expected
    completed = pm4py.filter_event_attribute_values(frame, "lifecycle:transition",
                                                    ["complete"], level="event")
    assert "user_workflow/take_pill" in set(completed["concept:name"])
    log = pm4py.read_xes(str(path), return_legacy_log_object=True)
    assert set(log.classifiers) == {"Activity", "ActivityLifecycle"}


# ------------------------------------------------------------------------ lanes by name

KITCHEN = Path(__file__).resolve().parents[1] / "tui" / "data" / "kitchen_lanes.bpmn"


def test_org_group_is_the_lanes_name_in_xes_and_ocel(tmp_path: Path, no_report) -> None:
    """The XES Organizational extension: "group — The group within the organizational
    structure" (IEEE 1849-2016, org:group). A process-mining tool shows this string to the
    analyst, so a BPMN lane's name ("Stove guard appliance"), not its XML id (guard_lane),
    as the text timeline shows it; a lane without a name keeps its id."""
    import json

    from opspec.cli import main

    out = tmp_path / "run"
    assert main(["evaluate", str(KITCHEN), "--users", "2", "--days", "1", "--workers", "1",
                 "--user-model", "klm", "--export", "xes,ocel", "--out", str(out),
                 "--quiet"]) == 0
    groups = {e["opspec:activity"]: e.get("org:group") for e in events_of(out / "traces.xes")
              if e.get("opspec:activity")}
    assert groups.get("sense_heat") == "Stove guard appliance", groups
    assert groups.get("confirm") == "Resident", groups
    ocel = json.loads((out / "traces.jsonocel").read_text(encoding="utf-8"))
    ocel_groups = {a["value"] for e in ocel["events"] for a in e["attributes"]
                   if a["name"] == "org:group"}
    assert ocel_groups == {"Stove guard appliance", "Resident"}, ocel_groups


def test_org_group_keeps_a_lane_id_without_a_name(tmp_path: Path,
                                                   dispenser_day: list[TraceEvent]) -> None:
    """Lanes named only for some: the named one by its name, the other by its id."""
    events = events_of(write_log(tmp_path / "t.xes", {"u": dispenser_day},
                                 lane_names={"device": "Dispenser"}))
    groups = {e.get("org:group") for e in events}
    assert "Dispenser" in groups and "user" in groups and "device" not in groups
