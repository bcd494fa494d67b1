"""Deadlines (synchronous and asynchronous) and exception paths."""

from __future__ import annotations

import re

import pytest
from builders import act, app, catch, deadline, field, manual, pkg, proc, subflow, task
from engine_runs import completed, events, run

from opspec.engine.builtin_performers import CallablePerformer, ScriptedUser
from opspec.engine.config import EngineConfig


def test_synchronous_deadline_interrupts_the_activity_and_takes_the_named_exception(
        config: EngineConfig) -> None:
    model = pkg(proc("p", [catch("wait", "message", "never", deadlines=[deadline(60, "late")]),
                           "ok", "handle_late", "other"],
                     [("wait", "ok"), ("wait", "handle_late", "exception:late"),
                      ("wait", "other", "exception:unrelated")]))
    result = run(model, config=config)
    assert completed(result) == ["handle_late"]
    expired = events(result, "deadline.expired", activity="wait")
    assert expired[0].time == 60.0 and expired[0].data["synchronous"] is True
    assert events(result, "exception.raised")[0].data["exception"] == "late"


def test_synchronous_deadline_withdraws_a_manual_offer(config: EngineConfig) -> None:
    model = pkg(proc("p", [manual("answer", deadlines=[deadline(30, "slow")]), "ok", "late"],
                     [("answer", "ok"), ("answer", "late", "default-exception")]))
    user = ScriptedUser([(45.0, "complete answer")])
    result = run(model, performers={"user": user}, config=config)
    assert completed(result) == ["late"]
    assert events(result, "activity.withdrawn", activity="answer")[0].time == 30.0
    assert result.summary["stale_completions"] == 1


def test_activity_done_before_its_deadline_ignores_the_deadline(config: EngineConfig) -> None:
    model = pkg(proc("p", [manual("answer", deadlines=[deadline(30, "slow")]), "ok", "late"],
                     [("answer", "ok"), ("answer", "late", "exception:slow")]))
    user = ScriptedUser([(10.0, "complete answer")])
    result = run(model, performers={"user": user}, config=config)
    assert completed(result) == ["answer", "ok"]
    assert events(result, "deadline.expired") == []


def test_asynchronous_deadline_starts_the_exception_path_beside_the_activity(
        config: EngineConfig) -> None:
    model = pkg(proc("p", [manual("work", deadlines=[deadline(20, "remind", synchronous=False)]),
                           "done", "reminder"],
                     [("work", "done"), ("work", "reminder", "exception:remind")]))
    user = ScriptedUser([(50.0, "complete work")])
    result = run(model, performers={"user": user}, config=config)
    assert completed(result) == ["reminder", "work", "done"]
    # (the pooled model adds its 1 ms switch cost before the general activity 'reminder')
    assert events(result, "activity.completed", activity="reminder")[0].time == pytest.approx(
        20.0, abs=0.01)
    assert events(result, "activity.completed", activity="work")[0].time == 50.0


def test_implementation_that_raises_follows_the_exception_transition(
        config: EngineConfig) -> None:
    def broken(_inputs: object) -> None:
        raise ValueError("sensor unplugged")

    model = pkg(proc("p", [task("read", "sensor"), "use", "fallback"],
                     [("read", "use"), ("read", "fallback", "exception:ValueError")]),
                applications=[app("sensor")])
    result = run(model, performers={"x": CallablePerformer({"sensor": broken})}, config=config)
    assert completed(result) == ["fallback"]
    failed = events(result, "activity.failed", activity="read")[0]
    assert failed.data == {"exception": "ValueError", "message": "sensor unplugged"}


def test_implementation_that_raises_without_exception_path_aborts_with_its_location(
        config: EngineConfig) -> None:
    def broken(_inputs: object) -> None:
        raise RuntimeError("motor stalled")

    model = pkg(proc("p", [task("drive", "motor", line=42), "next"], [("drive", "next")]),
                proc("other", [act("independent", cpu=5.0)]),
                applications=[app("motor")])
    result = run(model, performers={"x": CallablePerformer({"motor": broken})}, config=config)
    fault = result.summary["faults"][0]["message"]
    assert fault.startswith("test.xpdl:42: activity 'drive' of process 'p'")
    assert re.search(r"aborted at t=0\.00\d s: .*motor stalled", fault)
    assert events(result, "process.aborted", process="p")
    assert completed(result, "other") == ["independent"]     # the run went on


def test_callable_receives_inputs_and_its_outputs_reach_the_data_fields(
        config: EngineConfig) -> None:
    seen = {}

    def double(inputs: dict[str, object]) -> dict[str, object]:
        seen.update(inputs)
        return {"y": 2 * inputs["x"]}  # type: ignore[operator]

    model = pkg(proc("p", [task("calc", "double", ["a", "b"]), "check"], [("calc", "check")],
                     data=[field("a", 21), field("b", 0)]),
                applications=[app("double", ("x", "IN"), ("y", "OUT"))])
    result = run(model, performers={"x": CallablePerformer({"double": double})}, config=config)
    assert seen == {"x": 21}
    assert {"b": 42} in [dict(e.data) for e in events(result, "data.changed")]


def test_performer_failure_follows_default_exception(config: EngineConfig) -> None:
    model = pkg(proc("p", [manual("pour"), "ok", "spilled"],
                     [("pour", "ok"), ("pour", "spilled", "default-exception")]))
    user = ScriptedUser([(3.0, "fail pour spill")])
    result = run(model, performers={"user": user}, config=config)
    assert completed(result) == ["spilled"]


def test_failed_subflow_raises_aborted_in_the_caller(config: EngineConfig) -> None:
    def broken(_inputs: object) -> None:
        raise KeyError("x")

    model = pkg(proc("main", [subflow("call", "child"), "ok", "recover"],
                     [("call", "ok"), ("call", "recover", "exception:aborted")]),
                proc("child", [task("boom", "boom")]), applications=[app("boom")])
    result = run(model, performers={"x": CallablePerformer({"boom": broken})}, config=config)
    assert completed(result, "main") == ["recover"]


@pytest.mark.parametrize("text", ["n > ", "unknown_field > 1"], ids=["syntax", "missing-field"])
def test_condition_that_cannot_be_evaluated_aborts_the_instance(text: str) -> None:
    from opspec.model import Condition, ConditionKind, Name, Transition

    bad = Transition(id="t_bad", source="a", target="b",
                     condition=Condition(kind=ConditionKind.CONDITION, text=text,
                                         expression=Name(("unknown_field",))))
    good = Transition(id="t_ok", source="a", target="c",
                      condition=Condition(kind=ConditionKind.OTHERWISE))
    base = proc("p", ["a", "b", "c"])
    from dataclasses import replace
    model = pkg(replace(base, transitions=(bad, good)))
    result = run(model)
    assert "unknown_field" in result.summary["faults"][0]["message"]
