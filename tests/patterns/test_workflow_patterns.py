"""Workflow patterns 1-20 (van der Aalst, ter Hofstede, Kiepuszewski, Barros 2003, "Workflow
Patterns", workflowpatterns.com), one standard XPDL 2.1 spec each in ``specs/``.

Every test asserts the trace the published definition implies (quoted in the spec file's
comment): which activities ran, how often, in what (partial) order, when durations make the
order observable, and how the instance ended. Where the definition allows several behaviours
only the invariant is asserted. Issue 16.
"""

from __future__ import annotations

import pytest
from patternlib import done, dump, events, first, outcomes, run, started, when


def test_wcp01_sequence() -> None:
    result = run("p01_sequence.xpdl")
    assert done(result) == ["A", "B", "C"], dump(result)
    assert [first(result, a, "activity.started") for a in "ABC"] == [0.0, 1.0, 2.0]
    assert outcomes(result, "sequence") == ["completed"]


def test_wcp02_parallel_split_starts_both_branches_at_once() -> None:
    result = run("p02_parallel_split.xpdl")
    assert sorted(done(result)).count("B") == 1 and done(result).count("C") == 1
    # both threads are enabled together when A completes; they run concurrently
    assert first(result, "B", "activity.started") == first(result, "C", "activity.started") == 1.0
    assert first(result, "C") == 2.0 and first(result, "B") == 3.0
    assert outcomes(result, "parallel_split") == ["completed"]


def test_wcp03_synchronization_waits_for_every_branch_once() -> None:
    result = run("p03_synchronization.xpdl")
    assert done(result).count("D") == 1, dump(result)
    assert first(result, "D", "activity.started") == max(first(result, "B"), first(result, "C")) == 3.0
    assert outcomes(result, "synchronization") == ["completed"]


@pytest.mark.parametrize(("x", "taken", "not_taken"), [(10, "B", "C"), (1, "C", "B")])
def test_wcp04_exclusive_choice_takes_exactly_one_branch(x: int, taken: str, not_taken: str) -> None:
    result = run("p04_exclusive_choice.xpdl", params={"x": x})
    assert done(result).count(taken) == 1 and not_taken not in started(result), dump(result)
    assert outcomes(result, "choice") == ["completed"]


@pytest.mark.parametrize(("x", "branch"), [(10, "B"), (1, "C")])
def test_wcp05_simple_merge_runs_the_next_activity_once_after_the_chosen_branch(
        x: int, branch: str) -> None:
    result = run("p05_simple_merge.xpdl", params={"x": x})
    assert done(result).count("D") == 1, dump(result)
    assert first(result, "D", "activity.started") == first(result, branch)
    assert outcomes(result, "simple_merge") == ["completed"]


def test_wcp06_multi_choice_runs_every_branch_whose_condition_holds() -> None:
    result = run("p06_multi_choice.xpdl")          # x = 5: x > 1 and x > 2 hold, x > 100 not
    assert done(result).count("B") == 1 and done(result).count("C") == 1, dump(result)
    assert "D" not in started(result)
    assert first(result, "B", "activity.started") == first(result, "C", "activity.started")


def test_wcp07_synchronizing_merge_waits_for_the_activated_branches_only() -> None:
    result = run("p07_synchronizing_merge.xpdl")
    assert done(result).count("E") == 1, dump(result)
    # waits for C (the slower activated branch), not for D (never activated)
    assert first(result, "E", "activity.started") == first(result, "C") == 4.0
    assert outcomes(result, "sync_merge") == ["completed"]
    assert not events(result, "deadlock")


def test_wcp07_synchronizing_merge_with_one_branch_does_not_wait() -> None:
    result = run("p07_synchronizing_merge.xpdl", params={"x": 2})    # only x > 1
    assert done(result).count("E") == 1 and "C" not in started(result), dump(result)
    assert first(result, "E", "activity.started") == first(result, "B") == 2.0


def test_wcp08_multi_merge_runs_the_following_activities_once_per_incoming_thread() -> None:
    result = run("p08_multi_merge.xpdl")
    assert done(result).count("D") == 2 and done(result).count("E") == 2, dump(result)
    # the first D does not wait for C: it starts when B completes
    assert when(result, "D", "activity.started") == [first(result, "B"), first(result, "C")]
    assert outcomes(result, "multi_merge") == ["completed"]


def test_wcp09_discriminator_fires_once_on_the_first_branch_and_ignores_the_rest() -> None:
    result = run("p09_discriminator.xpdl")
    assert done(result).count("E") == 1, dump(result)
    assert first(result, "E", "activity.started") == first(result, "B") == 1.0
    assert first(result, "E") < first(result, "C")          # did not wait for the others
    assert [done(result).count(a) for a in "BCD"] == [1, 1, 1]   # which still ran to the end
    assert outcomes(result, "discriminator") == ["completed"]


@pytest.mark.parametrize(("skip", "b_runs"), [(False, 3), (True, 2)])
def test_wcp10_arbitrary_cycle_entered_at_either_point_repeats_until_its_exit(
        skip: bool, b_runs: int) -> None:
    result = run("p10_arbitrary_cycles.xpdl", params={"skip": skip})
    order = done(result)
    assert order.count("C") == 3 and order.count("B") == b_runs and order.count("D") == 1, order
    assert order[-1] == "D" and order[0] == "A"
    assert order[1] == ("C" if skip else "B")
    assert outcomes(result, "cycles") == ["completed"]


