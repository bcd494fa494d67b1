"""A deferred choice's chosen branch carried on by a plan (opspec/engine/plans.py, from
source: ``Flow.take`` queues the branch's plan in ``Flow.performed``'s place) changes nothing
a user can see: every trace event, its order and instance ids, the summary, the metrics and
the faults are those of the interpreter (``Flow.performed``, ``Flow.finish`` and
``Activities.start``, no plans at all). Each test runs the same package both ways and counts
that the branch plans ran; in the compiled build the plans are made for the test
(``plans.COMPILED`` off), so the generated code is held to the compiled engine too."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from builders import (
    act,
    activity_set,
    block,
    catch,
    count,
    deadline,
    end_event,
    field,
    formal,
    manual,
    pkg,
    proc,
    route,
    subflow,
)
from plan_ways import WAYS, count_resumes, run_both
from plan_ways import seen as _seen
from plan_ways import use_way as _way

from opspec.engine import plans
from opspec.engine.builtin_performers import ScriptedUser
from opspec.engine.compiled import compile_package
from opspec.engine.simulation import Simulation
from opspec.model import Package
from opspec.request import RunRequest, prepare

ROOT = Path(__file__).resolve().parents[2]
def _counting(sim: Any) -> dict[str, int]:
    """Wrap the run's branch plans so the test sees that they ran (by branch activity)."""
    ran: dict[str, int] = {}
    performs = sim.flow.performs
    for trans, fn in list(performs.items()):
        def counted(frame: Any, activities: Any, taken: Any, fn: Any = fn) -> None:
            aid = frame.graph.activities[taken.target].id
            ran[aid] = ran.get(aid, 0) + 1
            fn(frame, activities, taken)
        performs[trans] = counted
    return ran


class _Picks(ScriptedUser):
    """Completes every item at once, choosing the choice's alternatives in turn."""

    def __init__(self) -> None:
        super().__init__(default="complete")
        self.turn = 0

    def offer(self, item: Any) -> None:
        if item.choices:
            choice = item.choices[self.turn % len(item.choices)]
            self.turn += 1
            self.session.call_later(1.0, lambda: self.session.complete(item, choice=choice))
            return
        super().offer(item)


def _both(monkeypatch: pytest.MonkeyPatch, package: Package, make_user: Any = _Picks,
          until: float = 1000.0) -> tuple[Any, dict[str, int]]:
    """Run ``package`` both ways; assert they agree; the result and the branches run."""
    return run_both(monkeypatch, package, until, _counting, lambda sim: sim.flow.performs,
                    lambda: {"performers": {"user": make_user()}})


@pytest.mark.parametrize("name", ["medication_dispenser.xpdl", "medication_dispenser.bpmn"])
def test_the_dispenser_runs_the_same_event_for_event(monkeypatch: pytest.MonkeyPatch,
                                                     name: str) -> None:
    """The user's button (a deferred choice between reporting and the wrong button, raising
    the report message) with the stochastic user, three days, as ``opspec run`` builds it."""
    seen = []
    ran: dict[str, int] = {}
    for way in WAYS:
        _way(monkeypatch, way)
        request = RunRequest(spec=ROOT / "specs" / name, seed=7, keep_trace=True, days=3.0)
        run = prepare(request).build(0)
        if way == "plans":
            ran = _counting(run.sim)
        seen.append(_seen(run.execute().result))
    assert seen[0] == seen[1]
    assert len(seen[0][0]) > 100
    assert sum(ran.values()) >= 6          # (at least one decision a dose)


def test_branches_with_assignments_a_split_and_a_cycle(monkeypatch: pytest.MonkeyPatch) -> None:
    """An event-based gateway decides three times (a cycle back to it): each branch's end
    assignment, the exclusive split after it and the path back are the interpreter's, and
    the racing timer never wins; the other alternative is taken in turn."""
    loop = [("l", "x"), ("r", "x"), ("x", "g", "n < 3"), ("x", "done", "otherwise")]
    work = proc("work", ["a", route("g", "EVENT", join="XOR"),
                         manual("l", assign=[("n", "n + 1")]),
                         catch("late", "timer", seconds=50.0),
                         manual("r", assign=[("n", "n + 10")]), route("x", split="XOR"),
                         "done"],
                [("a", "g"), ("g", "l"), ("g", "late"), ("g", "r"), ("late", "done"), *loop],
                data=[field("n", 0)])
    (trace, summary, _metrics), ran = _both(monkeypatch, pkg(work))
    assert ran == {"l": 1, "r": 1}
    assert [e[8] for e in trace if e[1] == "data.changed"] == [{"n": 1}, {"n": 11}]
    assert summary["instances"]["completed"] == 1


