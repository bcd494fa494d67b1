"""`--export ocel` (OCEL 2.0 JSON), the case notions of the XES/JSONL exports (`--case`) and
the size estimate printed before an export (issue 20)."""

from __future__ import annotations

import json
import warnings
from collections import Counter
from datetime import datetime
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.engine.trace import EventKind, TraceEvent
from opspec.evaluation.exporters import DEFAULT_XES_KINDS

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
SCHEMA = Path(__file__).parent / "data" / "ocel20-json-checks.schema.json"
USERS, DAYS = 3, 2


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict, str]:
    """3 users x 2 days exported as OCEL, XES and JSONL, in one run: the XES and JSONL cases
    are chains by default (one per dose of the dispenser). No report: these tests read the
    exports (tests/evaluate_without_report.py)."""
    out = tmp_path_factory.mktemp("ocel") / "run"
    import contextlib
    import io

    from evaluate_without_report import without_report

    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr), \
            without_report():
        status = main(["evaluate", str(SPEC), "--users", str(USERS), "--days", str(DAYS),
                       "--seed", "4", "--out", str(out), "--export", "ocel,xes,jsonl",
                       "--workers", "1", "--json"])
    assert status == 0, stderr.getvalue()
    return out, json.loads(stdout.getvalue()), stderr.getvalue()


def jsonl_events(path: Path) -> list[dict]:
    lines = path.read_text(encoding="utf-8").splitlines()[1:]
    return [e for e in map(json.loads, lines) if e.get("kind") != "case.started"]


def test_ocel_follows_the_ocel2_json_format(run):
    jsonschema = pytest.importorskip("jsonschema")
    out, _, _ = run
    doc = json.loads((out / "traces.jsonocel").read_text(encoding="utf-8"))
    jsonschema.validate(doc, json.loads(SCHEMA.read_text(encoding="utf-8")))
    # what a schema cannot say: every reference resolves, every name is declared
    objects = {o["id"]: o["type"] for o in doc["objects"]}
    assert len(objects) == len(doc["objects"]), "object ids are unique"
    event_types = {t["name"]: {a["name"] for a in t["attributes"]} for t in doc["eventTypes"]}
    object_types = {t["name"]: {a["name"] for a in t["attributes"]} for t in doc["objectTypes"]}
    assert len({e["id"] for e in doc["events"]}) == len(doc["events"])
    for event in doc["events"]:
        assert event["type"] in event_types
        assert {a["name"] for a in event["attributes"]} <= event_types[event["type"]]
        assert all(r["objectId"] in objects for r in event["relationships"])
        datetime.fromisoformat(event["time"])
    for obj in doc["objects"]:
        assert obj["type"] in object_types
        assert {a["name"] for a in obj["attributes"]} <= object_types[obj["type"]]
        assert all(r["objectId"] in objects for r in obj["relationships"])


def test_ocel_events_and_objects_match_the_trace_and_the_metrics(run):
    out, doc, _ = run
    ocel = json.loads((out / "traces.jsonocel").read_text(encoding="utf-8"))
    trace = jsonl_events(out / "traces.jsonl")
    exported = [e for e in trace if e["kind"] in DEFAULT_XES_KINDS]
    assert len(ocel["events"]) == len(exported)
    kinds = Counter(next(a["value"] for a in e["attributes"] if a["name"] == "opspec:kind")
                    for e in ocel["events"])
    assert kinds == Counter(e["kind"] for e in exported)
    types = Counter(o["type"] for o in ocel["objects"])
    assert types["user"] == USERS and types["device"] == USERS
    # one object per dose the dispenser announced (the spec's own doses_due metric), typed
    # after the spec's own workflow that starts a dose, not a word opspec made up
    assert types["timer_workflow"] == doc["metrics"]["doses_due"]["total"] == USERS * DAYS * 4
    assert {"user", "device", "timer_workflow"} <= set(types) <= {
        "user", "device", "timer_workflow", "caregiver"}
    # every event concerns its user and is part of a chain, whose id is its XES/JSONL case
    cases = {e["case"] for e in jsonl_events(out / "traces.jsonl")}
    for event in ocel["events"]:
        related = {r["objectId"] for r in event["relationships"]}
        assert any(o.startswith("user ") for o in related)
        assert len(related & cases) == 1


