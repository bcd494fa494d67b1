"""Several start events of one process are independent: each timer or message start starts
its own instance at its own time, and only the triggered start event's path runs."""

from __future__ import annotations

import pytest

from .conftest import completed, instances, kinds, run


@pytest.mark.parametrize("name", ["several_start_events.bpmn", "several_start_events.xpdl"])
def test_each_start_event_starts_its_own_instance_with_only_its_path(name: str) -> None:
    """BPMN 2.0 §10.4.2 (Start Event): "There MAY be multiple Start Events for a given
    Process level. Each Start Event is an independent event. That is, a Process instance SHALL
    be generated when the Start Event is triggered." §13.1 (Process instantiation): "Each
    Start Event that occurs creates a token on its outgoing Sequence Flows". XPDL 2.1 takes
    its StartEvent triggers from BPMN; opspec reads an XPDL process's start events the same way.

    The timer start (R/PT1H) makes an instance at 1 h and at 2 h that runs "hourly" only; the
    message "call" sent at 10 min makes one instance that runs "answer" only. No instance runs
    both paths, and the message start is armed although the timer start comes first."""
    outcome = run(name, until=9000)
    instances: dict[int, list[str]] = {}
    for event in outcome.trace:
        if event.process == "p" and event.kind == "activity.completed":
            instances.setdefault(event.instance or 0, []).append(event.activity or "")
    started = [(e.time, e.data["trigger"]) for e in outcome.trace
               if e.process == "p" and e.kind == "process.started"]
    assert started == [(600.0, "message:call"), (3600.0, "period"), (7200.0, "period")]
    assert sorted(instances.values()) == [["every_hour", "hourly", "end_hourly"]] * 2 + [
        ["on_call", "answer", "end_answer"]]
    assert completed(outcome, "p")[0] == (600.0, "on_call")


def test_a_called_process_starts_at_its_none_start_event_only() -> None:
    """BPMN 2.0 §13.3.4 (Sub-Process / Call Activity): "the global Process that is called MAY
    also have non-empty Start Events. These non-empty Start Events are alternative to the
    empty Start Event and hence they are ignored when the Process is called from another
    Process." And a timer start event's instance runs only its own path (§10.4.2).

    "main" calls "p" at t=0: that instance runs "from_call" only; the timer start makes its
    own instances at 1 h and 2 h, which run "hourly" only."""
    outcome = run("start_events_when_called.bpmn", until=9000)
    instances: dict[int, list[str]] = {}
    for event in outcome.trace:
        if event.process == "p" and event.kind == "activity.completed":
            instances.setdefault(event.instance or 0, []).append(event.activity or "")
    assert sorted(instances.values()) == [["every_hour", "hourly", "end_hourly"]] * 2 + [
        ["s_none", "from_call", "end_call"]]
    assert [e.process for e in kinds(outcome, "process.completed")][:2] == ["p", "main"]


def test_a_none_start_beside_a_message_start_starts_its_own_instance() -> None:
    """BPMN 2.0 §10.4.2 (Start Event): "Each Start Event is an independent event. That is, a
    Process instance SHALL be generated when the Start Event is triggered." The none start
    event "begin" starts the instance the run begins with (as in a process with only a none
    start event), which runs "open" only; the message "call" at 10 min starts another, which
    runs "answer" only. Before, the none start event beside a triggered one started nothing."""
    outcome = run("none_beside_message_start.bpmn", until=3600)
    started = [(e.time, e.data["trigger"]) for e in outcome.trace
               if e.process == "p" and e.kind == "process.started"]
    assert started == [(0.0, "auto"), (600.0, "message:call")]
    assert instances(outcome) == [["begin", "open", "end_open"],
                                   ["on_call", "answer", "end_answer"]]


def test_the_api_starts_a_process_at_its_none_start_events_only() -> None:
    """BPMN 2.0 §10.4.2: a triggered start event starts an instance "when the Start Event is
    triggered", not otherwise. An instance started from the API (no trigger) begins at the
    none start event: "on_call", whose message never came, does not run with it."""
    from opspec.engine.simulation import Simulation
    from opspec.xpdl.loader import load_spec

    from .conftest import DATA

    simulation = Simulation(load_spec(DATA / "none_beside_message_start.bpmn"),
                            keep_trace=True)
    simulation.start("p")
    result = simulation.run(until=60)
    assert instances(result) == [["begin", "open", "end_open"]] * 2
