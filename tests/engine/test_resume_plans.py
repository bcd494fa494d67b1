"""A waiting activity's completion carried on by a resume plan (opspec/engine/plans.py:
straight-line Python per activity, from source) changes nothing a user can see: every trace
event, its order and instance ids, the summary, the metrics, the faults and a zero-time
cycle's report are those of the interpreter (``Activities._complete`` and
``Activities.start``, no plans at all). Each test runs the same package both ways, and
counts that the resume plans ran; in the compiled build the plans are made for the test
(``plans.COMPILED`` off), so the generated code is held to the compiled engine too."""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar

import pytest
from builders import (
    act,
    activity_set,
    app,
    block,
    catch,
    end_event,
    field,
    formal,
    manual,
    pkg,
    proc,
    subflow,
    task,
    throw,
)
from plan_ways import WAYS, count_resumes, resume_plans, run_both
from plan_ways import seen as _seen
from plan_ways import use_way as _way

from engine_runs import AnswersLater
from opspec.engine.compiled import compile_package
from opspec.engine.config import EngineConfig
from opspec.engine.simulation import Simulation
from opspec.errors import OpspecError
from opspec.model import Loop, Package
from opspec.request import RunRequest, prepare
from opspec.xpdl.conditions import parse_condition

ROOT = Path(__file__).resolve().parents[2]
def _counting(sim: Any) -> dict[str, int]:
    """Wrap the run's resume plans so the test sees that they ran (by activity id)."""
    return count_resumes(sim)


def _both(monkeypatch: pytest.MonkeyPatch, package: Package, until: float = 100.0,
          **kwargs: Any) -> tuple[Any, dict[str, int]]:
    """Run ``package`` both ways; assert they agree; the result and the resumes that ran."""
    return run_both(monkeypatch, package, until, _counting,
                    resume_plans, lambda: dict(kwargs))


@pytest.mark.parametrize("spec", ["medication_dispenser.xpdl --days 3",
                                  "medication_dispenser.bpmn --days 3",
                                  "vacuum_cleaner.xpdl --until 120",
                                  "toy_sumo.xpdl --until 120",
                                  "medication_cart_guidance.xpdl --until 300"])
def test_every_bundled_spec_runs_the_same_event_for_event(monkeypatch: pytest.MonkeyPatch,
                                                          spec: str) -> None:
    """Each bundled spec with its user model or world, as ``opspec run`` builds it."""
    name, option, length = spec.split()
    seen = []
    ran: dict[str, int] = {}
    for way in WAYS:
        _way(monkeypatch, way)
        request = RunRequest(spec=ROOT / "specs" / name, seed=7, keep_trace=True,
                             **{option[2:]: float(length)})
        run = prepare(request).build(0)
        if way == "plans":
            ran = _counting(run.sim)
        seen.append(_seen(run.execute().result))
    assert seen[0] == seen[1]
    assert len(seen[0][0]) > 100
    if name.startswith("medication_dispenser"):
        # the report caught, and the pill taken: each goes on through lone activities
        assert ran and sum(ran.values()) > 10


