"""A workflow's frameless first token runs as a plan made at load time (opspec/engine/plans.py:
straight-line Python per workflow, from source), and nothing a user can see changes: every
trace event, its order and instance ids, the summary, the metrics, the faults and a zero-time
cycle's report are those of ``lone.run`` (no plans) and of the general path (every instance
made with its frame, ``one_start = -1``). Each test runs the same package each way; in the
compiled build plans are made for the test (``plans.COMPILED`` off), so the generated code is
held to the compiled engine too."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from builders import act, app, field, formal, lookup_subflow, manual, pkg, proc, subflow, task
from plan_ways import seen as _seen

from engine_runs import AnswersLater
from opspec.engine import plans
from opspec.engine.compiled import CompiledPackage, compile_package
from opspec.engine.config import EngineConfig
from opspec.engine.lanes import user_lane
from opspec.engine.random import user_stream
from opspec.engine.simulation import Simulation
from opspec.errors import OpspecError
from opspec.model import Package
from opspec.request import RunRequest, prepare
from opspec.usermodels.loader import load_user_model
from opspec.xpdl.open_spec import open_spec

ROOT = Path(__file__).resolve().parents[2]
WAYS = ("plan", "lone", "general")


def _way(monkeypatch: pytest.MonkeyPatch, way: str) -> None:
    monkeypatch.setattr(plans, "COMPILED", way != "plan")


def _compiled(package: Package, way: str) -> CompiledPackage:
    compiled = compile_package(package)
    if way == "general":
        for proc_ in compiled.processes.values():
            proc_.one_start = -1
    return compiled


def _counting(sim: Simulation) -> dict[str, int]:
    """Wrap the run's plans so the test sees that they ran (and which)."""
    ran: dict[str, int] = {}
    for proc_ in sim.compiled.processes.values():
        if proc_.plan is None:
            continue

        def counted(inst: Any, activities: Any, unused: Any, fn: Any = proc_.plan,
                    pid: str = proc_.id) -> None:
            ran[pid] = ran.get(pid, 0) + 1
            fn(inst, activities, unused)
        proc_.plan = counted
    return ran


def _planless(sim: Simulation) -> bool:
    return all(proc_.plan is None for proc_ in sim.compiled.processes.values())


def _three(monkeypatch: pytest.MonkeyPatch, package: Package, until: float = 100.0,
           **kwargs: Any) -> tuple[Any, dict[str, int]]:
    """Run ``package`` the three ways; assert they agree; the plan's result and its counts."""
    seen = []
    ran: dict[str, int] = {}
    for way in WAYS:
        _way(monkeypatch, way)
        sim = Simulation(_compiled(package, way), keep_trace=True, **kwargs)
        if way == "plan":
            ran = _counting(sim)
        else:
            assert _planless(sim)
        seen.append(_seen(sim.run(until=until)))
    assert seen[0] == seen[1] == seen[2]
    return seen[0], ran


@pytest.mark.parametrize("spec", ["medication_dispenser.xpdl", "medication_dispenser.bpmn"])
def test_the_dispenser_with_its_users_runs_the_same_event_for_event(
        monkeypatch: pytest.MonkeyPatch, spec: str) -> None:
    """The timer and schedule workflows run as plans; notify and the user's workflow hand
    their token over to the general path at their first waiting activity."""
    seen = []
    ran: dict[str, int] = {}
    package = open_spec(ROOT / "specs" / spec)
    for way in WAYS:
        _way(monkeypatch, way)
        compiled = _compiled(package, way)
        model = load_user_model(ROOT / "specs" / "medication_dispenser.users.toml")
        user = model.performer(user_stream(5, 0))
        sim = Simulation(compiled, performers={n: user for n in user_lane(compiled).bind_names},
                         seed=5, keep_trace=True)
        if way == "plan":
            ran = _counting(sim)
        seen.append(_seen(sim.run(until=4 * 86400.0)))
    assert seen[0] == seen[1] == seen[2]
    assert ran["schedule_workflow"] == 16          # four doses a day, each looked up once
    assert len([e for e in seen[0][0] if e[1] == "process.completed"
                and e[2] == "schedule_workflow"]) == 16


@pytest.mark.parametrize("spec", ["vacuum_cleaner.xpdl", "toy_sumo.xpdl",
                                  "medication_cart_guidance.xpdl"])
def test_the_robot_specs_with_their_worlds_run_the_same(monkeypatch: pytest.MonkeyPatch,
                                                        spec: str) -> None:
    """Periodic workflows at 5 Hz: data-only ones (wander, the manoeuvre's usual path) end
    inside their plan; the others hand over at their first device activity."""
    seen = []
    for way in ("plan", "lone"):
        _way(monkeypatch, way)
        prepared = prepare(RunRequest(spec=ROOT / "specs" / spec, seed=3, until=60.0,
                                      no_user=True, keep_trace=True))
        seen.append(_seen(prepared.build(0).execute().result))
    assert seen[0] == seen[1]
    assert len(seen[0][0]) > 1000