def test_a_branch_that_ends_and_one_that_ends_in_error(monkeypatch: pytest.MonkeyPatch) -> None:
    """A branch into an end (the token is gone, the instance completes) is planned; a
    branch that is an error end event is not (the interpreter throws it and the instance
    aborts as before)."""
    work = proc("work", ["a", route("g", "EVENT"), manual("stop"), manual("fail"),
                         end_event("oops", "Error")],
                [("a", "g"), ("g", "stop"), ("g", "fail"), ("fail", "oops")])
    for picks in (0, 1):
        def user(picks: int = picks) -> _Picks:
            made = _Picks()
            made.turn = picks
            return made
        (_trace, summary, _metrics), ran = _both(monkeypatch, pkg(work), user)
        if picks == 0:
            assert ran == {"stop": 1} and summary["instances"]["completed"] == 1
        else:
            assert ran == {"fail": 1} and summary["faults"]


def test_a_choice_inside_an_activity_set_goes_through_the_interpreter(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The plans are written for the workflow's own graph: a deferred choice inside an
    activity set (its own frame and graph) is run by ``Flow.performed`` as before."""
    work = proc("work", [block("set", "S"), "after"], [("set", "after")],
                data=[field("n", 0)],
                sets=[activity_set("S", ["a", route("g", "EVENT"),
                                          manual("l", assign=[("n", "n + 1")]),
                                          manual("r", assign=[("n", "n + 2")]), "b"],
                                   [("a", "g"), ("g", "l"), ("g", "r"), ("l", "b"),
                                    ("r", "b")])])
    (trace, summary, _metrics), ran = _both(monkeypatch, pkg(work))
    assert ran == {}
    assert summary["instances"]["completed"] == 1
    assert [e[8] for e in trace if e[1] == "data.changed"] == [{"n": 1}]


def test_two_runs_of_one_package_with_other_listeners_take_turns(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The plans read which events the listeners want from globals set for a run's
    selection where each plan starts (``plan_writer.by_selection``): two runs of one compiled
    package, one keeping its whole trace and one only its metrics, stepped in turn, trace
    and count what each would alone, as the interpreter does."""
    work = proc("work", ["a", manual("ask"), route("g", "EVENT"),
                         manual("l", assign=[("n", "n + 1")]), manual("r"), "b", "end"],
                [("a", "ask"), ("ask", "g"), ("g", "l"), ("g", "r"), ("l", "b"), ("r", "b"),
                 ("b", "end")], data=[field("n", 0)], start="period:900")
    package = pkg(work, metrics=[count("asked", "activity.completed", "work", "ask"),
                                 count("ended", "process.completed", "work")])
    seen = []
    for way in WAYS:
        _way(monkeypatch, way)
        compiled = compile_package(package)
        traced = Simulation(compiled, keep_trace=True, performers={"user": _Picks()})
        counted = Simulation(compiled, performers={"user": _Picks()})
        results = []
        for step in range(1, 97):           # two days, half an hour at a time each
            for sim in (counted, traced):     # (the counting run selects first)
                results.append(sim.run(until=step * 1800.0))
        seen.append((_seen(results[-1]), results[-2].metrics, results[-2].summary))
    assert seen[0] == seen[1]
    trace, _summary, metrics = seen[0][0]
    assert seen[0][1] == metrics
    assert metrics["asked"]["total"] == metrics["ended"]["total"] >= 190
    assert len(trace) > 190 * 10


class _Slow(ScriptedUser):
    """Completes plain items at once and answers a choice only after 20 s."""

    def __init__(self) -> None:
        super().__init__(default="complete")

    def offer(self, item: Any) -> None:
        if item.choices:
            self.session.call_later(20.0, lambda: self.session.complete(
                item, choice=item.choices[0]))
            return
        super().offer(item)


def test_a_choice_offered_by_a_resume_plan_races_its_catch_event(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """After a manual activity, a resume plan makes the gateway's instance, arms its catch
    event and offers its manual branches itself (``Offers.offer_choice`` in line): the
    timer wins against a slow answer (the work item is withdrawn) and where nobody is bound
    to the branches, and a quick answer wins against the timer, as in the interpreter."""
    work = proc("work", [manual("ask", performer="clerk"), route("g", "EVENT"), manual("l"),
                         catch("late", "timer", seconds=5.0), manual("r"), "b", "end"],
                [("ask", "g"), ("g", "l"), ("g", "late"), ("g", "r"), ("l", "b"),
                 ("late", "b"), ("r", "b"), ("b", "end")])
    resumed = []
    for user in (_Slow, _Picks, None):
        seen = []
        for way in WAYS:
            _way(monkeypatch, way)
            performers: dict[str, Any] = {"clerk": ScriptedUser(default="complete")}
            if user is not None:
                performers["user"] = user()
            sim = Simulation(compile_package(pkg(work)), keep_trace=True,
                             performers=performers)
            if way == "plans":
                resumed.append(count_resumes(sim))
            seen.append(_seen(sim.run(until=100.0)))
        assert seen[0] == seen[1]
        done = [e[4] for e in seen[0][0] if e[1] == "activity.completed"]
        if user is _Picks:
            assert "l" in done and "late" not in done
        else:                               # too slow, or nobody to answer: the timer
            assert "late" in done and "l" not in done
    assert resumed == [{"ask": 1}] * 3


@pytest.mark.parametrize("sent_at", [3.0, 30.0])
def test_a_caught_event_under_a_deadline_and_a_boundary_event_started_by_a_plan(
        monkeypatch: pytest.MonkeyPatch, sent_at: float) -> None:
    """After a manual activity, a resume plan starts the catch event itself
    (``Activities.activate`` and ``_body`` in line): its deadline is armed, its boundary
    timer waits beside it, and the message caught in time, the boundary timer or the
    deadline ends the wait, as the interpreter does."""
    work = proc("work", [manual("ask"),
                         catch("wait", "message", "go", deadlines=[deadline(20.0, "late")]),
                         catch("tick", "timer", seconds=10.0, attached_to="wait",
                               interrupting=False),
                         "got", "ticked", "timed_out", "end"],
                [("ask", "wait"), ("wait", "got"), ("tick", "ticked"),
                 ("wait", "timed_out", "exception:late"), ("got", "end"),
                 ("timed_out", "end")])
    sender = proc("sender", [catch("pause", "timer", seconds=sent_at),
                             act("send", raises="message:go")], [("pause", "send")])
    package = pkg(work, sender)
    (trace, _summary, _metrics), _ran = _both(monkeypatch, package,
                                              lambda: ScriptedUser(default="complete"))
    done = [e[4] for e in trace if e[1] == "activity.completed"]
    assert ("ticked" in done) == (sent_at > 10.0)
    assert ("got" in done) == (sent_at < 20.0) and ("timed_out" in done) == (sent_at > 20.0)
    _way(monkeypatch, "plans")              # (the completion of ask is planned)
    planned = plans.dones(compile_package(package))
    ask = next(fn for a, fn in planned.items() if a.id == "ask")
    assert "triggers.deadline" in ask.__doc__ and "activate" not in ask.__doc__


def test_subflows_started_by_a_plan_with_their_process_deadlines(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A plan starts an asynchronous subflow and calls a synchronous one itself
    (``Flow.start_process`` in line): the same instance ids, data, trace and process
    deadlines (each called workflow has one, which ends a slow instance) as the
    interpreter, and a caller's higher priority passed on."""
    slow = proc("slow", [manual("work", performer="clerk"), "slow_end"],
                [("work", "slow_end")], formals=[formal("n", "INOUT")], deadline=3.0,
                auto_start=False)
    quick = proc("quick", [act("bump", assign=[("n", "n + 1")]), "quick_end"],
                 [("bump", "quick_end")], formals=[formal("n", "INOUT")], deadline=30.0,
                 priority=2, auto_start=False)
    main = proc("main", [manual("ask"), subflow("fire", "slow", ["n"], asynchronous=True),
                         subflow("call", "quick", ["n"]), "main_end"],
                [("ask", "fire"), ("fire", "call"), ("call", "main_end")],
                data=[field("n", 1)], priority=5)
    (trace, summary, _metrics), _ran = _both(
        monkeypatch, pkg(main, slow, quick), lambda: ScriptedUser(default="complete"))
    started = [(e[2], e[3], e[8]) for e in trace if e[1] == "process.started"]
    assert started == [("main", 1, {"trigger": "auto", "parent": None}),
                       ("slow", 2, {"trigger": "subflow:fire", "parent": None}),
                       ("quick", 3, {"trigger": None, "parent": 1})]
    assert [e[8] for e in trace if e[1] == "data.changed"] == [{"n": 2}, {"n": 2}]
    assert summary["instances"]["completed"] == 2
    assert summary["instances"]["aborted"] + summary["instances"]["terminated"] == 1
