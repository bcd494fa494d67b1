"""An instance's one token runs without a frame until it needs one (opspec/engine/lone.py),
and nothing a user can see changes: every trace event, its order, its instance ids, the
summary and the faults are those of the general path (the instance made with its frame at
the start). Each test runs the same package twice: as compiled, and with every process's
``one_start`` set to -1, which sends every instance the general way."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from builders import act, field, formal, lookup_subflow, manual, pkg, proc, subflow
from engine_runs import AnswersLater, events

from opspec.engine.compiled import CompiledPackage, compile_package
from opspec.engine.lanes import user_lane
from opspec.engine.random import user_stream
from opspec.engine.simulation import Simulation
from opspec.model import Package
from opspec.usermodels.loader import load_user_model
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]


def _general(compiled: CompiledPackage) -> CompiledPackage:
    for proc_ in compiled.processes.values():
        proc_.one_start = -1
    return compiled


def _trace(result: Any) -> list[tuple[Any, ...]]:
    return [(e.time, e.kind, e.process, e.instance, e.activity, e.lane, e.participant,
             e.package, dict(e.data), e.seq) for e in result.trace]


def _both(package: Package, **kwargs: Any) -> tuple[Any, Any]:
    lone = Simulation(compile_package(package), keep_trace=True, **kwargs).run(until=100.0)
    general = Simulation(_general(compile_package(package)), keep_trace=True,
                         **kwargs).run(until=100.0)
    return lone, general


def _same(lone: Any, general: Any) -> None:
    assert _trace(lone) == _trace(general)
    assert lone.summary == general.summary
    assert lone.metrics == general.metrics


@pytest.mark.parametrize("spec", ["medication_dispenser.xpdl", "medication_dispenser.bpmn"])
def test_the_dispenser_with_its_users_runs_the_same_event_for_event(spec: str) -> None:
    """The dispenser's timer and schedule workflows end without a frame; its notify and user
    workflows get theirs at their first waiting activity."""
    runs = []
    for general in (False, True):
        compiled = compile_package(open_spec(ROOT / "specs" / spec))
        if general:
            _general(compiled)
        model = load_user_model(ROOT / "specs" / "medication_dispenser.users.toml")
        user = model.performer(user_stream(5, 0))
        sim = Simulation(compiled, performers={n: user for n in user_lane(compiled).bind_names},
                         seed=5, keep_trace=True)
        runs.append(sim.run(until=4 * 86400.0))
    lone, general_run = runs
    _same(lone, general_run)
    started = events(lone, "process.started", process="schedule_workflow")
    assert len(started) == 16            # four doses a day, each looked up once
    assert len(events(lone, "process.completed", process="schedule_workflow")) == 16


def test_a_data_only_subflow_returns_its_out_parameters_as_before() -> None:
    main = proc("main", [subflow("call", "lookup", ["hour", "dose"]), "after"],
                [("call", "after")], data=[field("hour", 14), field("dose", "")])
    lone, general = _both(pkg(main, lookup_subflow()))
    _same(lone, general)
    assert {"dose": "noon"} in [dict(e.data) for e in events(lone, "data.changed",
                                                             process="main")]


def test_a_failing_assignment_in_a_frameless_instance_is_the_same_located_fault() -> None:
    main = proc("main", [subflow("call", "lookup", ["hour", "dose"]), "after"],
                [("call", "after")], data=[field("hour", 14), field("dose", "")])
    lone, general = _both(pkg(main, lookup_subflow("missing_field + 1")))
    _same(lone, general)
    assert lone.summary["faults"] and "missing_field" in lone.summary["faults"][0]["message"]


def test_no_condition_holding_ends_or_aborts_the_same_way() -> None:
    """An XOR split whose conditions all fail and that has no OTHERWISE: without a declared
    split the path ends (XPDL 1.0 engines); with a declared XOR split the instance aborts."""
    for split in (None, "XOR"):
        child = proc("child", [act("a", split=split), "b"], [("a", "b", "hour > 99")],
                     formals=[formal("hour", "IN")])
        main = proc("main", [subflow("call", "child", ["hour"]), "after"],
                    [("call", "after")], data=[field("hour", 1)])
        lone, general = _both(pkg(main, child))
        _same(lone, general)


def test_a_token_that_reaches_a_waiting_activity_gets_its_frame_and_goes_on() -> None:
    """A start, an assignment, then a manual activity: the instance gets its frame there;
    a performer answering later completes it as on the general path."""

    work = proc("work", [act("set", assign=[("n", "n + 1")]), manual("do"), "end"],
                [("set", "do"), ("do", "end")], data=[field("n", 0)])
    lone = Simulation(compile_package(pkg(work)), performers={"user": AnswersLater()},
                      keep_trace=True).run(until=100.0)
    general = Simulation(_general(compile_package(pkg(work))), performers={"user": AnswersLater()},
                         keep_trace=True).run(until=100.0)
    _same(lone, general)
    assert [e.time for e in events(lone, "process.completed", process="work")] == [5.0]

