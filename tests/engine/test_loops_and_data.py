"""Standard loops, activity start triggers, terminate end events, package-wide data."""

from __future__ import annotations

from builders import act, catch, end_event, field, pkg, proc, trigger
from engine_runs import completed, events, run

from opspec.engine.config import EngineConfig
from opspec.model import Loop
from opspec.xpdl.conditions import parse_condition


def _loop(condition: str | None, maximum: int | None, before: bool) -> Loop:
    return Loop(condition=parse_condition(condition) if condition else None,
                condition_text=condition, maximum=maximum, test_before=before)


def _looping(loop: Loop, start: int = 0) -> object:
    return pkg(proc("p", [act("step", loop=loop, assign=[("n", "n + 1")]), "after"],
                    [("step", "after")], data=[field("n", start)]))


def _runs(result: object) -> list[object]:
    return [e.data["n"] for e in events(result, "data.changed")]  # type: ignore[arg-type]


def test_loop_with_test_after_runs_at_least_once(config: EngineConfig) -> None:
    assert _runs(run(_looping(_loop("n < 0", None, False)), config=config)) == [1]


def test_loop_with_test_before_may_not_run_at_all(config: EngineConfig) -> None:
    result = run(_looping(_loop("n < 0", None, True)), config=config)
    assert _runs(result) == [] and completed(result) == ["step", "after"]


def test_loop_repeats_while_its_condition_holds(config: EngineConfig) -> None:
    assert _runs(run(_looping(_loop("n < 3", None, True)), config=config)) == [1, 2, 3]


def test_loop_maximum_bounds_the_iterations(config: EngineConfig) -> None:
    assert _runs(run(_looping(_loop("true", 4, False)), config=config)) == [1, 2, 3, 4]


def test_activity_start_trigger_holds_the_activity_until_the_message() -> None:
    model = pkg(proc("p", [act("go", start_trigger=trigger("message:ready")), "next"],
                     [("go", "next")]),
                proc("q", [catch("d", "timer", seconds=6.0), act("tell", raises="message:ready")],
                     [("d", "tell")]))
    result = run(model)
    assert events(result, "activity.started", activity="go")[0].time == 6.0


def test_terminate_end_event_ends_the_whole_instance() -> None:
    model = pkg(proc("p", [act("s", split="AND"), catch("long", "timer", seconds=50.0),
                           end_event("stop", result="Terminate")],
                     [("s", "long"), ("s", "stop")]))
    result = run(model)
    assert events(result, "process.terminated")[0].time == 0.0
    assert "long" not in completed(result)


def test_package_wide_data_is_shared_by_instances_and_params_override_it() -> None:
    model = pkg(proc("writer", [act("w", assign=[("shared", "shared + 1")])]),
                proc("reader", [catch("d", "timer", seconds=1.0), act("r", assign=[
                    ("seen", "shared")])], [("d", "r")], data=[field("seen", 0)]),
                data=[field("shared", 10)])
    result = run(model, params={"shared": 100})
    assert {"seen": 101} in [dict(e.data) for e in events(result, "data.changed")]
