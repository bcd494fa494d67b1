"""Trace predicates: what holds, what fails, and what a failure shows."""

from __future__ import annotations

import pytest

from opspec.engine.compiled import CompiledPackage
from opspec.engine.trace import TraceEvent
from opspec.errors import ConfigurationError
from opspec.testing.predicates import (
    activity_completed,
    check,
    count,
    event,
    eventually,
    happens_before,
    holds,
    never,
    per_instance,
    process_started,
    trigger_raised,
    within,
)
from opspec.testing.simulation import SimulationResult


def test_a_user_reporting_90_s_after_the_alarm_responds_within_90_but_not_60_seconds(
        prompt_user: SimulationResult) -> None:
    assert holds(prompt_user, within("sound_alarm", "press_report", 90))
    assert not holds(prompt_user, within("sound_alarm", "press_report", 60))


@pytest.mark.parametrize("predicate, expected", [
    (happens_before("sound_alarm", "press_report"), True),
    (happens_before("press_report", "sound_alarm"), False),
    (happens_before("trg_2", "dispense", each=True), True),
    (eventually("dispense"), True),
    (activity_completed("dispense", process="notify_workflow"), True),
    (activity_completed("dispense", process="user_workflow"), False),
    (never("notify_caregiver"), True),
    (never("dispense"), False),
    (count("sound_alarm") == 1, True),
    (count("sound_alarm") == 2, False),
    (count("sound_alarm").between(1, 3), True),
    (count("dispense").at_least(2), False),
    (count(trigger_raised("trg_1")).at_most(1), True),
    ((count("dispense") == 1).per_instance("notify_workflow"), True),
    (per_instance("user_workflow", never("dispense")), True),
    (never("dispense") | eventually("press_report"), True),
    (never("dispense") & eventually("press_report"), False),
    ((never("dispense") | eventually("press_report")) & never("notify_caregiver"), True),
    (never("notify_caregiver") & (never("dispense") | never("press_report")), False),
    (~never("dispense"), True),
    (~happens_before("sound_alarm", "dispense"), False),
    (event("activity.offered", activity="take_pill"), True),
    (process_started("notify_workflow"), True),
    (within(lambda e: e.kind == "trigger.raised", "activity:dispense", 60), False),
], ids=lambda x: x if isinstance(x, bool) else repr(x))
def test_predicates_on_a_prompt_user(prompt_user: SimulationResult, predicate: object,
                                     expected: bool) -> None:
    assert holds(prompt_user, predicate) is expected  # type: ignore[arg-type]


def test_a_user_who_never_reports_gets_the_caregiver_within_15_minutes_of_the_dose(
        absent_user: SimulationResult) -> None:
    check(absent_user, within("process:notify_workflow", "notify_caregiver", 15 * 60),
          count("sound_alarm") == 3, never("dispense"),
          happens_before("record_missed", "notify_caregiver"))


def test_a_failed_within_shows_the_violation_and_the_next_response_not_the_whole_trace(
        prompt_user: SimulationResult) -> None:
    with pytest.raises(AssertionError) as info:
        check(prompt_user, within("sound_alarm", "press_report", 60))
    text = str(info.value)
    assert text.startswith("expected within(sound_alarm, press_report, 60 s)")
    assert ("activity sound_alarm at d1 08:00:00 was not followed by activity press_report within 1 min; "
            "the next came at d1 08:01:30, 1.5 min after it") in text
    marked = [line for line in text.splitlines() if line.startswith(">")]
    assert len(marked) == 2 and "sound_alarm" in marked[0] and "press_report" in marked[1]
    assert len([line for line in text.splitlines() if "d1 " in line]) <= 16
    assert len(prompt_user.trace) > 50            # the trace is much longer than the slice
    assert "(seed 0, 1 replication(s))" in text


