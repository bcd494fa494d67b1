"""The waiting activities' path kept the same where it was made cheaper from source.

A deferred choice's branches (the manual ones offered as one work item's ``choices``, the
catch events that race it) are worked out once per deciding activity and run
(``Offers.choices_of``); the work items of one instance share one read-only view of its data.
These tests hold both to what working everything out at every offer gives.
"""

from __future__ import annotations

from typing import Any

import pytest
from builders import catch, field, manual, pkg, proc, route
from engine_runs import events

from opspec.engine.builtin_performers import ScriptedUser
from opspec.engine.compiled import compile_package
from opspec.engine.offers import Offers
from opspec.engine.simulation import RunResult, Simulation
from opspec.model import Package


class _Forgetful(dict[Any, Any]):
    """A cache that keeps nothing: every offer works its branches out again."""

    def __setitem__(self, key: Any, value: Any) -> None:
        pass


def _choices_model() -> Package:
    # two workflows whose deciding activities share their ids (``g``) but not their
    # branches; each decides three times (a cycle back to ``g``); ``q``'s choice also
    # races a timer event that never wins (the user answers at once)
    loop = [("l", "x"), ("r", "x"), ("x", "g", "n < 3"), ("x", "done", "otherwise")]
    p = proc("p", ["a", route("g", "EVENT", join="XOR"),
                   manual("l", assign=[("n", "n + 1")]), manual("r", assign=[("n", "n + 1")]),
                   route("x", split="XOR"), "done"],
             [("a", "g"), ("g", "l"), ("g", "r"), *loop], data=[field("n", 0)])
    q = proc("q", ["a", route("g", "EVENT", join="XOR"),
                   manual("r", assign=[("n", "n + 1")]), catch("late", "timer", seconds=50.0),
                   manual("l", assign=[("n", "n + 1")]), route("x", split="XOR"), "done"],
             [("a", "g"), ("g", "r"), ("g", "late"), ("g", "l"), ("late", "done"), *loop],
             data=[field("n", 0)])
    return pkg(p, q)


def _run(package: Any, *, forget: bool) -> tuple[RunResult, ScriptedUser]:
    user = ScriptedUser(default="complete")
    sim = Simulation(package, performers={"user": user}, keep_trace=True)
    if forget:
        offers = getattr(sim, "offers", None)
        assert isinstance(offers, Offers)
        offers.choices_of = _Forgetful()
    return sim.run(until=1000.0), user


def _trace(result: RunResult) -> list[tuple[Any, ...]]:
    assert result.trace is not None
    return [(e.time, e.kind, e.process, e.instance, e.activity, dict(e.data), e.seq)
            for e in result.trace]


def test_a_deferred_choice_offers_its_own_branches_every_time() -> None:
    """WCP-16 Deferred Choice: "A point in a process where one of several branches is chosen
    based on interaction with the operating environment. Prior to the decision, all branches
    represent possible future courses of execution." (Russell, ter Hofstede, van der Aalst,
    Mulyar, Workflow Control-Flow Patterns: A Revised View, 2006.) Each decision offers the
    manual branches of *its* activity, in their declared order, however often it is reached
    and whichever other workflow has an activity of the same id."""
    result, user = _run(compile_package(_choices_model()), forget=False)
    offered = [(item.process, item.activity, item.choices) for item in user.offers]
    # (both instances start at 0 s and the user answers at once: their decisions alternate)
    assert offered == [("p", "g", ("l", "r")), ("q", "g", ("r", "l"))] * 3
    # the first branch is taken each time; the racing timer never fires
    for name in ("p", "q"):
        done = [e.activity for e in events(result, "activity.completed", process=name)]
        assert done.count("l" if name == "p" else "r") == 3 and done[-1] == "done"
    assert not events(result, "activity.completed", activity="late")
    assert result.summary["instances"]["completed"] == 2


@pytest.mark.parametrize("runs", [1, 2])
def test_choices_worked_out_once_give_the_trace_of_choices_worked_out_every_time(
        runs: int) -> None:
    """The same trace events (time, kind, ids, data, sequence) with the cached choices as
    with a cache that keeps nothing, on one compiled package run once and run again."""
    compiled = compile_package(_choices_model())
    for _ in range(runs):
        cached, _user = _run(compiled, forget=False)
    fresh, _user = _run(compiled, forget=True)
    assert _trace(cached) == _trace(fresh)
    assert cached.summary == fresh.summary


def test_the_work_items_of_one_instance_show_its_data_read_only_and_live() -> None:
    """Every work item of an instance shows that instance's data fields as they are now
    (one shared view), and a performer cannot write them through it."""
    model = pkg(proc("p", [manual("one", assign=[("n", "n + 1")]),
                           manual("two", assign=[("n", "n + 10")]), "end"],
                     [("one", "two"), ("two", "end")], data=[field("n", 0)]),
                proc("q", [manual("three"), "end"], [("three", "end")],
                     data=[field("n", 100)]))
    user = ScriptedUser(default="complete")
    Simulation(model, performers={"user": user}, keep_trace=True).run(until=10.0)
    items = {item.activity: item for item in user.offers}
    assert set(items) == {"one", "two", "three"}
    assert items["one"].data["n"] == items["two"].data["n"] == 11
    assert items["three"].data["n"] == 100
    with pytest.raises(TypeError):
        items["one"].data["n"] = 5          # type: ignore[index]
