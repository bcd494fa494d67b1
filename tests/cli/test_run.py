"""`opspec run`: one simulation, a readable timeline, JSON metrics, traces that are never lost."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.engine.trace_sinks import read_trace

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
FIRST_DOSE = ["--until", str(9 * 3600)]       # 08:00 dose plus its alarms and deadline


def run_json(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, dict]:
    status = main(["run", str(SPEC), "--json", *args])
    out = capsys.readouterr().out
    return status, json.loads(out)


def script(tmp_path: Path, *steps: tuple[str, str]) -> str:
    path = tmp_path / "user.toml"
    body = ",\n".join(f'  ["{when}", "{action}"]' for when, action in steps)
    path.write_text(f'otherwise = "complete"\nsteps = [\n{body}\n]\n', encoding="utf-8")
    return str(path)


def test_user_reporting_90s_after_the_alarm_takes_the_dose(tmp_path, capsys):
    status, doc = run_json(capsys, *FIRST_DOSE,
                           "--script", script(tmp_path, ("after trg_2 90s", "press_report")))
    assert status == 0
    metrics = doc["metrics"]
    assert metrics["doses_taken"] == {"kind": "count", "total": 1}
    assert metrics["doses_missed"]["total"] == 0
    latency = metrics["report_latency_s"]
    assert latency["n"] == 1
    assert latency["mean"] == pytest.approx(90.0)
    assert latency["median"] == pytest.approx(90.0)
    assert latency["p95"] == pytest.approx(90.0)


def test_user_who_never_reports_gets_three_alarms_a_miss_and_the_caregiver(tmp_path, capsys):
    status, doc = run_json(capsys, *FIRST_DOSE, "--script", script(
        tmp_path, ("never", "press_report")))
    assert status == 0
    metrics = doc["metrics"]
    assert metrics["alarms"]["total"] == 3
    assert metrics["doses_missed"]["total"] == 1
    assert metrics["caregiver_notified"]["total"] == 1
    assert metrics["doses_taken"]["total"] == 0


def test_json_has_the_run_parameters_and_instance_counts(capsys):
    status, doc = run_json(capsys, "--days", "2", "--seed", "7")
    assert status == 0
    assert doc["seed"] == 7 and doc["days"] == 2 and doc["until"] == 2 * 86400
    assert doc["metrics"]["doses_due"]["total"] == 8
    assert doc["instances"]["started"] == doc["instances"]["completed"]
    assert doc["deadlocks"] == [] and doc["faults"] == []


def test_a_spec_with_a_run_length_runs_that_long_unless_told_otherwise(capsys):
    cart = str(ROOT / "specs" / "medication_cart_guidance.xpdl")   # opspec:RunLength PT10M
    assert main(["run", cart, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["until"] == 600.0 and doc["metrics"]["patients_found"]["total"] == 1
    assert main(["run", cart, "--until", "30", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["until"] == 30.0
    assert main(["run", cart, "--timeline", "none"]) == 0
    assert "for 10 min simulated" in capsys.readouterr().out


def test_same_seed_same_run_and_another_seed_differs(capsys):
    _, first = run_json(capsys, "--days", "3", "--seed", "11")
    _, again = run_json(capsys, "--days", "3", "--seed", "11")
    _, other = run_json(capsys, "--days", "3", "--seed", "12")
    assert first["metrics"] == again["metrics"]
    assert first["metrics"] != other["metrics"]


def test_timeline_shows_the_story_of_a_dose(tmp_path, capsys):
    status = main(["run", str(SPEC), *FIRST_DOSE, "--script",
                   script(tmp_path, ("after trg_2 90s", "press_report"))])
    out = capsys.readouterr().out
    assert status == 0
    assert "user lane: the script" in out
    lines = out.splitlines()
    alarm = next(i for i, line in enumerate(lines) if "sound_alarm completed" in line)
    report = next(i for i, line in enumerate(lines) if "press_report completed" in line)
    dispense = next(i for i, line in enumerate(lines) if "dispense completed" in line)
    assert alarm < report < dispense
    assert lines[alarm].strip().startswith("d1 08:00:00")
    assert lines[report].strip().startswith("d1 08:01:30")
    assert "doses_taken" in out and "report_latency_s" in out
    # routes and start/end events are left out of the brief timeline
    assert "merge completed" not in out


def test_trace_file_holds_every_event_and_reads_back(tmp_path, capsys):
    trace = tmp_path / "out" / "run.jsonl"
    status, doc = run_json(capsys, "--days", "1", "--trace", str(trace))
    assert status == 0 and doc["trace"] == str(trace)
    events = list(read_trace(trace))
    assert len(events) == doc["events"]
    assert events[0].kind == "run.started" and events[-1].kind == "run.ended"


def test_companion_user_model_is_used_unless_told_otherwise(capsys):
    main(["run", str(SPEC), "--days", "1"])
    assert "medication_dispenser.users.toml" in capsys.readouterr().out
    status = main(["run", str(SPEC), "--days", "1", "--no-user"])
    out = capsys.readouterr().out
    assert "user-lane activities wait" in out
    # nobody performs the lane by choice: its instances waiting at the end are said in one
    # line, not reported as deadlocks, and are not a failure (issue 20)
    assert status == 0
    assert "deadlock:" not in out
    assert "left waiting for the user at hear_alarm" in out


def test_pooled_processor_model_reports_its_pool(capsys):
    status, doc = run_json(capsys, "--days", "1", "--processor-model", "pooled",
                           "--workers", "2")
    assert status == 0
    assert doc["pool"]["workers"] == 2


def test_realtime_at_high_speed_reports_drift(tmp_path, capsys):
    status, doc = run_json(capsys, "--until", "30000", "--realtime", "--speed", "100000",
                           "--script", script(tmp_path, ("after trg_2 30s", "press_report")))
    assert status == 0
    assert doc["drift"]["events"] > 0
    assert doc["metrics"]["doses_taken"]["total"] == 1


@pytest.mark.parametrize("args, message", [
    (["--speed", "10"], "--speed only applies with --realtime"),
    (["--days", "-1"], "--days must be a positive number"),
    (["--until", "soon"], "--until: cannot read duration 'soon': not a duration"),
    (["--user-model", "no-such-preset"], "no-such-preset"),
    (["--engine-config", "/nonexistent/engine.toml"], "engine.toml"),
], ids=["speed-without-realtime", "negative-days", "bad-until", "unknown-preset",
        "missing-engine-config"])
def test_bad_options_are_one_line_errors_with_status_2(args, message, capsys):
    status = main(["run", str(SPEC), *args])
    err = capsys.readouterr().err
    assert status == 2
    assert message in err
    assert "Traceback" not in err


def test_script_naming_an_unknown_activity_lists_the_real_ones(tmp_path, capsys):
    status = main(["run", str(SPEC), "--script", script(tmp_path, ("10s", "press_red"))])
    err = capsys.readouterr().err
    assert status == 2
    assert "press_red" in err and "press_report" in err


def test_broken_spec_names_file_and_line(tmp_path, capsys):
    broken = tmp_path / "broken.xpdl"
    broken.write_text(SPEC.read_text(encoding="utf-8").replace("</Package>", ""),
                      encoding="utf-8")
    status = main(["run", str(broken)])
    err = capsys.readouterr().err
    assert status == 1
    assert f"{broken}:" in err


def test_spec_given_as_a_folder_is_a_usage_error(capsys):
    assert main(["run", str(ROOT / "specs")]) == 2
    assert "give one specification file" in capsys.readouterr().err


def test_a_deadlock_validation_finds_is_refused_before_the_run_with_status_1(capsys):
    deadlock = ROOT / "tests" / "validate" / "data" / "and_join_deadlock.xpdl"
    status = main(["run", str(deadlock)])
    captured = capsys.readouterr()
    assert status == 1
    assert captured.out == ""                      # nothing ran
    assert "and_join_deadlock.xpdl:21:" in captured.err and "deadlock" in captured.err


def test_compiled_script_runs_like_the_xpdl(tmp_path, capsys):
    wfs = tmp_path / "dispenser.wfs"
    assert main(["compile", str(SPEC), "-o", str(wfs)]) == 0
    capsys.readouterr()
    main(["run", str(wfs), "--json", "--days", "1", "--no-user"])
    from_wfs = json.loads(capsys.readouterr().out)
    main(["run", str(SPEC), "--json", "--days", "1", "--no-user"])
    from_xpdl = json.loads(capsys.readouterr().out)
    assert from_wfs["metrics"] == from_xpdl["metrics"]
    assert from_wfs["metrics"]["doses_missed"]["total"] == 4


MAIN_WITH_MODES = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" xmlns:opspec="urn:opspec:sisarl:1"
         Id="main" Name="main">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2026</Created>
  </PackageHeader>
  <WorkflowProcesses>
    <WorkflowProcess Id="switch" Name="switch">
      <ProcessHeader/>
      <Activities>
        <Activity Id="s_start"><Event><StartEvent/></Event></Activity>
        <Activity Id="s_work"><Implementation><No/></Implementation>
          <ExtendedAttributes><ExtendedAttribute Name="opspec:Duration"
            Value="ConstantParameter(5)"/></ExtendedAttributes></Activity>
        <Activity Id="s_go"><Implementation><No/></Implementation>
          <ExtendedAttributes><ExtendedAttribute Name="opspec:BuiltIn">
            <opspec:ModeChange To="later"/></ExtendedAttribute></ExtendedAttributes></Activity>
        <Activity Id="s_end"><Event><EndEvent/></Event></Activity>
      </Activities>
      <Transitions>
        <Transition Id="a" From="s_start" To="s_work"/><Transition Id="b" From="s_work" To="s_go"/>
        <Transition Id="c" From="s_go" To="s_end"/>
      </Transitions>
      <ExtendedAttributes><ExtendedAttribute Name="opspec:AutoStart" Value="true"/>
      </ExtendedAttributes>
    </WorkflowProcess>
  </WorkflowProcesses>
  <ExtendedAttributes>
    <ExtendedAttribute Name="opspec:Modes"><opspec:Mode Id="first" Initial="true"
      Workflows="switch"/><opspec:Mode Id="later" Source="later.xpdl"/></ExtendedAttribute>
  </ExtendedAttributes>
</Package>
"""

