"""`opspec preprocess`: SISARL built-ins become compound built-in activities in standard XPDL 2.1
that validates against the official schema, loads back, and computes what the built-in means."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from builtin_models import BUILTINS, DATA, builtin_package, schema_errors, without_locations
from lxml import etree

from opspec.engine.conditions import evaluate, evaluate_condition
from opspec.errors import Severity
from opspec.model import (
    Activity,
    ActivitySet,
    BlockActivity,
    ConditionKind,
    CoordinationBuiltIn,
    CoordinationKind,
    NoImplementation,
    Package,
    Route,
    Task,
    TaskKind,
    WorkflowProcess,
)
from opspec.xpdl.loader import load_package, parse_bytes
from opspec.xpdl.preprocess import (
    MODE_CHANGE_APPLICATION,
    PULL_APPLICATION,
    PUSH_APPLICATION,
    preprocess,
    preprocess_to_xpdl,
)


def _process(package: Package, key: str) -> WorkflowProcess:
    found = package.process(f"p_{key.replace('-', '_')}")
    assert found is not None
    return found


def _compound(process: WorkflowProcess) -> tuple[Activity, ActivitySet]:
    activity = process.activity(f"{process.id}_coordinate")
    assert activity is not None and isinstance(activity.body, BlockActivity)
    activity_set = process.activity_set(activity.body.activity_set)
    assert activity_set is not None
    return activity, activity_set


def _run(activity_set: ActivitySet, start: str, data: dict[str, Any]) -> list[Activity]:
    """Walk the generated set the way the engine will: assignments at the end of each
    activity, XOR splits taking the first true condition in TransitionRef order (OTHERWISE
    last), single outgoing transitions followed, and stop where nothing leaves."""
    by_id = {a.id: a for a in activity_set.activities}
    outgoing: dict[str, list[Any]] = {}
    for transition in activity_set.transitions:
        outgoing.setdefault(transition.source, []).append(transition)
    path, current = [], by_id[start]
    for _ in range(100):
        path.append(current)
        for assignment in current.assignments:
            assert assignment.expression is not None
            data[assignment.target] = evaluate(assignment.expression, data)
        leaving = outgoing.get(current.id, [])
        if current.split is not None:
            order = {ref: i for i, ref in enumerate(current.split.transition_refs)}
            leaving = sorted(leaving, key=lambda t: order[t.id])
        chosen = None
        for transition in leaving:
            condition = transition.condition
            if condition.kind is ConditionKind.OTHERWISE or condition.expression is None or \
                    evaluate_condition(condition.expression, data):
                chosen = transition
                break
        if chosen is None:
            return path
        current = by_id[chosen.target]
    raise AssertionError("the generated activity set loops")


def _expanded(key: str) -> tuple[Activity, ActivitySet]:
    result = preprocess(builtin_package((key,)))
    assert result.diagnostics == ()
    return _compound(_process(result.package, key))


# --------------------------------------------------------------------------- structure


@pytest.mark.parametrize("key", list(BUILTINS))
def test_each_builtin_becomes_a_block_activity_over_routes_and_plain_activities(key: str) -> None:
    activity, activity_set = _expanded(key)
    assert activity.coordination is None
    assert activity.performers == ("robot",)             # the activity keeps its identity
    assert activity.directives.priority_increment == 1
    assert isinstance(activity.body, BlockActivity)
    assert activity.body.start_activity == activity_set.activities[0].id
    for member in activity_set.activities:
        assert member.coordination is None
        assert isinstance(member.body, (Route, NoImplementation, Task)), member
        if isinstance(member.body, Task):
            assert member.body.kind is TaskKind.APPLICATION


@pytest.mark.parametrize("key", list(BUILTINS))
def test_preprocessed_output_validates_against_the_xpdl_2_1_schema(
    key: str, xpdl_schema: etree.XMLSchema
) -> None:
    data, diagnostics = preprocess_to_xpdl(builtin_package((key,)))
    assert diagnostics == ()
    assert schema_errors(xpdl_schema, data) == []
    assert b"opspec:BuiltIn" not in data


@pytest.mark.parametrize("key", list(BUILTINS))
def test_preprocessed_output_loads_back_to_the_same_activity_sets(key: str) -> None:
    result = preprocess(builtin_package((key,)))
    loaded = parse_bytes(preprocess_to_xpdl(builtin_package((key,)))[0], path="out.xpdl")
    assert loaded.ok, [str(d) for d in loaded.diagnostics]
    assert loaded.package is not None
    expected = _process(result.package, key)
    got = _process(loaded.package, key)
    assert [s.id for s in got.activity_sets] == [s.id for s in expected.activity_sets]
    for got_set, expected_set in zip(got.activity_sets, expected.activity_sets):
        assert [a.id for a in got_set.activities] == [a.id for a in expected_set.activities]
        assert [(t.source, t.target, t.condition.kind, t.condition.expression)
                for t in got_set.transitions] == [
            (t.source, t.target, t.condition.kind, t.condition.expression)
            for t in expected_set.transitions]
        assert [a.assignments[0].expression if a.assignments else None
                for a in got_set.activities] == [
            a.assignments[0].expression if a.assignments else None
            for a in expected_set.activities]
    assert all(a.coordination is None for a in got.all_activities())


def test_generated_ids_never_clash_with_existing_ones() -> None:
    package = builtin_package(("arbiter",))
    process = package.processes[0]
    # An existing activity already uses the id the arbiter's decision route would get.
    taken = Activity(id="p_arbiter_coordinate.decide")
    package = Package(id=package.id, data_fields=package.data_fields,
                      participants=package.participants, pools=package.pools,
                      processes=(WorkflowProcess(
                          id=process.id, activities=process.activities + (taken,),
                          transitions=process.transitions),))
    result = preprocess(package)
    ids = [a.id for a in result.package.processes[0].all_activities()]
    assert len(ids) == len(set(ids))
    assert "p_arbiter_coordinate.decide.2" in ids


# --------------------------------------------------------------------------- meaning


@pytest.mark.parametrize(
    ("avoid", "wander", "expected"),
    [
        pytest.param("back", "forward", "back", id="higher-priority-wins"),
        pytest.param("", "forward", "forward", id="empty-input-is-skipped"),
        pytest.param(None, "left", "left", id="null-input-is-skipped"),
        pytest.param("", "", None, id="no-command-at-all-gives-null"),
    ],
)
def test_the_arbiter_passes_the_highest_priority_input_that_has_a_command(
    avoid: str | None, wander: str, expected: str | None
) -> None:
    _, activity_set = _expanded("arbiter")
    data = {"avoid_cmd": avoid, "wander_cmd": wander, "motor_cmd": "stale"}
    _run(activity_set, activity_set.activities[0].id, data)
    assert data["motor_cmd"] == expected


@pytest.mark.parametrize(
    ("votes", "expected"),
    [
        pytest.param(("left", "left", "stop"), "left", id="majority"),
        pytest.param(("stop", "left", "forward"), "forward", id="three-way-tie-first-option"),
        pytest.param(("stop", "left", "nonsense"), "left", id="tie-goes-to-earlier-option"),
        pytest.param(("stop", "stop", "left"), "stop", id="last-option-can-win"),
        pytest.param(("nonsense", None, ""), None, id="no-vote-for-an-option-gives-null"),
    ],
)
def test_the_voter_outputs_the_option_with_most_votes_ties_by_option_order(
    votes: tuple[str | None, ...], expected: str | None
) -> None:
    _, activity_set = _expanded("voter")
    data: dict[str, Any] = {"vote_a": votes[0], "vote_b": votes[1], "vote_c": votes[2],
                            "motor_cmd": ""}
    _run(activity_set, activity_set.activities[0].id, data)
    assert data["motor_cmd"] == expected


def test_the_voter_tallies_are_new_integer_data_fields_of_the_process() -> None:
    result = preprocess(builtin_package(("voter",)))
    process = _process(result.package, "voter")
    tallies = [f for f in process.data_fields if f.id.startswith("_vote_")]
    assert [f.initial for f in tallies] == [0, 0, 0]


def test_superposition_assigns_the_weighted_sum_in_one_activity() -> None:
    _, activity_set = _expanded("superposition")
    assert len(activity_set.activities) == 1
    data = {"v_avoid": 1.0, "v_goal": 2.0, "v": 0.0}
    _run(activity_set, activity_set.activities[0].id, data)
    assert data["v"] == pytest.approx(0.7 * 1.0 + 0.3 * 2.0)
    assert activity_set.activities[0].assignments[0].text == "0.7 * v_avoid + 0.3 * v_goal"


@pytest.mark.parametrize(
    ("key", "application", "parameters"),
    [
        pytest.param("push", PUSH_APPLICATION, ['"range"', "distance"], id="push"),
        pytest.param("pull", PULL_APPLICATION, ['"range"', "distance"], id="pull"),
        pytest.param("mode-change", MODE_CHANGE_APPLICATION, ['"dock"'], id="mode-change"),
    ],
)
def test_data_exchange_and_mode_change_call_the_opspec_application(
    key: str, application: str, parameters: list[str]
) -> None:
    result = preprocess(builtin_package((key,)))
    _, activity_set = _compound(_process(result.package, key))
    (task_activity,) = activity_set.activities
    assert isinstance(task_activity.body, Task)
    (call,) = task_activity.body.applications
    assert call.application == application
    assert [p.text for p in call.actual_parameters] == parameters
    declared = result.package.application(application)
    assert declared is not None and declared.formal_parameters


def test_opspec_applications_are_added_once_and_only_when_used() -> None:
    result = preprocess(builtin_package(("arbiter", "push", "pull")))
    ids = [a.id for a in result.package.applications]
    assert ids == [PUSH_APPLICATION, PULL_APPLICATION]


# --------------------------------------------------------------------------- bad built-ins


@pytest.mark.parametrize(
    ("builtin", "message"),
    [
        pytest.param(CoordinationBuiltIn(kind=CoordinationKind.VOTER, inputs=("a",),
                                         output="o"), "has no Options", id="voter-no-options"),
        pytest.param(CoordinationBuiltIn(kind=CoordinationKind.ARBITER, inputs=("a",)),
                     "has no output", id="arbiter-no-output"),
        pytest.param(CoordinationBuiltIn(kind=CoordinationKind.PUSH_DATA, inputs=("a",)),
                     "needs a Channel", id="push-no-channel"),
        pytest.param(CoordinationBuiltIn(kind=CoordinationKind.MODE_CHANGE),
                     "names no mode", id="mode-change-no-mode"),
    ],
)
def test_an_unusable_builtin_is_an_error_and_the_activity_is_left_alone(
    builtin: CoordinationBuiltIn, message: str
) -> None:
    package = builtin_package(("arbiter",))
    process = package.processes[0]
    broken = Activity(id="broken", coordination=builtin)
    package = Package(id="p", processes=(WorkflowProcess(
        id=process.id, activities=process.activities + (broken,)),))
    result = preprocess(package)
    (diagnostic,) = result.diagnostics
    assert diagnostic.severity is Severity.ERROR and diagnostic.code == "bad-builtin"
    assert message in diagnostic.message and "'broken'" in diagnostic.message
    assert result.package.processes[0].activity("broken") == broken


# --------------------------------------------------------------------------- from a file


def test_a_sisarl_file_with_every_builtin_preprocesses_to_valid_standard_xpdl(
    tmp_path: Path, xpdl_schema: etree.XMLSchema
) -> None:
    out = tmp_path / "robot.std.xpdl"
    completed = subprocess.run(
        [sys.executable, "-m", "opspec", "preprocess", str(DATA / "robot.xpdl"), "-o", str(out)],
        capture_output=True, text=True, check=False)
    assert completed.returncode == 0, completed.stderr
    assert schema_errors(xpdl_schema, out.read_bytes()) == []
    loaded = load_package(out)
    assert loaded.ok, [str(d) for d in loaded.diagnostics]
    assert loaded.package is not None
    behave = loaded.package.process("behave")
    assert behave is not None
    assert [s.id for s in behave.activity_sets] == [
        "pull_range.pull", "arbitrate.arbiter", "vote.voter", "blend.superposition",
        "push_range.push", "to_dock.mode-change"]
    assert all(a.coordination is None for a in behave.all_activities())
    # Directives survive as opspec: extended attributes, whichever form the input used.
    arbitrate = behave.activity("arbitrate")
    to_dock = behave.activity("to_dock")
    assert arbitrate is not None and arbitrate.directives.priority_increment == 1
    assert to_dock is not None and to_dock.directives.auto_run is True
    assert behave.directives.period == pytest.approx(0.1)
    assert [m.id for m in loaded.package.modes] == ["search", "dock"]


def test_preprocess_of_a_spec_with_errors_writes_nothing_and_exits_1(tmp_path: Path) -> None:
    bad = tmp_path / "bad.xpdl"
    bad.write_text((DATA / "robot.xpdl").read_text().replace('Value="PT0.1S"', 'Value="soon"'))
    out = tmp_path / "out.xpdl"
    completed = subprocess.run(
        [sys.executable, "-m", "opspec", "preprocess", str(bad), "-o", str(out)],
        capture_output=True, text=True, check=False)
    assert completed.returncode == 1
    assert "bad.xpdl:" in completed.stderr and "error" in completed.stderr
    assert not out.exists()


@pytest.mark.parametrize("which", ["missing-input", "unwritable-output"])
def test_preprocess_io_problems_are_one_line_and_exit_2(tmp_path: Path, which: str) -> None:
    source = DATA / "robot.xpdl" if which == "unwritable-output" else tmp_path / "none.xpdl"
    out = tmp_path / "no-such-dir" / "out.xpdl"
    completed = subprocess.run(
        [sys.executable, "-m", "opspec", "preprocess", str(source), "-o", str(out)],
        capture_output=True, text=True, check=False)
    assert completed.returncode == 2
    assert len(completed.stderr.strip().splitlines()) == 1
    assert "Traceback" not in completed.stderr


def test_the_documented_example_preprocesses_to_valid_xpdl_that_loads_cleanly(
    tmp_path: Path, xpdl_schema: etree.XMLSchema
) -> None:
    import re

    docs = Path(__file__).resolve().parents[2] / "docs" / "sisarl-xpdl.md"
    (example,) = [b for b in re.findall(r"```xml\n(.*?)```", docs.read_text(), re.DOTALL)
                  if "<Package" in b]
    source = tmp_path / "example.xpdl"
    source.write_text(example)
    loaded = load_package(source)
    assert loaded.ok and loaded.package is not None
    data, diagnostics = preprocess_to_xpdl(loaded.package)
    assert diagnostics == ()
    assert schema_errors(xpdl_schema, data) == []
    again = parse_bytes(data, path="example.std.xpdl")
    # No warnings either: a kept opspec:Rate is not doubled by a generated opspec:Period.
    assert again.diagnostics == (), [str(d) for d in again.diagnostics]
    assert again.package is not None
    assert [without_locations(p.directives) for p in again.package.processes] == [
        without_locations(p.directives) for p in loaded.package.processes]


def test_preprocess_refuses_a_spec_that_validate_rejects(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from opspec.cli import main

    spec = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"
    text = spec.read_text()
    assert 'From="start_notify" To="timer_done"' in text
    bad = tmp_path / "dangling.xpdl"   # reads fine; only the structural checks object
    bad.write_text(text.replace('From="start_notify" To="timer_done"',
                                'From="start_notify" To="nowhere"'))
    assert main(["validate", str(bad)]) == 1
    capsys.readouterr()
    out = tmp_path / "out.xpdl"
    assert main(["preprocess", str(bad), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    line = next(n for n, text_line in enumerate(text.splitlines(), 1)
                if 'From="start_notify" To="timer_done"' in text_line)
    assert f"{bad}:{line}: error: " in err and "'nowhere'" in err
    assert "nothing written" in err
    assert not out.exists()


@pytest.mark.parametrize(
    "path", sorted((Path(__file__).resolve().parents[2] / "specs").glob("*.xpdl")),
    ids=lambda p: p.name)
def test_every_bundled_spec_preprocesses(tmp_path: Path, path: Path) -> None:
    from opspec.cli import main

    assert main(["preprocess", str(path), "-o", str(tmp_path / "out.xpdl")]) == 0


def test_preprocess_warns_when_its_output_will_not_pass_the_2_1_schema(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from opspec.cli import main

    source = Path("/work/shared/corpus/xpdl/jawe10__workflow_patterns.xpdl")
    if not source.is_file():
        pytest.skip("corpus not available")
    out = tmp_path / "patterns.xpdl"
    assert main(["preprocess", str(source), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    (warning,) = [line for line in err.splitlines() if "will not be valid XPDL 2.1" in line]
    assert warning.startswith(f"{source}:") and ": warning: " in warning
    assert "activity ids 'A', 'B', 'C' and 13 more" in warning
    assert out.exists()
    assert main(["preprocess", str(source), "-o", str(tmp_path / "strict.xpdl"),
                 "--strict"]) == 1
    assert not (tmp_path / "strict.xpdl").exists()


def test_schema_warnings_name_external_subflows_and_shared_process_ids() -> None:
    from opspec.model.activities import SubFlow
    from opspec.xpdl.schema_limits import schema_warnings

    calls = Activity(id="call", body=SubFlow(process="elsewhere"))
    inner = ActivitySet(id="main", activities=(Activity(id="x"),))
    package = Package(id="pkg", processes=(
        WorkflowProcess(id="main", activities=(calls,), activity_sets=(inner,)),))
    messages = [d.message for d in schema_warnings(package)]
    assert len(messages) == 2
    assert "'main'" in messages[0] and "one id space" in messages[0]
    assert "SubFlow calls 'elsewhere'" in messages[1]


@pytest.mark.parametrize(
    "path", sorted((Path(__file__).resolve().parents[2] / "specs").glob("*.xpdl")),
    ids=lambda p: p.name)
def test_bundled_specs_preprocess_without_schema_warnings(
    tmp_path: Path, path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from opspec.cli import main

    assert main(["preprocess", str(path), "-o", str(tmp_path / "out.xpdl"), "--strict"]) == 0
    assert "not be valid" not in capsys.readouterr().err
