"""The basic workflow-control patterns, under both processor models."""

from __future__ import annotations

from builders import act, catch, field, manual, pkg, proc, route
from engine_runs import before, completed, events, run

from opspec.engine.builtin_performers import ScriptedUser
from opspec.engine.config import EngineConfig


def test_sequence_runs_activities_in_order(config: EngineConfig) -> None:
    result = run(pkg(proc("p", ["a", "b", "c"], [("a", "b"), ("b", "c")])), config=config)
    assert completed(result) == ["a", "b", "c"]
    assert result.summary["instances"]["completed"] == 1


def test_parallel_split_and_synchronisation_merge_once_after_both_branches(
        config: EngineConfig) -> None:
    model = pkg(proc("p", [act("a", split="AND"), "b", act("c", cpu=0.5), act("d", join="AND"),
                           "e"],
                     [("a", "b"), ("a", "c"), ("b", "d"), ("c", "d"), ("d", "e")]))
    result = run(model, config=config)
    done = completed(result)
    assert done.count("d") == 1 and done.count("e") == 1
    assert before(done, "b", "d") and before(done, "c", "d")
    # the last arriving branch (c, 0.5 s of CPU) performs the merge
    assert events(result, "activity.started", activity="d")[0].time >= 0.5


def test_exclusive_choice_takes_first_condition_that_holds_in_declared_order(
        config: EngineConfig) -> None:
    model = pkg(proc("p", [route("x", split="XOR", order=["p_1_x_b", "p_0_x_a"]), "a", "b",
                           "c"],
                     [("x", "a", "n > 0"), ("x", "b", "n > 1"), ("x", "c", "otherwise")],
                     data=[field("n", 5)]))
    assert completed(run(model, config=config)) == ["x", "b"]


def test_exclusive_choice_falls_back_to_otherwise(config: EngineConfig) -> None:
    model = pkg(proc("p", [route("x", split="XOR"), "a", "c"],
                     [("x", "a", "n > 10"), ("x", "c", "otherwise")], data=[field("n", 5)]))
    assert completed(run(model, config=config)) == ["x", "c"]


def test_simple_merge_runs_the_merge_activity_once_per_arriving_branch(
        config: EngineConfig) -> None:
    model = pkg(proc("p", [route("x", split="XOR"), "a", "b", act("m", join="XOR"), "e"],
                     [("x", "a", "flag"), ("x", "b", "otherwise"), ("a", "m"), ("b", "m"),
                      ("m", "e")], data=[field("flag", True)]))
    assert completed(run(model, config=config)) == ["x", "a", "m", "e"]


def test_multi_choice_starts_every_branch_whose_condition_holds(config: EngineConfig) -> None:
    model = pkg(proc("p", [route("x", split="OR"), "a", "b", "c"],
                     [("x", "a", "n > 1"), ("x", "b", "n > 2"), ("x", "c", "n > 100")],
                     data=[field("n", 5)]))
    assert sorted(completed(run(model, config=config))) == ["a", "b", "x"]


def test_structured_synchronising_merge_waits_only_for_activated_branches(
        config: EngineConfig) -> None:
    model = pkg(proc("p", [route("x", split="OR"), act("a", cpu=1.0), act("b", cpu=2.0), "c",
                           route("j", join="OR"), "e"],
                     [("x", "a", "n > 1"), ("x", "b", "n > 2"), ("x", "c", "n > 100"),
                      ("a", "j"), ("b", "j"), ("c", "j"), ("j", "e")],
                     data=[field("n", 5)]))
    result = run(model, config=config)
    done = completed(result)
    assert done.count("j") == 1 and "c" not in done
    assert events(result, "activity.started", activity="j")[0].time >= 2.0
    assert result.summary["deadlocks"] == []


def test_or_join_with_a_single_activated_branch_fires_without_waiting(
        config: EngineConfig) -> None:
    model = pkg(proc("p", [route("x", split="OR"), "a", "b", route("j", join="OR"), "e"],
                     [("x", "a", "n > 1"), ("x", "b", "n > 100"), ("a", "j"), ("b", "j"),
                      ("j", "e")], data=[field("n", 5)]))
    assert completed(run(model, config=config))[-2:] == ["j", "e"]