LATER = """<?xml version="1.0" encoding="UTF-8"?>
<Package xmlns="http://www.wfmc.org/2008/XPDL2.1" Id="later" Name="later">
  <PackageHeader><XPDLVersion>2.1</XPDLVersion><Vendor>t</Vendor><Created>2026</Created>
  </PackageHeader>
  <WorkflowProcesses>
    <WorkflowProcess Id="hello" Name="hello">
      <ProcessHeader/>
      <Activities>
        <Activity Id="h_start"><Event><StartEvent/></Event></Activity>
        <Activity Id="h_end"><Event><EndEvent/></Event></Activity>
      </Activities>
      <Transitions><Transition Id="h" From="h_start" To="h_end"/></Transitions>
      <ExtendedAttributes><ExtendedAttribute Name="opspec:AutoStart" Value="true"/>
      </ExtendedAttributes>
    </WorkflowProcess>
  </WorkflowProcesses>
</Package>
"""


def test_a_mode_loads_its_workflows_from_another_spec_at_run_time(tmp_path, capsys):
    main_spec = tmp_path / "main.xpdl"
    main_spec.write_text(MAIN_WITH_MODES, encoding="utf-8")
    (tmp_path / "later.xpdl").write_text(LATER, encoding="utf-8")
    trace = tmp_path / "t.jsonl"
    assert main(["run", str(main_spec), "--until", "20", "--trace", str(trace),
                 "--timeline", "none"]) == 0
    capsys.readouterr()
    events = list(read_trace(trace))
    changed = [e for e in events if e.kind == "mode.changed"]
    hello = [e for e in events if e.kind == "process.started" and e.process == "hello"]
    assert [e.time for e in changed] == [5.0] and [e.time for e in hello] == [5.0]


def test_the_simulation_event_count_does_not_depend_on_what_is_shown(capsys):
    vacuum = ROOT / "specs" / "vacuum_cleaner.xpdl"
    counts = []
    for options in (["--timeline", "none"], ["--timeline", "all"], ["--timing"]):
        assert main(["run", str(vacuum), "--until", "20", *options]) == 0
        last = capsys.readouterr().out.strip().splitlines()[-1]
        counts.append(last.split(": ", 1)[1].split(" simulation events")[0])
    assert len(set(counts)) == 1 and int(counts[0]) > 0


def test_a_percentile_bound_too_few_instances_cannot_give_is_explained(capsys) -> None:
    # 30 instances of the battery watch in 300 s: no distribution-free upper bound for p90
    vacuum = ROOT / "specs" / "vacuum_cleaner.xpdl"
    assert main(["run", str(vacuum), "--until", "300", "--timing", "--timeline", "none"]) == 0
    out = capsys.readouterr().out
    battery = out.split("\n  battery", 1)[1].splitlines()[1]
    assert "p90 1.00 [1.00, ?]" in battery
    assert "? where too few instances give no such bound" in out
