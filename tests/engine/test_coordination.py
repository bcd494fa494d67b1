"""Behaviour-coordination built-ins: arbiter, voter, superposition, push/pull, mode change."""

from __future__ import annotations

import pytest
from builders import act, catch, coordination, field, pkg, proc
from engine_runs import completed, events, run

from opspec.engine.config import EngineConfig
from opspec.engine.coordination import arbiter, superposition, voter
from opspec.model import WorkflowMode


def _changes(result: object, name: str) -> list[object]:
    return [e.data[name] for e in events(result, "data.changed") if name in e.data]  # type: ignore[arg-type]


@pytest.mark.parametrize(("commands", "expected"), [
    ((None, "turn", "forward"), "turn"), (("stop", "turn"), "stop"), ((None, ""), None)],
    ids=["first-set-wins", "highest-priority", "none-set"])
def test_arbiter_picks_the_highest_priority_command_that_is_set(commands: tuple[object, ...],
                                                                expected: object) -> None:
    assert arbiter(commands) == expected


def test_voter_takes_the_majority_and_breaks_ties_by_option_order() -> None:
    assert voter(["left", "right", "left"]) == "left"
    assert voter(["left", "right"], options=["right", "left"]) == "right"
    assert voter([None, None]) is None


def test_superposition_weights_numbers_and_vectors() -> None:
    assert superposition([1.0, 3.0], [0.5, 0.5]) == 2.0
    assert superposition([[1, 0], [0, 1]], [2.0, 1.0]) == [2.0, 1.0]
    with pytest.raises(ValueError, match="weights"):
        superposition([1.0, 2.0], [1.0])


def test_arbiter_activity_writes_its_output(config: EngineConfig) -> None:
    model = pkg(proc("p", [act("arb", coordination=coordination(
        "arbiter", inputs=("avoid", "wander"), output="cmd"))],
        data=[field("avoid", None, None), field("wander", "forward"), field("cmd", "")]))
    assert _changes(run(model, config=config), "cmd") == ["forward"]


def test_pull_waits_for_push_through_the_supervisor_mailbox(config: EngineConfig) -> None:
    model = pkg(proc("consumer", [act("pull", coordination=coordination(
                         "pull", channel="range", output="got")), "use"], [("pull", "use")],
                     data=[field("got", 0)]),
                proc("producer", [catch("d", "timer", seconds=4.0), act("push", coordination=
                                  coordination("push", channel="range", inputs=("r",)))],
                     [("d", "push")], data=[field("r", 42)]))
    result = run(model, config=config)
    assert _changes(result, "got") == [42]
    assert events(result, "activity.completed", activity="pull")[0].time >= 4.0


def test_pushed_data_is_held_until_the_receiver_pulls(config: EngineConfig) -> None:
    model = pkg(proc("producer", [act("push", coordination=coordination(
                         "push", channel="c", inputs=("r",)))], data=[field("r", 7)]),
                proc("consumer", [catch("d", "timer", seconds=9.0), act("pull", coordination=
                                  coordination("pull", channel="c", output="got"))],
                     [("d", "pull")], data=[field("got", 0)]))
    assert _changes(run(model, config=config), "got") == [7]


def test_mode_change_switches_the_active_workflows_at_run_time() -> None:
    model = pkg(proc("cleaning", [catch("work", "timer", seconds=100.0)], mode="clean",
                     auto_start=True),
                proc("docking", ["go_home"], mode="dock", auto_start=True),
                proc("battery", [catch("d", "timer", seconds=5.0), act("switch", coordination=
                                 coordination("mode-change", target_mode="dock"))],
                     [("d", "switch")]),
                modes=[WorkflowMode(id="clean", initial=True), WorkflowMode(id="dock")])
    result = run(model)
    assert events(result, "process.terminated", process="cleaning")[0].time == 5.0
    assert completed(result, "docking") == ["go_home"]
    assert events(result, "mode.changed")[0].data == {"from": "clean", "to": "dock"}
    assert result.summary["mode"] == "dock"