def test_pm4py_reads_the_ocel_log(run):
    pm4py = pytest.importorskip("pm4py")
    out, doc, _ = run
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ocel = pm4py.read_ocel2(str(out / "traces.jsonocel"))
    trace = jsonl_events(out / "traces.jsonl")
    assert len(ocel.events) == sum(1 for e in trace if e["kind"] in DEFAULT_XES_KINDS)
    counts = ocel.objects["ocel:type"].value_counts().to_dict()
    counts.pop("caregiver", None)            # only when a dose was missed
    assert counts == {"timer_workflow": doc["metrics"]["doses_due"]["total"], "user": USERS,
                      "device": USERS}


def test_case_per_dose_makes_one_trace_per_dose_holding_its_whole_chain(run):
    out, doc, _ = run
    trace = jsonl_events(out / "traces.jsonl")
    by_case: dict[str, list[dict]] = {}
    for event in trace:
        by_case.setdefault(event["case"], []).append(event)
    assert len(by_case) == doc["metrics"]["doses_due"]["total"]
    for case, events in by_case.items():
        processes = Counter(e["process"] for e in events if e["kind"] == "process.started")
        # a dose: one timer firing, its notify and schedule instances, and one user_workflow
        # per alarm (1 to 3)
        assert processes["timer_workflow"] == 1 and processes["notify_workflow"] == 1, case
        assert processes["schedule_workflow"] == 1
        assert 1 <= processes["user_workflow"] <= 3
        alarms = sum(1 for e in events if e["kind"] == "trigger.raised"
                     and e["data"].get("name") == "trg_2")
        assert alarms == processes["user_workflow"], "each alarm's response is in its dose"


def test_xes_per_dose_has_the_same_cases(run):
    from lxml import etree

    out, doc, _ = run
    tree = etree.parse(str(out / "traces.xes"))
    ns = {"x": "http://www.xes-standard.org/"}
    names = tree.xpath("//x:trace/x:string[@key='concept:name']/@value", namespaces=ns)
    assert len(names) == len(set(names)) == doc["metrics"]["doses_due"]["total"]
    assert all(n.split("/")[2].startswith("timer_workflow#") for n in names)


def test_case_per_instance_makes_one_case_per_workflow_instance(tmp_path, no_report):
    out = tmp_path / "run"
    assert main(["evaluate", str(SPEC), "--users", "2", "--days", "1", "--out", str(out),
                 "--export", "jsonl", "--case", "instance", "--workers", "1",
                 "--quiet"]) == 0
    trace = jsonl_events(out / "traces.jsonl")
    started = [e for e in trace if e["kind"] == "process.started"]
    cases = {e["case"] for e in trace}
    assert len(cases) == len(started)
    for event in trace:
        instance = event.get("instance", event.get("data", {}).get("instance"))
        assert event["case"].endswith(f"#{instance}"), event


def test_the_size_estimate_is_printed_and_close(run):
    out, _, err = run
    for name in ("traces.xes", "traces.jsonocel", "traces.jsonl"):
        line = next(x for x in err.splitlines()
                    if x.startswith(f"opspec evaluate: {name} will be about"))
        number, unit = line.split("about ")[1].split(" (")[0].split()
        estimate = float(number) * {"kB": 1e3, "MB": 1e6, "GB": 1e9}[unit]
        actual = (out / name).stat().st_size
        assert 0.5 * actual < estimate < 2 * actual, (name, estimate, actual)


def test_an_export_past_the_trace_cap_is_refused_before_anything_runs(tmp_path, capsys,
                                                                       monkeypatch):
    monkeypatch.setenv("OPSPEC_TRACE_MAX_BYTES", "200000")
    out = tmp_path / "run"
    status = main(["evaluate", str(SPEC), "--users", "50", "--days", "3", "--out", str(out),
                   "--export", "xes", "--quiet"])
    err = capsys.readouterr().err
    assert status == 2
    assert "traces.xes would be about" in err and "past the trace cap of 200 kB" in err
    assert "OPSPEC_TRACE_MAX_BYTES" in err
    assert not out.exists()


