"""The constructs issue 16 lists, one spec each in ``specs/c_*.xpdl``; every test asserts what
XPDL 2.1 / BPMN 2.0 (or the cited definition, in the spec file's comment) implies."""

from __future__ import annotations

import pytest
from patternlib import done, dump, events, first, outcomes, run, when


def test_implicit_termination_with_parallel_work_going_on() -> None:
    """A path that reaches an activity with no outgoing transition ends that path only."""
    result = run("p11_implicit_termination.xpdl")
    assert first(result, "B") == 1.0 and first(result, "D") == 4.0, dump(result)
    assert [e.time for e in events(result, "process.completed")] == [4.0]


def test_n_out_of_m_join_fires_once_when_n_branches_are_done() -> None:
    """Complex join, Route IncomingCondition="activationCount >= 2" (2 out of 3)."""
    result = run("c_n_out_of_m_join.xpdl")
    assert done(result).count("E") == 1, dump(result)
    assert first(result, "E", "activity.started") == first(result, "C") == 2.0
    assert first(result, "D") == 3.0                   # the third branch still runs, ignored
    assert outcomes(result, "n_out_of_m") == ["completed"]


@pytest.mark.parametrize(("need", "fires_at"), [(3, 3.0), (2, 2.0), (1, 1.0)])
def test_complex_gateway_activation_condition_over_data(need: int, fires_at: float) -> None:
    result = run("c_complex_gateway.xpdl", params={"need": need})
    assert done(result).count("E") == 1, dump(result)
    assert first(result, "E", "activity.started") == fires_at
    assert outcomes(result, "complex") == ["completed"]


# (file, A start times, B start times): A takes 2 s, B 1 s, three instances
MI = {
    "parallel_all": ([0, 0, 0], [2]),
    "parallel_one": ([0, 0, 0], [2]),
    "parallel_complex": ([0, 0, 0], [2]),
    "parallel_none": ([0, 0, 0], [2, 2, 2]),
    "sequential_all": ([0, 2, 4], [6]),
    "sequential_one": ([0, 2, 4], [2]),
    "sequential_complex": ([0, 2, 4], [4]),
    "sequential_none": ([0, 2, 4], [2, 4, 6]),
}


@pytest.mark.parametrize("case", list(MI))
def test_multi_instance_loop_ordering_and_flow_condition(case: str) -> None:
    a_starts, b_starts = MI[case]
    result = run(f"c_mi_{case}.xpdl")
    assert when(result, "A", "activity.started") == a_starts, dump(result)
    assert done(result).count("A") == 3               # every instance runs to its end
    assert when(result, "B", "activity.started") == b_starts, dump(result)
    assert outcomes(result, "mi") == ["completed"]


def test_conditional_flows_without_a_split_take_every_true_one() -> None:
    result = run("c_conditional_flows.xpdl")
    assert sorted(done(result)) == ["A", "B", "C"], dump(result)
    assert first(result, "B") == first(result, "C") == 2.0       # concurrently, not in sequence


def test_condition_text_beside_an_empty_expression_is_the_condition() -> None:
    result = run("c_condition_beside_empty_expression.xpdl")
    assert done(result) == ["A", "C"], dump(result)


def test_every_tool_of_an_activity_runs_in_order() -> None:
    result = run("c_tools_in_order.xpdl")
    changes = [e.data.get("x") for e in events(result, "data.changed", activity="A")]
    assert changes == [2, 20], dump(result)
    assert done(result) == ["A", "big"]


def test_timer_repeating_interval_r3_pt7s_fires_three_times_7_s_apart() -> None:
    result = run("c_timers.xpdl", until=100)
    starts = [e.time for e in events(result, "process.started", process="cycle")]
    assert len(starts) == 3, dump(result)
    assert [b - a for a, b in zip(starts, starts[1:])] == [7.0, 7.0]
    assert outcomes(result, "cycle") == ["completed"] * 3


def test_intermediate_timer_time_cycle_waits_its_duration() -> None:
    result = run("c_timers.xpdl", until=100)
    assert first(result, "w1") - first(result, "w0") == 7.0, dump(result)


def test_timer_time_date_fires_once_at_that_date() -> None:
    result = run("c_timedate.xpdl", until=3 * 86400)
    assert [e.time for e in events(result, "process.started")] == [30.0], dump(result)


def test_a_message_is_delivered_to_one_waiting_catcher() -> None:
    result = run("c_messages.xpdl", until=100)
    got = [a for a in ("r1_work", "r2_work") if a in done(result)]
    assert len(got) == 1, dump(result)
    assert first(result, got[0]) == 2.0


def test_a_signal_is_broadcast_to_every_catcher() -> None:
    result = run("c_messages.xpdl", until=100)
    assert first(result, "r1_heard") == first(result, "r2_heard") == 4.0, dump(result)


def test_a_message_thrown_before_the_receiver_waits_is_kept_until_caught() -> None:
    result = run("c_messages.xpdl", until=100)
    assert first(result, "lr_got") == 11.0, dump(result)
    assert outcomes(result, "late_receiver") == ["completed"]


def test_bounded_synchronous_recursion_runs_to_its_base_case() -> None:
    result = run("c_recursion.xpdl")
    count = result.instances("count")
    assert len(count) == 4 and {i.outcome for i in count} == {"completed"}, dump(result)
    assert done(result).count("base") == 1 and done(result).count("recurse") == 3
    # each callee completes before its caller (synchronous)
    ends = [i.ended for i in count]
    assert ends == sorted(ends, reverse=True) or len(set(ends)) == 1
    assert outcomes(result, "main") == ["completed"] and first(result, "after_call") == 4.0


def test_an_instance_ended_by_its_end_trigger_does_nothing_afterwards() -> None:
    result = run("c_end_trigger.xpdl", script=[("50", "B")], until=300)
    assert outcomes(result, "worker") == ["terminated"], dump(result)
    end = events(result, "process.terminated", process="worker")[0].time
    assert end == 5.0
    assert [e.time for e in events(result, "activity.withdrawn", activity="B")] == [5.0]
    after = [e for e in result.trace if e.process == "worker" and e.time > end]
    assert not after, dump(result)
    assert not [e for e in events(result, "trigger.raised") if e.data.get("name") == "never"]


def test_array_data_flow_into_vector_superposition() -> None:
    result = run("c_vector_superposition.xpdl")
    changes = [e.data["out"] for e in events(result, "data.changed", activity="combine")]
    assert changes and list(changes[-1]) == [21.0, 42.0], dump(result)
