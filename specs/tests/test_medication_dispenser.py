"""Executable tests of specs/medication_dispenser.xpdl (the reference scenario "dispenser-day").

They are written with the opspec pytest plugin (``spec`` / ``simulate`` fixtures, scripts as
plain data, ``expect`` lines) and read like the scenario: doses at 08:00, 12:00, 18:00 and
22:00, up to 3 alarms 300 s apart, then a miss and a call to the caregiver.
"""

from __future__ import annotations

from typing import Any

import pytest

from opspec.testing import SimulationResult, expect, simulator_for

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