def test_case_without_a_cased_export_is_refused(tmp_path, capsys):
    status = main(["evaluate", str(SPEC), "--users", "2", "--out", str(tmp_path / "r"),
                   "--export", "ocel", "--case", "dose"])
    assert status == 2
    assert "--case dose applies to the xes and jsonl exports" in capsys.readouterr().err


def test_the_caregiver_is_an_object_of_the_missed_doses(tmp_path, dispenser_day):
    """The fixture's user takes the morning dose and hears no other alarm: the three other
    doses are missed and the caregiver notified of each, which the log relates to a
    caregiver object (the spec's HUMAN participant other than the user)."""
    from opspec.engine.compiled import compile_package
    from opspec.engine.lanes import user_lane
    from opspec.evaluation.ocel import OcelWriter, people_of
    from opspec.xpdl.loader import load_spec

    package = load_spec(SPEC)
    people = people_of(package, user_lane(compile_package(package)).bind_names)
    assert dict(people.others) == {"caregiver": "caregiver"}
    path = tmp_path / "day.jsonocel"
    with OcelWriter(path, people=people) as writer:
        writer.add_case("A/0", dispenser_day, {"user": 0})
    doc = json.loads(path.read_text(encoding="utf-8"))
    notified = [e for e in dispenser_day if e.kind == EventKind.ACTIVITY_COMPLETED
                and e.activity == "notify_caregiver"]
    assert len(notified) == 3
    concerning = [e for e in doc["events"] if e["type"] ==
                  "notify_workflow/notify_caregiver complete"]
    assert len(concerning) == 3
    for event in concerning:
        assert {"objectId": "caregiver A/0", "qualifier": "concerns"} in event["relationships"]
    [caregiver] = [o for o in doc["objects"] if o["type"] == "caregiver"]
    assert caregiver["relationships"] == [{"objectId": "user A/0", "qualifier": "cares for"}]


def test_an_interrupted_ocel_export_leaves_only_the_partial_file(tmp_path):
    from opspec.evaluation.ocel import OcelWriter

    def broken():
        yield TraceEvent(1.0, EventKind.ACTIVITY_COMPLETED, process="p", instance=1,
                         activity="a")
        raise RuntimeError("replication crashed")

    path = tmp_path / "t.jsonocel"
    with pytest.raises(RuntimeError), OcelWriter(path) as writer:
        writer.add_case("A/0", broken())
    assert not path.exists() and (tmp_path / "t.jsonocel.partial").exists()


def test_ocel_relates_a_user_workflows_events_to_the_user_whatever_its_lanes_say(
        tmp_path, no_report):
    """The pill template's user workflow has no opspec:Lane directive: its events carry no
    lane, yet they are the user's work (its activities are manual, performed by the HUMAN
    participant). OCEL 2.0 relationships qualify how an object takes part in an event; the
    user ``performed by``, not the device."""
    import contextlib
    import io

    assert main(["new", str(tmp_path / "pill"), "--template", "pill"]) == 0
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(["evaluate", str(tmp_path / "pill" / "pill.xpdl"), "--users", "2",
                     "--days", "1", "--workers", "1", "--out", str(tmp_path / "run"),
                     "--export", "ocel", "--quiet"]) == 0
    doc = json.loads((tmp_path / "run" / "traces.jsonocel").read_text(encoding="utf-8"))
    users = [e for e in doc["events"] if e["type"].startswith("user_workflow")]
    device = [e for e in doc["events"] if e["type"].startswith("reminder_workflow")]
    assert users and device
    for event in users:
        qualifiers = {r["objectId"].split(" ")[0]: r["qualifier"]
                      for r in event["relationships"]}
        assert qualifiers.get("user") == "performed by" and "device" not in qualifiers, event
    for event in device:
        qualifiers = {r["objectId"].split(" ")[0]: r["qualifier"]
                      for r in event["relationships"]}
        assert qualifiers.get("device") == "performed by" and qualifiers["user"] == "for"
