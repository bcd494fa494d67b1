"""Load warnings reach every command that runs a spec (issue 20): a misspelt directive changes
what runs without an error, so `run` and `evaluate` print what `validate` prints, with the
name that was probably meant; and a devices-only run (`--no-user`) is not a deadlock."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
TRIGGER = '<ExtendedAttribute Name="opspec:StartTrigger" Value="timer:08:00'


def copy_with(tmp_path: Path, old: str, new: str) -> tuple[Path, int]:
    """A copy of the dispenser (and its user model) with ``old`` replaced once by ``new``;
    returns it and the line of the change."""
    text = SPEC.read_text(encoding="utf-8")
    assert text.count(old) == 1
    line = text[:text.index(old)].count("\n") + 1
    spec = tmp_path / "typo.xpdl"
    spec.write_text(text.replace(old, new), encoding="utf-8")
    shutil.copy(SPEC.with_suffix(".users.toml"), tmp_path / "typo.users.toml")
    return spec, line


def misspelt_trigger(tmp_path: Path) -> tuple[Path, int]:
    return copy_with(tmp_path, TRIGGER, TRIGGER.replace("StartTrigger", "StartTriger"))


@pytest.mark.parametrize("command", [
    ["validate"],
    ["run", "--timeline", "none"],
    ["run", "--json"],
    ["evaluate", "--users", "2", "--days", "1", "--quiet"],
])
def test_a_misspelt_directive_is_shown_with_the_name_meant(tmp_path, capsys, command):
    spec, line = misspelt_trigger(tmp_path)
    extra = ["--out", str(tmp_path / "run")] if command[0] == "evaluate" else []
    status = main([command[0], str(spec), *command[1:], *extra])
    captured = capsys.readouterr()
    shown = captured.out + captured.err if command[0] == "validate" else captured.err
    assert status == 0
    assert f"{spec}:{line}: warning: unknown directive opspec:StartTriger" in shown
    assert "did you mean opspec:StartTrigger?" in shown
    if command == ["run", "--json"]:
        json.loads(captured.out)                  # stdout stays one JSON document


def test_the_misspelling_changes_what_runs(tmp_path, capsys):
    """Why it must be seen: without its start trigger the timer never fires, so the
    dispenser announces no dose at 08:00, 12:00, 18:00 and 22:00."""
    spec, _ = misspelt_trigger(tmp_path)
    main(["run", str(SPEC), "--json", "--days", "1"])
    right = json.loads(capsys.readouterr().out)["metrics"]["doses_due"]["total"]
    main(["run", str(spec), "--json", "--days", "1"])
    wrong = json.loads(capsys.readouterr().out)["metrics"]["doses_due"]["total"]
    assert right == 4 and wrong < right


def test_the_attribute_form_gets_the_same_hint(tmp_path, capsys):
    old = '<WorkflowProcess Id="timer_workflow"'
    spec, line = copy_with(tmp_path, old, old + ' opspec:Priorty="2"')
    assert main(["run", str(spec), "--timeline", "none"]) == 0
    err = capsys.readouterr().err
    assert f"{spec}:{line}: warning: unknown directive opspec:Priorty" in err
    assert "did you mean opspec:Priority?" in err


def test_a_misspelt_prefix_is_not_silently_ignored(tmp_path, capsys):
    spec, line = copy_with(tmp_path, TRIGGER, TRIGGER.replace("opspec:", "opspc:"))
    assert main(["validate", str(spec)]) == 0
    out = capsys.readouterr().out
    assert f"{spec}:{line}: warning: ExtendedAttribute 'opspc:StartTrigger'" in out
    assert "did you mean opspec:StartTrigger?" in out


def test_a_directive_on_the_wrong_element_says_where_it_belongs(tmp_path, capsys):
    lane = '<ExtendedAttribute Name="opspec:Lane" Value="device"/>'
    text = SPEC.read_text(encoding="utf-8")
    spec = tmp_path / "wrong.xpdl"
    spec.write_text(text.replace(TRIGGER, '<ExtendedAttribute Name="opspec:AutoRun" '
                                 'Value="false"/>' + TRIGGER, 1), encoding="utf-8")
    assert lane in text
    main(["validate", str(spec)])
    out = capsys.readouterr().out
    assert ("opspec:AutoRun is a directive of an Activity, not of a WorkflowProcess"
            in out), out


def test_other_tools_extended_attributes_are_left_alone(tmp_path, capsys):
    spec, _ = copy_with(tmp_path, TRIGGER, '<ExtendedAttribute Name="JaWE_GRAPH_OFFSET" '
                        'Value="60,60"/>' + TRIGGER)
    assert main(["validate", str(spec)]) == 0
    assert "0 warnings" in capsys.readouterr().out


def test_no_user_is_the_expected_end_not_a_deadlock(capsys):
    status = main(["run", str(SPEC), "--days", "1", "--no-user", "--timeline", "none"])
    out = capsys.readouterr().out
    assert status == 0
    assert "deadlock:" not in out
    [line] = [x for x in out.splitlines() if "nobody performed the user lane" in x]
    # the dispenser alarms for 4 doses x 3 alarms; each alarm starts a user_workflow
    assert "(--no-user): 12 instance(s) of user_workflow were left waiting" in line
    status = main(["run", str(SPEC), "--days", "1", "--no-user", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert status == 0 and doc["deadlocks"] == []
    assert doc["waiting_for_user"]["instances"] == 12
    assert doc["metrics"]["doses_missed"]["total"] == 4      # nobody took a dose
