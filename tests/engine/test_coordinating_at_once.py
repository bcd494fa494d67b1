"""Coordination built-ins that finish at once (``coordinating.at_once``) run without an
activity instance; the others (a pull waiting for its push, a mode change, ...) still make one.
What the trace, data and metrics say is the same either way (``tests/engine/test_coordination``
and the bundled specs' outcomes); what differs is whether an instance of the activity is
running in its workflow instance when its start is traced, which a listener can see."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from builders import act, coordination, field, pkg, proc

from engine_runs import completed, events, run
from opspec.engine.config import EngineConfig
from opspec.engine.coordinating import first_set
from opspec.engine.coordination import arbiter
from opspec.engine.trace import TraceEvent
from opspec.request import RunRequest, prepare

SPECS = Path(__file__).resolve().parents[2] / "specs"
COORDINATING = ("arbiter", "push_range", "pull_range")


def _instances_at_start() -> dict[str, list[bool]]:
    """For each start of the vacuum cleaner's arbiter, push and pull (120 s, seed 3): whether
    an activity instance of it was running when the start was traced."""
    seen: dict[str, list[bool]] = {name: [] for name in COORDINATING}
    holder: dict[str, Any] = {}

    def listener(event: TraceEvent) -> None:
        if event.kind == "activity.started" and event.activity in seen:
            inst = holder["sim"].live.get(event.instance)
            running = {ai.act.id for frame in inst.frames for ai in frame.running.values()}
            seen[event.activity].append(event.activity in running)

    built = prepare(RunRequest(spec=str(SPECS / "vacuum_cleaner.xpdl"), until=120.0,
                               no_user=True, seed=3, listeners=(listener,))).build(0)
    holder["sim"] = built.sim
    built.execute()
    return seen


def test_an_arbiter_and_a_push_have_no_instance_a_waiting_pull_has() -> None:
    seen = _instances_at_start()
    assert len(seen["arbiter"]) > 500 and not any(seen["arbiter"])
    assert len(seen["push_range"]) > 500 and not any(seen["push_range"])
    pulls = seen["pull_range"]
    # the avoid workflow's pull starts before sense's push: it waits, as an instance
    assert len(pulls) > 100 and all(pulls)


def test_an_arbiter_missing_an_input_fails_through_its_instance(config: EngineConfig) -> None:
    """Not at once: the activity fails as it did (its instance stopped, the failure traced
    with the field named); another workflow's arbiter, with its inputs, is done at once."""
    model = pkg(proc("p", [
        act("bad", coordination=coordination("arbiter", inputs=("nothing",), output="cmd"))],
        data=[field("cmd", "")]),
        proc("q", [
        act("good", coordination=coordination("arbiter", inputs=("wander",), output="cmd"))],
        data=[field("wander", "forward"), field("cmd", "")]))
    result = run(model, config=config)
    (failed,) = events(result, "activity.failed", activity="bad")
    assert failed.data["message"] == "data field 'nothing' does not exist"
    assert completed(result) == ["good"]
    assert [e.data["cmd"] for e in events(result, "data.changed") if "cmd" in e.data] == [
        "forward"]


@pytest.mark.parametrize("commands", [
    [None, "turn", "forward"], ["stop", "turn"], [None, ""], [], ["", 0, "x"], [0.0, None]])
def test_the_compiled_arbiter_is_the_arbiter(commands: list[object]) -> None:
    assert first_set(commands) == arbiter(commands)