def test_a_manual_activity_into_an_exclusive_split_of_lone_activities(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The resume plan takes the completed activity's own split (its conditions in order)
    and carries the token through assignments to the end: the instance completes once."""
    work = proc("work", [manual("do", split="XOR"), act("low", assign=[("n", "n + 1")]),
                         act("high", assign=[("n", "n + 2")]), "end"],
                [("do", "low", "n < 1"), ("do", "high", "otherwise"), ("low", "end"),
                 ("high", "end")], data=[field("n", 0)])
    (trace, summary, _metrics), ran = _both(monkeypatch, pkg(work),
                                            performers={"user": AnswersLater()})
    assert ran == {"do": 1}
    assert summary["instances"]["completed"] == 1
    assert {"n": 1} in [e[8] for e in trace if e[1] == "data.changed"]


@pytest.mark.parametrize("hour", [1, "noon"])
def test_a_failing_or_missing_condition_after_a_completion_is_the_same(
        monkeypatch: pytest.MonkeyPatch, hour: Any) -> None:
    """No condition holds without a declared split: the path ends (the frame loses its
    token); with a declared XOR split: the instance aborts; a condition that fails aborts
    it with the condition's message. The same fault, located the same, both ways."""
    outcomes = []
    for split in (None, "XOR"):
        work = proc("work", [manual("do", split=split), act("b"), "end"],
                    [("do", "b", "hour > 99"), ("b", "end")], data=[field("hour", hour)])
        (_trace, summary, _metrics), ran = _both(monkeypatch, pkg(work),
                                                 performers={"user": AnswersLater()})
        assert ran["do"] == 1             # (and "beep", when the horn answers)
        outcomes.append([f["message"] for f in summary["faults"]])
    if hour == 1:
        assert outcomes[0] == [] and "no outgoing transition" in outcomes[1][0]
    else:
        assert all("a transition condition failed" in o[0] for o in outcomes)


def test_a_resumed_token_beside_another_waits_for_it_at_the_end(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """An AND split: one branch's completion runs to its end in a resume plan while the
    other still waits; the frame keeps its other token and the instance completes when
    both are done. A completion into a join is not planned (the interpreter takes it)."""
    work = proc("work", [act("fork", split="AND"), manual("one"), "after_one", "end_one",
                         catch("wait", "timer", seconds=9.0), "after_wait",
                         manual("two"), act("sync", join="AND"), "end"],
                [("fork", "one"), ("fork", "wait"), ("fork", "two"), ("one", "after_one"),
                 ("after_one", "end_one"), ("wait", "after_wait"), ("after_wait", "sync"),
                 ("two", "sync"), ("sync", "end")])
    (trace, summary, _metrics), ran = _both(monkeypatch, pkg(work),
                                            performers={"user": AnswersLater()})
    assert ran == {"one": 1}
    assert [e[0] for e in trace if e[1] == "process.completed"] == [9.0]
    assert summary["instances"]["completed"] == 1


def test_a_zero_time_cycle_after_a_completion_is_reported_the_same(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The plan writes the path out until it comes back to an activity already on it, then
    goes on in ``Activities.start`` with the steps counted so far."""
    cycle = proc("spin", [manual("do"), act("a"), act("b", split="XOR"), "end"],
                 [("do", "a"), ("a", "b"), ("b", "a", "n < 1"), ("b", "end", "otherwise")],
                 data=[field("n", 0)])
    reports = []
    for way in WAYS:
        _way(monkeypatch, way)
        sim = Simulation(compile_package(pkg(cycle)), keep_trace=True,
                         performers={"user": AnswersLater()})
        with pytest.raises(OpspecError) as raised:
            sim.run(until=10.0)
        reports.append(str(raised.value))
    assert reports[0] == reports[1]
    assert "stopped advancing" in reports[0]


def test_what_waits_only_on_some_runs_is_handed_over(monkeypatch: pytest.MonkeyPatch) -> None:
    """After the completion, a task is lone unless a performer is bound to its application
    on this run, and every activity waits for a worker with the pooled processor."""

    class Echo:
        applications: ClassVar[dict[str, None]] = {"horn": None}   # bound to "horn"

        def attach(self, session: Any) -> None:
            self.session = session

        def offer(self, item: Any) -> None:
            self.session.call_later(2.0, lambda: self.session.complete(item))

        def withdraw(self, item: Any, reason: str) -> None:
            pass

    work = pkg(proc("work", [manual("do"), act("set", assign=[("n", "n + 1")]),
                             task("beep", "horn"), "end"],
                    [("do", "set"), ("set", "beep"), ("beep", "end")], data=[field("n", 0)]),
               applications=[app("horn")])
    ends = []
    for kwargs in ({}, {"performers": {"device": Echo(), "user": AnswersLater()}},
                   {"config": EngineConfig(processor_model="pooled")}):
        kwargs.setdefault("performers", {"user": AnswersLater()})
        (trace, summary, _metrics), ran = _both(monkeypatch, work, **kwargs)
        assert ran["do"] == 1             # (and "beep", when the horn answers)
        assert summary["instances"]["completed"] == 1
        ends += [e[0] for e in trace if e[1] == "process.completed"]
    assert ends[:2] == [5.0, 7.0]           # the bound horn answers 2 s after the user


def test_a_subflow_an_activity_set_and_a_loop_complete_into_lone_activities(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A synchronous subflow's return, an activity set's end and a loop's last iteration
    each go on through the lone activities after them; a terminate end event among them
    (not lone) is handed over and ends the instance as the interpreter does."""
    child = proc("child", [manual("inner"), "child_end"], [("inner", "child_end")],
                 formals=[formal("n", "INOUT")])
    main = proc("main", [subflow("call", "child", ["n"]), act("after_call", assign=[
        ("n", "n + 10")]), block("set", "S"), "after_set",
        manual("again", loop=Loop(condition=parse_condition("n < 13"), maximum=3)),
        act("after_loop", assign=[("n", "n * 2")]), end_event("stop", "Terminate")],
                [("call", "after_call"), ("after_call", "set"), ("set", "after_set"),
                 ("after_set", "again"), ("again", "after_loop"), ("after_loop", "stop")],
                data=[field("n", 1)],
                sets=[activity_set("S", [manual("in_set"), act("set_lone")],
                                   [("in_set", "set_lone")])])
    (trace, summary, _metrics), ran = _both(monkeypatch, pkg(main, child),
                                            performers={"user": AnswersLater()})
    assert ran == {"call": 1, "set": 1, "again": 1, "inner": 1}
    assert summary["instances"]["terminated"] + summary["instances"]["completed"] == 2
    assert [e[8] for e in trace if e[1] == "data.changed" and e[4] == "after_loop"] == [
        {"n": 22}]


def test_throws_and_raised_triggers_after_a_completion_are_sent_the_same(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A throw event and an activity that raises a trigger are not lone (a frameless token
    hands over before them) but a resume plan, in the frame, writes them out with
    ``Flow.done_next``'s broadcasts: the message starts its workflow, the signal is sent to
    the catch waiting for it, at the same step; an error end event is handed over (and
    aborts the instance before the caught signal goes on)."""
    work = proc("work", [act("fork", split="AND"), manual("do"), throw("ping", "ping"),
                         act("shout", raises="signal:sig", assign=[("n", "n + 1")]),
                         end_event("oops", "Error"), catch("hear", "signal", "sig"), "heard"],
                [("fork", "do"), ("fork", "hear"), ("do", "ping"), ("ping", "shout"),
                 ("shout", "oops"), ("hear", "heard")], data=[field("n", 0)])
    listener = proc("listener", ["got", "got_end"], [("got", "got_end")],
                    start="message:ping")
    (trace, summary, _metrics), ran = _both(monkeypatch, pkg(work, listener),
                                            performers={"user": AnswersLater()})
    assert ran == {"do": 1}
    kinds = [(e[1], e[2], e[4]) for e in trace]
    assert ("trigger.raised", "work", "ping") in kinds
    assert ("trigger.raised", "work", "shout") in kinds
    assert ("process.completed", "listener", None) in kinds
    assert "an error without a code" in summary["faults"][0]["message"]


class _Recorder(AnswersLater):
    """Answers later, and keeps what each work item offered to it says."""

    def __init__(self) -> None:
        super().__init__()
        self.items: list[tuple[Any, ...]] = []

    def offer(self, item: Any) -> None:
        self.items.append((item.key, item.process, item.instance, item.activity, item.label,
                           item.participant, item.lane, item.offered_at, item.application,
                           dict(item.data), item.choices, item.root_instance, item.duration))
        super().offer(item)


def test_a_manual_activity_offered_from_a_plan_is_the_same_work_item(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A plan offers a plain manual activity itself (``start_slow`` and ``offer`` in line):
    the same work items (keys, data, root instance) reach the performer, and with nobody
    bound the activity waits for a performer as the interpreter says."""
    child = proc("child", [act("first", assign=[("n", "n + 1")]), manual("ask"),
                           act("then", assign=[("n", "n * 3")]), manual("ask_again"), "end"],
                 [("first", "ask"), ("ask", "then"), ("then", "ask_again"),
                  ("ask_again", "end")], formals=[formal("n", "INOUT")])
    main = proc("main", [subflow("call", "child", ["n"]), "done"], [("call", "done")],
                data=[field("n", 1)])
    items = []
    ran: dict[str, int] = {}
    for way in WAYS:
        _way(monkeypatch, way)
        user = _Recorder()
        sim = Simulation(compile_package(pkg(main, child)), keep_trace=True,
                         performers={"user": user})
        if way == "plans":
            ran = _counting(sim)
        items.append((user.items, _seen(sim.run(until=100.0))))
    assert items[0] == items[1]
    assert ran == {"ask": 1, "ask_again": 1, "call": 1}
    assert [(i[3], i[9]) for i in items[0][0]] == [("ask", {"n": 2}), ("ask_again", {"n": 6})]
    unbound = proc("unbound", [act("first"), manual("ask", performer="nobody"), "end"],
                   [("first", "ask"), ("ask", "end")])
    (trace, _summary, _metrics), _unused = _both(monkeypatch, pkg(unbound))
    assert [e[8] for e in trace if e[1] == "activity.offered"] == [{"performer": None}]


def test_an_answer_to_a_suspended_instance_waits_for_its_resumption(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The performer answers while the instance is suspended: ``body_done`` defers the
    completion, and the resume plan carries the token through the lone activities after
    it once the instance resumes."""
    work = proc("work", [manual("do"), act("set", assign=[("n", "n + 1")]), "end"],
                [("do", "set"), ("set", "end")], data=[field("n", 0)])
    seen = []
    ran: dict[str, int] = {}
    for way in WAYS:
        _way(monkeypatch, way)
        sim = Simulation(compile_package(pkg(work)), keep_trace=True,
                         performers={"user": AnswersLater()})
        if way == "plans":
            ran = _counting(sim)
        sim.run(until=3.0)
        sim.suspend(1)
        sim.run(until=8.0)
        sim.resume(1)
        seen.append(_seen(sim.run(until=20.0)))
    assert seen[0] == seen[1]
    assert ran == {"do": 1}
    assert [e[0] for e in seen[0][0] if e[1] == "process.completed"] == [8.0]