def test_arbitrary_cycle_repeats_until_the_exit_condition_holds(config: EngineConfig) -> None:
    model = pkg(proc("p", ["s", act("a", join="XOR", assign=[("n", "n + 1")]),
                           route("x", split="XOR"), "b", "done"],
                     [("s", "a"), ("a", "x"), ("x", "b", "n < 3"), ("b", "a"),
                      ("x", "done", "otherwise")], data=[field("n", 0)]))
    assert completed(run(model, config=config)) == ["s", "a", "x", "b", "a", "x", "b", "a", "x",
                                                    "done"]


def test_and_join_inside_a_cycle_counts_per_iteration(config: EngineConfig) -> None:
    model = pkg(proc("p", ["go", act("s", join="XOR", split="AND", assign=[("n", "n + 1")]),
                           "a", act("b", cpu=0.1), act("j", join="AND"), route("x", split="XOR"),
                           "end"],
                     [("go", "s"), ("s", "a"), ("s", "b"), ("a", "j"), ("b", "j"), ("j", "x"),
                      ("x", "s", "n < 3"), ("x", "end", "otherwise")],
                     data=[field("n", 0)]))
    result = run(model, config=config)
    assert completed(result).count("j") == 3
    assert completed(result)[-1] == "end"


def test_deferred_choice_offers_one_item_and_the_performer_picks_a_branch(
        config: EngineConfig) -> None:
    model = pkg(proc("p", ["a", route("g", "EVENT"), manual("left"), manual("right"), "after"],
                     [("a", "g"), ("g", "left"), ("g", "right"), ("left", "after"),
                      ("right", "after")]))
    user = ScriptedUser([(5.0, "choose right")])
    result = run(model, performers={"user": user}, config=config)
    offered = events(result, "activity.offered", activity="g")
    assert len(offered) == 1 and offered[0].data["choices"] == ["left", "right"]
    assert completed(result)[-2:] == ["right", "after"]
    assert "left" not in completed(result)
    assert events(result, "activity.completed", activity="right")[0].time >= 5.0


def test_deferred_choice_on_xor_split_of_manual_branches_of_one_performer(
        config: EngineConfig) -> None:
    model = pkg(proc("p", [act("a", split="XOR"), manual("left"), manual("right")],
                     [("a", "left"), ("a", "right")]))
    user = ScriptedUser([(1.0, "choose left")])
    result = run(model, performers={"user": user}, config=config)
    assert [i.choices for i in user.offers] == [("left", "right")]
    assert completed(result) == ["a", "left"]


def test_event_based_gateway_takes_the_event_that_happens_first(config: EngineConfig) -> None:
    model = pkg(proc("p", [route("g", "EVENT"), catch("msg", "message", "go"),
                           catch("late", "timer", seconds=60.0), "x", "y"],
                     [("g", "msg"), ("g", "late"), ("msg", "x"), ("late", "y")]),
                proc("sender", [catch("wait", "timer", seconds=10.0),
                                act("send", raises="message:go")], [("wait", "send")]))
    result = run(model, config=config)
    assert "x" in completed(result, "p") and "y" not in completed(result, "p")


def test_cancel_activity_withdraws_the_offer_when_an_interrupting_event_fires(
        config: EngineConfig) -> None:
    model = pkg(proc("p", [manual("work"), catch("stop", "timer", seconds=30.0,
                                                  attached_to="work"), "done", "cancelled"],
                     [("work", "done"), ("stop", "cancelled")]))
    user = ScriptedUser([(100.0, "complete work")])
    result = run(model, performers={"user": user}, config=config)
    assert completed(result) == ["stop", "cancelled"]
    withdrawn = events(result, "activity.withdrawn", activity="work")
    assert len(withdrawn) == 1 and withdrawn[0].time == 30.0
    assert result.summary["stale_completions"] == 1
