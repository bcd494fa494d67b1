"""Executable tests of specs/medication_dispenser.xpdl (the reference scenario "dispenser-day").

They are written with the opspec pytest plugin (``spec`` / ``simulate`` fixtures, scripts as
plain data, ``expect`` lines) and read like the scenario: doses at 08:00, 12:00, 18:00 and
22:00, up to 3 alarms 300 s apart, then a miss and a call to the caregiver.
"""

from __future__ import annotations

from typing import Any

import pytest

from opspec.testing import (
    SimulationResult,
    assert_mean,
    assert_no_violations,
    assert_quantile,
    assert_rate,
    assert_rate_sequential,
    check,
    count,
    expect,
    happens_before,
    min_gap,
    never,
    per_instance,
    simulator_for,
    within,
)
from opspec.testing.simulation import derive_seed

SPEC = "../medication_dispenser.xpdl"
USERS = "../medication_dispenser.users.toml"
FIRST_DOSE_HOUR = 9 * 3600.0         # run to 09:00: only the 08:00 dose


def test_user_reporting_90_s_after_the_first_alarm_takes_the_dose(spec: Any,
                                                                   simulate: Any) -> None:
    result = simulate(spec, script=[("after trg_2 90s", "press_report")],
                      until=FIRST_DOSE_HOUR)
    expect(result, "doses_taken == 1", "report_latency_s.mean == 90", "alarms == 1",
           "never activity notify_caregiver",
           "activity dispense within 90s after trigger trg_2")


def test_user_who_never_reports_gets_three_alarms_a_miss_and_a_caregiver_call(
        spec: Any, simulate: Any) -> None:
    result = simulate(spec, script=[("never", "press_report")], until=FIRST_DOSE_HOUR)
    expect(result, "alarms == 3", "doses_missed == 1", "caregiver_notified == 1",
           "doses_taken == 0", "never activity dispense",
           "activity notify_caregiver within 15 min after process notify_workflow")
    (dose,) = result.instances("notify_workflow")
    alarms = [e.time for e in dose.events
              if e.kind == "activity.completed" and e.activity == "sound_alarm"]
    assert alarms == [8 * 3600.0, 8 * 3600.0 + 300, 8 * 3600.0 + 600]
    assert dose.outcome == "completed" and dose.completed("record_missed")


def test_a_user_who_reports_twice_for_one_dose_gets_one_dispense(spec: Any,
                                                                  simulate: Any) -> None:
    result = simulate(spec, script=[("at 08:00:30", "raise trg_1"), ("at 08:00:40", "raise trg_1"),
                                    ("never", "press_report")], until=FIRST_DOSE_HOUR)
    expect(result, "count activity dispense == 1", "doses_taken == 1")


@pytest.mark.parametrize("latencies", [(0, 0, 290, 10), (290, 10, 0, 0), (290, 290, 290, 290)],
                         ids=["late-evening-then-prompt-night", "late-morning-then-prompt-noon",
                              "always-late"])
def test_no_double_dose_within_the_smallest_legitimate_spacing(
        spec: Any, simulate: Any, latencies: tuple[int, ...]) -> None:
    # Doses are 4 h apart at the closest (08/12 and 18/22) and the device waits at most 15 min
    # for a report, so two dispenses closer than 3 h 45 min would be a double dose.
    script = [(f"after trg_2 {s}s", "press_report") for s in latencies]
    result = simulate(spec, script=script, days=2)
    expect(result, "never activity dispense twice within 3h45m", "doses_taken == 8")


@pytest.mark.xfail(strict=True, reason=(
    "spec finding: 'no dispense within 4 h of the previous one' does not hold - the 18:00 and "
    "22:00 (and 08:00/12:00) slots are exactly 4 h apart, so a late report for the first and a "
    "prompt one for the second dispense less than 4 h apart"))
def test_no_two_dispenses_within_4_hours(spec: Any, simulate: Any) -> None:
    script = [("after trg_2 0s", "press_report"), ("after trg_2 0s", "press_report"),
              ("after trg_2 290s", "press_report"), ("after trg_2 10s", "press_report")]
    expect(simulate(spec, script=script, days=1), "never activity dispense twice within 4h")


# ---------------------------------------------------------------- the reference user model
# 600 simulated users x 1 day = 2400 doses: the analytic miss rate is 0.35 % (0.15^3 of the
# alarms unheard, plus wrong-button delays), so ~8 misses are expected and the 95 % Wilson
# lower bound clears 99 % unless more than ~16 occur (well under 1 % of seeds).
@pytest.fixture(scope="module")
def reference_users(request: pytest.FixtureRequest) -> SimulationResult:
    result: SimulationResult = simulator_for(request)(SPEC, users=600, days=1, user_model=USERS)
    return result


def test_reference_users_take_at_least_99_percent_of_doses(
        reference_users: SimulationResult) -> None:
    expect(reference_users, "rate doses_taken/doses_due >= 0.99 with 95% confidence")