def _caller(hour: Any = 14) -> Any:
    return proc("main", [subflow("call", "lookup", ["hour", "dose"]), "after"],
                [("call", "after")], data=[field("hour", hour), field("dose", "")])


def test_a_data_only_subflow_returns_its_out_parameters(monkeypatch: pytest.MonkeyPatch
                                                         ) -> None:
    (trace, _summary, _metrics), ran = _three(monkeypatch, pkg(_caller(), lookup_subflow()))
    assert ran == {"main": 1, "lookup": 1}
    assert ("data.changed", {"dose": "noon"}) in [(e[1], e[8]) for e in trace]


def test_a_failing_assignment_is_the_same_located_fault(monkeypatch: pytest.MonkeyPatch
                                                        ) -> None:
    (_trace, summary, _metrics), _ran = _three(
        monkeypatch, pkg(_caller(), lookup_subflow("missing_field + 1")))
    assert summary["faults"] and "missing_field" in summary["faults"][0]["message"]


def test_a_failing_condition_is_the_same_located_fault(monkeypatch: pytest.MonkeyPatch
                                                       ) -> None:
    """``hour < 12`` on a text that is no number: the instance aborts with the condition's
    message, as the general path's split reports it."""
    (_trace, summary, _metrics), _ran = _three(
        monkeypatch, pkg(_caller("noon"), lookup_subflow()))
    assert "a transition condition failed" in summary["faults"][0]["message"]


def test_no_condition_holding_ends_or_aborts_the_same_way(monkeypatch: pytest.MonkeyPatch
                                                          ) -> None:
    """An XOR split whose conditions all fail and that has no OTHERWISE: without a declared
    split the path ends (XPDL 1.0 engines); with a declared XOR split the instance aborts."""
    outcomes = []
    for split in (None, "XOR"):
        child = proc("child", [act("a", split=split), "b"], [("a", "b", "hour > 99")],
                     formals=[formal("hour", "IN")])
        main = proc("main", [subflow("call", "child", ["hour"]), "after"],
                    [("call", "after")], data=[field("hour", 1)])
        (_trace, summary, _metrics), ran = _three(monkeypatch, pkg(main, child))
        assert ran["child"] == 1
        outcomes.append(bool(summary["faults"]))
    assert outcomes == [False, True]


def test_transition_assignments_and_an_asynchronous_start(monkeypatch: pytest.MonkeyPatch
                                                          ) -> None:
    """Assignments on the chosen transition, start assignments, and an asynchronous subflow
    started from inside the plan (its instance is queued, as on the general path)."""
    from opspec.model import Assignment
    from opspec.xpdl.conditions import parse_expression

    child = proc("child", [act("c", assign=[("seen", "n * 2")])],
                 formals=[formal("n", "IN")], data=[field("seen", 0)])
    main = proc("main", [act("a", split="XOR", assign_start=[("n", "n + 1")]),
                         subflow("go", "child", ["n"], asynchronous=True), "other", "end"],
                [("a", "go", "n > 1"), ("a", "other", "otherwise"), ("go", "end"),
                 ("other", "end")], data=[field("n", 1)])
    transition = main.transitions[0]
    moved = transition.__class__(**{**{k: getattr(transition, k) for k in
                                       transition.__dataclass_fields__},
                                    "assignments": (Assignment(
                                        target="n", text="n + 10",
                                        expression=parse_expression("n + 10")),)})
    main = main.__class__(**{**{k: getattr(main, k) for k in main.__dataclass_fields__},
                             "transitions": (moved, *main.transitions[1:])})
    (trace, _summary, _metrics), ran = _three(monkeypatch, pkg(main, child))
    assert ran == {"main": 1, "child": 1}
    assert [e[8] for e in trace if e[1] == "data.changed" and e[2] == "child"] == [
        {"seen": 24}]


def test_a_zero_time_cycle_is_reported_the_same(monkeypatch: pytest.MonkeyPatch) -> None:
    """A loop of instantaneous activities: the plan writes the path out until it comes back
    to an activity already on it, then goes on in ``lone.run`` with the steps counted so
    far, so the zero-time guard stops the run at the same step with the same report."""
    cycle = proc("spin", ["s", act("a"), act("b", split="XOR"), "end"],
                 [("s", "a"), ("a", "b"), ("b", "a", "n < 1"), ("b", "end", "otherwise")],
                 data=[field("n", 0)])
    reports = []
    for way in WAYS:
        _way(monkeypatch, way)
        with pytest.raises(OpspecError) as raised:
            Simulation(_compiled(pkg(cycle), way), keep_trace=True).run(until=10.0)
        reports.append(str(raised.value))
    assert reports[0] == reports[1] == reports[2]
    assert "stopped advancing" in reports[0]