def test_a_failed_never_marks_the_first_occurrence(prompt_user: SimulationResult) -> None:
    with pytest.raises(AssertionError, match=r"dispense happened at "
                                             r"d1 08:01:30") as info:
        check(prompt_user, never("dispense"))
    assert next(line for line in str(info.value).splitlines() if line.startswith(">")).endswith(
        "activity.completed   dispense")


def test_a_failed_per_instance_names_the_instance(absent_user: SimulationResult) -> None:
    with pytest.raises(AssertionError, match=r"in notify_workflow instance #2 \(started d1 "
                                             r"08:00:00\):\n  but activity sound_alarm happened 3 time"):
        check(absent_user, per_instance("notify_workflow", count("sound_alarm") <= 2))


def test_a_failed_alternative_lists_why_each_part_failed(prompt_user: SimulationResult) -> None:
    with pytest.raises(AssertionError, match="none of the alternatives holds:\n"
                       r".*count\(sound_alarm\) == 2: but activity sound_alarm happened 1 time"):
        check(prompt_user, (count("sound_alarm") == 2) | never("dispense"))


@pytest.mark.parametrize("predicate, listed", [
    (within("sound_alarm", "press_reprt", 60), "press_report"),
    (never("activity:trg_2"), "dispense"),
    (count(trigger_raised("trg_9")) == 0, "trg_2, trg_1"),
    (per_instance("notify", never("dispense")), "notify_workflow"),
], ids=["misspelt-activity", "trigger-named-as-activity", "unknown-trigger", "unknown-process"])
def test_a_name_the_spec_lacks_fails_listing_the_names_it_has(
        prompt_user: SimulationResult, predicate: object, listed: str) -> None:
    with pytest.raises(ConfigurationError, match="the spec has no") as info:
        holds(prompt_user, predicate)  # type: ignore[arg-type]
    assert listed in str(info.value)


def test_predicates_work_on_plain_event_lists_without_a_spec() -> None:
    trace = [TraceEvent(0.0, "activity.completed", "p", 1, "a", seq=1),
             TraceEvent(5.0, "activity.completed", "p", 1, "b", seq=2),
             TraceEvent(100.0, "activity.completed", "p", 1, "a", seq=3),
             TraceEvent(200.0, "activity.completed", "p", 1, "b", seq=4)]
    assert holds(trace, happens_before("a", "b", each=True))
    assert holds(trace, within("a", "b", 100)) and not holds(trace, within("a", "b", 99))
    assert holds(trace, count("a") == 2) and holds(trace, never("c"))
    assert not holds(trace[1:], happens_before("a", "b"))


def test_a_cause_whose_window_outlives_the_run_is_not_judged() -> None:
    trace = [TraceEvent(0.0, "activity.completed", "p", 1, "a", seq=1),
             TraceEvent(50.0, "activity.completed", "p", 1, "x", seq=2)]
    assert holds(trace, within("a", "b", 60))
    assert not holds(trace, within("a", "b", 40))


def test_predicates_judge_every_replication(dispenser: object) -> None:
    from opspec.testing.simulation import simulate

    result = simulate(dispenser, users=3, days=1,  # type: ignore[arg-type]
                      script=[("never", "press_report")])
    assert holds(result, count("notify_caregiver") == 4)
    with pytest.raises(AssertionError, match=r"expected count\(dispense\) >= 1 \(replication 0\)"):
        check(result, count("dispense") >= 1)


def test_an_engine_run_result_is_judged_and_checked_against_spec_when_given(
        dispenser: CompiledPackage) -> None:
    from opspec.engine.simulation import Simulation
    from opspec.testing.script import parse_script

    user = parse_script([("after trg_2 30s", "press_report")]).performer()
    run = Simulation(dispenser, performers={"user": user}, listeners=[user],
                     keep_trace=True).run(until=9 * 3600.0)
    assert holds(run, within("sound_alarm", "dispense", 30))
    assert holds(run, never("no_such_activity"))                 # no spec: nothing to check
    with pytest.raises(ConfigurationError, match="no activity, trigger or process 'no_such"):
        holds(run, never("no_such_activity"), spec=dispenser)
