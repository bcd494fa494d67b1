"""`opspec check` reports a reachable zero-time cycle (a warning: a counted loop may leave it)
with its witness, the start to the cycle and once round it; only cycles certainly taking no
time are reported (see opspec.engine.zero_time_check)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.engine.compiled import compile_package
from opspec.engine.zero_time_check import zero_time_cycles
from opspec.xpdl.loader import load_spec

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "tests" / "engine" / "hang_specs"


def found(name: str) -> list:
    return zero_time_cycles(compile_package(load_spec(SPECS / f"{name}.xpdl")))


def test_a_cycle_of_instantaneous_activities_with_its_witness() -> None:
    [problem] = found("cycle")
    assert problem.kind == "zero-time-cycle" and problem.severity == "warning"
    assert problem.process == "spin" and problem.activity == "B"
    assert problem.witness == ("A", "B", "C", "B")
    assert "zero-time cycle B -> C -> B" in problem.message
    assert problem.line is not None


def test_a_loop_with_an_instantaneous_body() -> None:
    [problem] = found("loop")
    assert problem.witness == ("spin", "spin")
    assert "'spin' loops with a body that takes no time" in problem.message


def test_a_workflow_that_starts_itself_asynchronously() -> None:
    [problem] = found("self_start")
    assert problem.process == "again"
    assert problem.witness == ("again:restart", "again:restart")
    assert "again -> again" in problem.message


# a start that decides whether to start the workflow again (x never changes, but the check
# abstracts from data: the condition may let it out)
CONDITIONAL = (
    '<DataFields><DataField Id="x"><DataType><BasicType Type="INTEGER"/></DataType>'
    "<InitialValue>0</InitialValue></DataField></DataFields><Activities>"
    '<Activity Id="decide"><Route/><TransitionRestrictions><TransitionRestriction>'
    '<Split Type="Exclusive"/></TransitionRestriction></TransitionRestrictions></Activity>'
    '<Activity Id="stop"><Route/></Activity>',
    '</Activities><Transitions><Transition Id="d_r" From="decide" To="restart"><Condition '
    'Type="CONDITION"><Expression>x == 0</Expression></Condition></Transition><Transition '
    'Id="d_s" From="decide" To="stop"><Condition Type="OTHERWISE"/></Transition>'
    "</Transitions>")


def _conditional_self_start(tmp_path: Path) -> Path:
    text = (SPECS / "self_start.xpdl").read_text(encoding="utf-8")
    head, tail = text.split('<WorkflowProcess Id="again">')
    tail = tail.replace("<Activities>", CONDITIONAL[0], 1).replace(
        "</Activities>", CONDITIONAL[1], 1)
    path = tmp_path / "maybe_again.xpdl"
    path.write_text(head + '<WorkflowProcess Id="again">' + tail, encoding="utf-8")
    return path


def test_an_unconditional_self_start_is_not_sound(
        capsys: pytest.CaptureFixture[str]) -> None:
    """Soundness asks for the option to complete: "For any case, the procedure will
    terminate eventually and the moment the procedure terminates there is a token in place o
    and all the other places are empty" (van der Aalst, The Application of Petri Nets to
    Workflow Management, 1998, Def. 6). A workflow that starts itself with no condition and
    no delay leaves a new instance behind at every step, all at one instant: it never
    terminates, so check calls it not sound and exits 1, naming why."""
    [problem] = found("self_start")
    assert problem.severity == "error"
    spec = SPECS / "self_start.xpdl"
    assert main(["check", str(spec)]) == 1
    out = capsys.readouterr().out.splitlines()
    [error] = [line for line in out if ": error: again: workflows start each other" in line]
    assert error.startswith(f"{spec}:") and "can never complete" in error
    assert f"{spec}: again: 1 problem(s) (" in "\n".join(out)
    assert main(["check", "--json", str(spec)]) == 1
    doc = json.loads(capsys.readouterr().out)
    assert doc["sound"] is False and doc["problems"][0]["kind"] == "zero-time-cycle"


def test_a_self_start_behind_a_condition_stays_a_warning(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Whether a condition ever lets the token out depends on data the check abstracts
    from: a warning, and the process still sound."""
    spec = _conditional_self_start(tmp_path)
    [problem] = zero_time_cycles(compile_package(load_spec(spec)))
    assert problem.severity == "warning" and problem.witness[0] == "again:decide"
    assert main(["check", str(spec)]) == 0
    assert "2 of 2 process level(s) sound, 0 problem(s), 1 warning(s)" in \
        capsys.readouterr().out


def test_a_cycle_through_a_timer_or_a_duration_is_not_reported(tmp_path: Path) -> None:
    assert found("zero_timer") == []       # a timer waits (even PT0S): not certainly zero-time
    text = (SPECS / "cycle.xpdl").read_text().replace(
        '<Activity Id="C"><Implementation><No/></Implementation>',
        '<Activity Id="C"><Implementation><No/></Implementation><ExtendedAttributes>'
        '<ExtendedAttribute Name="opspec:Duration" Value="ConstantParameter(60)"/>'
        "</ExtendedAttributes>")
    slow = tmp_path / "slow.xpdl"
    slow.write_text(text)
    assert zero_time_cycles(compile_package(load_spec(slow))) == []


def test_the_bundled_specs_have_none() -> None:
    for spec in sorted((ROOT / "specs").glob("*.xpdl")):
        assert zero_time_cycles(compile_package(load_spec(spec))) == [], spec


def test_opspec_check_prints_the_warning_and_witness_and_stays_0(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(SPECS / "cycle.xpdl")]) == 0
    out = capsys.readouterr().out.splitlines()
    [warning] = [line for line in out if ": warning: spin: zero-time cycle" in line]
    assert warning.startswith(f"{SPECS / 'cycle.xpdl'}:")
    assert out[out.index(warning) + 1] == "    witness: A -> B -> C -> B"
    assert out[-1].endswith("1 of 1 process level(s) sound, 0 problem(s), 1 warning(s)")


def test_opspec_check_json_gives_the_warning(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(_conditional_self_start(tmp_path)), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["sound"] is True
    assert doc["problems"] == []
    [problem] = doc["warnings"]
    assert problem["kind"] == "zero-time-cycle" and problem["severity"] == "warning"
    assert problem["witness"] == ["again:decide", "again:restart", "again:decide"]


def test_opspec_check_of_one_process_reports_only_its_cycles(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", str(SPECS / "self_start.xpdl"), "--process", "boot"]) == 0
    assert "zero-time" not in capsys.readouterr().out
