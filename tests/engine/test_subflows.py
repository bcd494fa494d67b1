"""Synchronous subflows with parameters, asynchronous starts, activity sets."""

from __future__ import annotations

from builders import act, activity_set, block, field, formal, pkg, proc, subflow
from engine_runs import completed, events, run

from opspec.engine.config import EngineConfig


def _child() -> object:
    return proc("child", [act("work", assign=[("out", "inp * 10"), ("both", "both + 1")],
                              cpu=1.0)],
                formals=[formal("inp", "IN"), formal("out", "OUT"), formal("both", "INOUT")])


def test_synchronous_subflow_maps_in_out_and_inout_parameters(config: EngineConfig) -> None:
    model = pkg(proc("main", [subflow("call", "child", ["a", "b", "c"]), "after"],
                     [("call", "after")],
                     data=[field("a", 4), field("b", 0), field("c", 100)]), _child())
    result = run(model, config=config)
    changes = [dict(e.data) for e in events(result, "data.changed", process="main")]
    assert {"b": 40} in changes and {"c": 101} in changes
    assert completed(result, "main") == ["call", "after"]
    call_done = events(result, "activity.completed", process="main", activity="call")[0]
    assert call_done.time >= 1.0                      # the caller waited for the subflow


def test_in_parameter_changes_in_the_subflow_do_not_reach_the_caller(
        config: EngineConfig) -> None:
    child = proc("child", [act("w", assign=[("inp", "0")])], formals=[formal("inp", "IN")])
    model = pkg(proc("main", [subflow("call", "child", ["a"])], data=[field("a", 7)]), child)
    result = run(model, config=config)
    assert all(e.process == "child" for e in events(result, "data.changed"))


def test_asynchronous_subflow_does_not_wait(config: EngineConfig) -> None:
    model = pkg(proc("main", [subflow("fire", "child", ["a", "b", "c"], asynchronous=True),
                              "after"], [("fire", "after")],
                     data=[field("a", 1), field("b", 0), field("c", 0)]), _child())
    result = run(model, config=config)
    after = events(result, "activity.completed", process="main", activity="after")[0]
    work = events(result, "activity.completed", process="child", activity="work")[0]
    assert after.time < work.time
    assert events(result, "process.started", process="child")[0].data["parent"] is None


def test_block_activity_runs_its_activity_set_then_continues(config: EngineConfig) -> None:
    inner = activity_set("S", ["x", act("y", assign=[("n", "n + 1")])], [("x", "y")])
    model = pkg(proc("p", ["a", block("b", "S"), "c"], [("a", "b"), ("b", "c")],
                     sets=[inner], data=[field("n", 0)]))
    assert completed(run(model, config=config)) == ["a", "x", "y", "b", "c"]