def test_a_token_that_reaches_a_waiting_activity_gets_its_frame(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A start, an assignment, then a manual activity: the instance gets its frame there;
    a performer answering later completes it as on the general path."""

    work = proc("work", [act("set", assign=[("n", "n + 1")]), manual("do"), "end"],
                [("set", "do"), ("do", "end")], data=[field("n", 0)])
    (trace, _summary, _metrics), ran = _three(monkeypatch, pkg(work),
                                              performers={"user": AnswersLater()})
    assert ran == {"work": 1}
    assert [e[0] for e in trace if e[1] == "process.completed"] == [5.0]


def test_what_is_lone_only_on_some_runs_is_handed_over(monkeypatch: pytest.MonkeyPatch
                                                       ) -> None:
    """A task is lone unless a performer is bound to its application on this run, and every
    activity waits for a worker with the pooled processor: the plan checks both per run."""

    class Echo:
        applications = {"horn": None}       # bound to the application (PerformerRegistry)

        def attach(self, session: Any) -> None:
            self.session = session

        def offer(self, item: Any) -> None:
            self.session.call_later(2.0, lambda: self.session.complete(item))

        def withdraw(self, item: Any, reason: str) -> None:
            pass

    work = pkg(proc("work", [act("set", assign=[("n", "n + 1")]), task("beep", "horn"),
                             "end"], [("set", "beep"), ("beep", "end")], data=[field("n", 0)]),
               applications=[app("horn")])
    ends = []
    for kwargs in ({}, {"performers": {"device": Echo()}},
                   {"config": EngineConfig(processor_model="pooled")}):
        (trace, summary, _metrics), ran = _three(monkeypatch, work, **kwargs)
        assert ran == {"work": 1}
        assert summary["instances"]["completed"] == 1
        ends += [e[0] for e in trace if e[1] == "process.completed"]
    assert ends[:2] == [0.0, 2.0]           # the bound horn answers after 2 s


def test_plans_are_made_once_per_package_and_only_from_source(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(plans, "COMPILED", True)
    compiled = compile_package(pkg(_caller(), lookup_subflow()))
    plans.attach(compiled)
    assert not compiled.plans and _planless(Simulation(compiled))
    monkeypatch.setattr(plans, "COMPILED", False)
    plans.attach(compiled)
    made = {pid: proc_.plan for pid, proc_ in compiled.processes.items()}
    assert all(made.values()) and set(made) == {"main", "lookup"}
    assert "def plan(inst, activities, _unused):" in (made["lookup"].__doc__ or "")
    Simulation(compiled)                    # a second run: the same plans
    assert {pid: proc_.plan for pid, proc_ in compiled.processes.items()} == made


def test_a_failing_actual_parameter_of_an_asynchronous_start_aborts_the_same_way(
        monkeypatch: pytest.MonkeyPatch) -> None:
    child = proc("child", ["c"], formals=[formal("n", "IN")])
    main = proc("main", [subflow("go", "child", ["missing + 1"], asynchronous=True), "end"],
                [("go", "end")])
    (_trace, summary, _metrics), ran = _three(monkeypatch, pkg(main, child))
    assert ran == {"main": 1}
    assert "an actual parameter failed" in summary["faults"][0]["message"]


def test_no_text_of_the_spec_reaches_a_plans_source(monkeypatch: pytest.MonkeyPatch) -> None:
    """A plan is Python made by ``exec``: what the spec names (activity, lane, participant
    and field ids, assigned values, conditions) must reach it as objects bound by name,
    never as source text, or a spec could run code of its own. Ids and a field written to
    break out of a string literal or a line run the same three ways, and the plan's source
    contains none of them."""
    evil = "x'\"); __import__('os').system('echo owned') #\n"
    ids = [f"set{evil}", f"split{evil}", f"low{evil}", f"high{evil}"]
    target = f"f{evil}"
    work = proc(f"work{evil}",
                [act(ids[0], assign=[(target, '"a\\" }{ \\n"'), ("n", "n + 1")]),
                 act(ids[1], split="XOR"), act(ids[2]), act(ids[3]), "end"],
                [(ids[0], ids[1]), (ids[1], ids[2], "n > 5"), (ids[1], ids[3], "otherwise"),
                 (ids[2], "end"), (ids[3], "end")],
                data=[field(target, ""), field("n", 0)])
    (trace, _summary, _metrics), ran = _three(monkeypatch, pkg(work))
    assert ran == {f"work{evil}": 1}
    assert [e[4] for e in trace if e[1] == "activity.started"][:3] == [ids[0], ids[1], ids[3]]
    _way(monkeypatch, "plan")
    compiled = _compiled(pkg(work), "plan")
    process = compiled.processes[f"work{evil}"]
    source = plans.build(process, process.one_start).__doc__ or ""
    assert "owned" not in source and "__import__" not in source and "def plan" in source