def test_reference_users_need_about_1_176_alarms_per_dose(
        reference_users: SimulationResult) -> None:
    # analytic: 1 + 0.15 + 0.15^2 + (walk past 300 s) ... = 1.176 (SCENARIO.md)
    expect(reference_users, "mean alarms_per_dose in [1.12, 1.24] with 95% confidence")


def test_reference_users_report_within_10_minutes_at_the_95th_percentile(
        reference_users: SimulationResult) -> None:
    expect(reference_users, "p95 report_latency_s <= 600 with 95% confidence")


def test_reference_users_never_get_a_double_dose(spec: Any, simulate: Any) -> None:
    result = simulate(spec, users=40, days=3, user_model=USERS, keep_trace=True)
    expect(result, "never activity dispense twice within 3h45m", "doses_due == 480")
    assert result.value("doses_taken") + result.value("doses_missed") == 480


# ---------------------------------------------------------------- trace predicates
def test_a_user_reporting_within_60_s_of_every_first_alarm_takes_every_dose(
        spec: Any, simulate: Any) -> None:
    result = simulate(spec, script=[("each after trg_2 45s", "press_report")], days=1)
    check(result,
          within("sound_alarm", "press_report", 60),
          happens_before("sound_alarm", "press_report", each=True),
          within("press_report", "dispense", 0),
          per_instance("notify_workflow", (count("dispense") == 1) & never("notify_caregiver")
                       & (count("sound_alarm") == 1)))


def test_a_user_who_never_reports_is_alarmed_three_times_then_the_caregiver_is_called(
        spec: Any, simulate: Any) -> None:
    result = simulate(spec, script=[("never", "press_report")], days=1)
    check(result, never("dispense"),
          per_instance("notify_workflow", (count("sound_alarm") == 3)
                       & happens_before("record_missed", "notify_caregiver")
                       & within("process:notify_workflow", "notify_caregiver", 15 * 60)))


# ---------------------------------------------------------------- golden trace
def test_the_morning_dose_of_a_prompt_user_matches_its_golden_trace(
        spec: Any, simulate: Any, golden: Any) -> None:
    # review golden/prompt_user_morning.jsonl when it changes (pytest --opspec-regen-golden)
    result = simulate(spec, script=[("after trg_2 90s", "press_report")],
                      until=FIRST_DOSE_HOUR, seed=1)
    golden(result, "golden/prompt_user_morning.jsonl")


# ---------------------------------------------------------------- older adults
# The reference user slowed down 1.5x (the older-adults modifier, docs/user-models.md).
OLDER_ADULTS = "dispenser-reference,older-adults"


@pytest.fixture(scope="module")
def older_adults(request: pytest.FixtureRequest) -> SimulationResult:
    result: SimulationResult = simulator_for(request)(SPEC, users=200, days=1,
                                                      user_model=OLDER_ADULTS)
    return result


def test_older_adults_take_at_least_98_percent_of_doses(older_adults: SimulationResult
                                                        ) -> None:
    assert_rate(older_adults, "taken_rate", at_least=0.98, confidence=0.95)


def test_older_adults_report_within_10_minutes_at_the_95th_percentile(
        older_adults: SimulationResult) -> None:
    assert_quantile(older_adults, "report_latency_s", 0.95, at_most=600)
    assert_mean(older_adults, "alarms_per_dose", at_most=1.35)


def test_older_adults_take_98_percent_decided_sequentially(spec: Any, simulate: Any,
                                                           opspec_seed: int) -> None:
    # batches of 100 users until the claim is decided (Bonferroni over at most 10 looks)
    outcome = assert_rate_sequential(
        lambda k, n: simulate(spec, users=n, user_model=OLDER_ADULTS,
                              seed=derive_seed(opspec_seed, f"batch {k}")),
        ("doses_taken", "doses_due"), at_least=0.98, batch_users=100, max_users=1000)
    assert outcome.users < 1000         # clear enough to stop before the cap


# ---------------------------------------------------------------- monitors
def test_reference_users_never_get_two_dispenses_within_3h45m(spec: Any, simulate: Any
                                                              ) -> None:
    result = simulate(spec, users=40, days=3, user_model=USERS,
                      monitors=[min_gap("dispense", minutes=225), min_gap("dispense", hours=4)])
    assert_no_violations(result, "min_gap dispense 3.75h")
    # the 4 h rule is broken routinely (see the xfail below): a hazard, not a rare event
    assert result.monitor_report().row("min_gap dispense 4h").hazard_lo > 0.2


@pytest.mark.xfail(strict=True, reason=(
    "spec finding: the monitor 'min_gap dispense 4h' fires - 08:00/12:00 and 18:00/22:00 are "
    "exactly 4 h apart, so a late report then a prompt one dispense less than 4 h apart"))
def test_monitor_no_dispense_within_4_hours_of_the_previous_one(spec: Any, simulate: Any
                                                                ) -> None:
    result = simulate(spec, users=20, days=2, user_model=USERS, monitors=["min_gap dispense 4h"])
    assert_no_violations(result)