def test_wcp11_implicit_termination_ends_a_path_only_and_the_case_when_nothing_is_left() -> None:
    result = run("p11_implicit_termination.xpdl")
    assert first(result, "B") == 1.0                 # B's path ends here; C and D go on
    assert first(result, "D") == 4.0, dump(result)
    ends = events(result, "process.completed")
    assert len(ends) == 1 and ends[0].time == 4.0
    assert not events(result, "deadlock")


def test_wcp12_mi_without_synchronization_lets_each_instance_go_on_alone() -> None:
    result = run("p12_mi_without_synchronization.xpdl")
    assert done(result).count("A") == 3 and done(result).count("B") == 3, dump(result)
    # no synchronisation: the first B starts before the last instance of A has completed
    assert first(result, "B", "activity.started") < max(when(result, "A"))
    assert outcomes(result, "mi_nosync") == ["completed"]


def test_wcp13_mi_with_design_time_knowledge_runs_n_instances_then_synchronizes() -> None:
    result = run("p13_mi_design_time.xpdl")
    assert when(result, "A", "activity.started") == [0.0, 0.0, 0.0], dump(result)
    assert done(result).count("B") == 1
    assert first(result, "B", "activity.started") == max(when(result, "A")) == 2.0
    assert outcomes(result, "mi_design") == ["completed"]


@pytest.mark.parametrize("k", [3, 1])
def test_wcp14_mi_with_run_time_knowledge_runs_as_many_instances_as_the_case_says(k: int) -> None:
    result = run("p14_mi_run_time.xpdl", params={"k": k})
    assert len(when(result, "A", "activity.started")) == k + 1, dump(result)
    assert done(result).count("B") == 1
    assert first(result, "B", "activity.started") >= max(when(result, "A"))


def test_wcp15_mi_without_a_priori_knowledge_creates_instances_while_others_run() -> None:
    script = [("1", "ask more=true"), ("1", "ask more=true"), ("1", "ask more=false")]
    result = run("p15_mi_no_a_priori.xpdl", script=script)
    works = when(result, "work", "activity.started")
    assert len(works) == 3 and done(result).count("work") == 3, dump(result)
    assert works[1] < first(result, "work")          # a new instance while the first runs
    ends = events(result, "process.completed")
    assert len(ends) == 1 and ends[0].time == max(when(result, "work")) == 10.0


@pytest.mark.parametrize(("script", "chosen", "other"),
                         [([("3", "choose C")], "C", "B"), ([("2", "choose B")], "B", "C")])
def test_wcp16_deferred_choice_runs_only_the_alternative_the_environment_takes(
        script: list, chosen: str, other: str) -> None:
    result = run("p16_deferred_choice.xpdl", script=script)
    assert done(result).count(chosen) == 1 and other not in done(result), dump(result)
    offer = events(result, "activity.offered", activity="choice")
    assert offer and sorted(offer[0].data["choices"]) == ["B", "C"]   # both were offered
    assert done(result).count("D") == 1
    assert outcomes(result, "deferred") == ["completed"]


def test_wcp17_interleaved_parallel_routing_runs_each_once_never_two_at_a_time() -> None:
    result = run("p17_interleaved_parallel_routing.xpdl")
    spans = sorted((first(result, a, "activity.started"), first(result, a)) for a in "BCD")
    assert [done(result).count(a) for a in "BCD"] == [1, 1, 1], dump(result)
    assert all(end <= start for (_, end), (start, _) in zip(spans, spans[1:])), spans
    assert first(result, "E", "activity.started") >= spans[-1][1] == 7.0


def test_wcp18_milestone_enables_d_only_after_b_and_while_the_milestone_holds() -> None:
    result = run("p18_milestone.xpdl", script=[("4", "D")])
    assert first(result, "D") == 10.0 and "expire" not in done(result), dump(result)
    assert min(e.time for e in events(result, "activity.offered")) >= first(result, "B")
    assert outcomes(result, "milestone") == ["completed"]


def test_wcp18_milestone_expired_d_is_no_longer_enabled() -> None:
    result = run("p18_milestone.xpdl", script=[("20", "D")])
    assert "D" not in done(result) and first(result, "expire") == 16.0, dump(result)
    assert done(result).count("F") == 1
    assert outcomes(result, "milestone") == ["completed"]


def test_wcp19_cancel_activity_withdraws_the_enabled_activity() -> None:
    result = run("p19_cancel_activity.xpdl", script=[("50", "B")])
    assert "B" not in done(result), dump(result)
    withdrawn = events(result, "activity.withdrawn", activity="B")
    assert len(withdrawn) == 1 and withdrawn[0].time == 5.0
    assert done(result).count("C") == 1 and first(result, "C") == 5.0


def test_wcp19_cancel_activity_case_completes_after_the_cancellation_path() -> None:
    result = run("p19_cancel_activity.xpdl", script=[("50", "B")])
    assert outcomes(result, "cancel_activity") == ["completed"], dump(result)


def test_wcp20_cancel_case_removes_the_whole_instance() -> None:
    result = run("p20_cancel_case.xpdl", script=[("50", "B")], until=300)
    assert outcomes(result, "cancel_case") == ["terminated"], dump(result)
    end = events(result, "process.terminated")[0].time
    assert end == 5.0
    assert not [a for a in ("B", "L", "after_B", "after_L") if a in done(result)]
    assert not [e for e in result.trace if e.instance is not None and e.time > end], dump(result)
    assert [e.time for e in events(result, "activity.withdrawn", activity="B")] == [5.0]
