"""The pooled processor model: queueing, switch cost, priorities; dedicated for contrast."""

from __future__ import annotations

import pytest
from builders import act, pkg, proc
from engine_runs import events, run

from opspec.engine.config import EngineConfig


def _busy_package(priority_a: int = 0, priority_b: int = 0) -> object:
    return pkg(proc("a", [act("compute_a", cpu=1.0)], priority=priority_a),
               proc("b", [act("compute_b", cpu=1.0)], priority=priority_b),
               proc("c", [act("compute_c", cpu=1.0)], priority=0))


def test_pooled_model_queues_activities_when_all_workers_are_busy() -> None:
    result = run(_busy_package(), config=EngineConfig(processor_model="pooled", workers=1))
    queued = events(result, "activity.queued")
    assert [e.activity for e in queued] == ["compute_b", "compute_c"]
    done = {e.activity: e.time for e in events(result, "activity.completed")}
    assert done == {"compute_a": 1.0, "compute_b": 2.0, "compute_c": 3.0}


def test_dedicated_model_never_queues() -> None:
    result = run(_busy_package())
    assert events(result, "activity.queued") == []
    assert {e.time for e in events(result, "activity.completed")} == {1.0}


def test_switch_cost_is_paid_per_transition_into_a_general_activity() -> None:
    model = pkg(proc("p", ["a", "b", "c"], [("a", "b"), ("b", "c")]))
    result = run(model, config=EngineConfig(processor_model="pooled", switch_cost=0.01))
    assert [e.time for e in events(result, "activity.completed")] == pytest.approx(
        [0.01, 0.02, 0.03])


def test_higher_priority_workflow_is_served_first_from_the_queue() -> None:
    result = run(_busy_package(priority_a=0, priority_b=0).__class__(  # same package shape
        id="x", processes=(proc("a", [act("compute_a", cpu=1.0)]),
                           proc("b", [act("compute_b", cpu=1.0)], priority=0),
                           proc("c", [act("compute_c", cpu=1.0)], priority=5))),
        config=EngineConfig(processor_model="pooled", workers=1, priorities=8))
    done = {e.activity: e.time for e in events(result, "activity.completed")}
    assert done["compute_c"] < done["compute_b"]


def test_priority_increment_raises_an_activity_above_its_workflow_priority() -> None:
    from builders import pkg as make

    model = make(proc("a", [act("first", cpu=1.0)]),
                 proc("b", [act("normal", cpu=1.0)]),
                 proc("c", [act("urgent", cpu=1.0, priority_increment=3)]))
    result = run(model, config=EngineConfig(processor_model="pooled", workers=1))
    done = {e.activity: e.time for e in events(result, "activity.completed")}
    assert done["urgent"] < done["normal"]


def test_deadline_missed_only_under_the_pooled_model() -> None:
    model = pkg(proc("load", [act("heavy", cpu=5.0)]),
                proc("control", [act("react", cpu=0.5)], deadline=1.0))
    dedicated = run(model)
    pooled = run(model, config=EngineConfig(processor_model="pooled", workers=1))
    assert events(dedicated, "deadline.expired") == []
    assert [e.process for e in events(pooled, "deadline.expired")] == ["control"]
