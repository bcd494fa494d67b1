"""The medication dispenser (SCENARIO.md) with scripted users."""

from __future__ import annotations

import pytest
from engine_runs import completed, events
from dispenser_model import DOSES, dispenser_package

from opspec.engine.builtin_performers import ScriptedUser
from opspec.engine.compiled import compile_package
from opspec.engine.config import EngineConfig
from opspec.engine.simulation import Simulation

FIRST_DOSE = DOSES[0]


@pytest.fixture(scope="module")
def compiled() -> object:
    return compile_package(dispenser_package())


def _run(compiled: object, user: ScriptedUser, config: EngineConfig | None = None,
         until: float = FIRST_DOSE + 3600) -> object:
    sim = Simulation(compiled, config, performers={"user": user}, keep_trace=True)  # type: ignore[arg-type]
    return sim.run(until=until)


@pytest.mark.parametrize("model", ["dedicated", "pooled"])
def test_user_who_reports_90_s_after_the_first_alarm_takes_the_dose(compiled: object,
                                                                    model: str) -> None:
    user = ScriptedUser([(0, "complete hear_alarm"), (90, "complete walk_to_dispenser"),
                         (0, "choose press_report"), (20, "complete take_pill")])
    result = _run(compiled, user, EngineConfig(processor_model=model))
    metrics = result.metrics
    assert metrics["doses_due"] == {"kind": "count", "total": 1}
    assert metrics["doses_taken"]["total"] == 1 and metrics["doses_missed"]["total"] == 0
    latency = metrics["report_latency_s"]
    assert latency["n"] == 1 and latency["mean"] == pytest.approx(90.0, abs=0.01)
    assert metrics["alarms_per_dose"]["value"] == 1.0
    assert completed(result, "user_workflow")[-1] == "user_done"


def test_user_who_never_reports_gets_three_alarms_a_miss_and_a_caregiver_call(
        compiled: object) -> None:
    result = _run(compiled, ScriptedUser([], default="omit"))
    metrics = result.metrics
    assert metrics["alarms"]["total"] == 3
    assert metrics["doses_missed"]["total"] == 1
    assert metrics["caregiver_notified"]["total"] == 1
    assert metrics["doses_taken"]["total"] == 0
    alarms = [e.time for e in events(result, "activity.completed", activity="sound_alarm")]
    assert alarms == [FIRST_DOSE, FIRST_DOSE + 300, FIRST_DOSE + 600]
    assert events(result, "activity.completed", activity="notify_caregiver")[0].time == (
        FIRST_DOSE + 900)


def test_report_after_the_device_gave_up_changes_nothing(compiled: object) -> None:
    user = ScriptedUser([(0, "complete hear_alarm"), (1000, "complete walk_to_dispenser"),
                         (0, "choose press_report"), (20, "complete take_pill")],
                        default="omit")
    result = _run(compiled, user)
    assert result.metrics["doses_missed"]["total"] == 1
    assert result.metrics["doses_taken"]["total"] == 0
    # the user still finished their own workflow; the late trg_1 reached no one
    assert "take_pill" in completed(result, "user_workflow")
    assert result.summary["deadlocks"] == []


def test_wrong_button_loops_back_to_the_choice(compiled: object) -> None:
    user = ScriptedUser([(0, "complete hear_alarm"), (60, "complete walk_to_dispenser"),
                         (0, "choose press_wrong_button"), (10, "choose press_report"),
                         (20, "complete take_pill")])
    result = _run(compiled, user)
    assert result.metrics["report_latency_s"]["mean"] == pytest.approx(70.0)
    offers = [i.choices for i in user.offers if i.choices]
    assert offers == [("press_report", "press_wrong_button")] * 2


def test_schedule_subflow_returns_the_dose_of_the_slot(compiled: object) -> None:
    result = _run(compiled, ScriptedUser([], default="omit"), until=DOSES[3] + 1000)
    doses = [e.data["dose"] for e in events(result, "data.changed", process="notify_workflow")
             if "dose" in e.data]
    assert doses == ["morning", "noon", "evening", "night"]


def test_four_doses_a_day_for_three_days(compiled: object) -> None:
    sim = Simulation(compiled, performers={"user": ScriptedUser([], default="omit")})  # type: ignore[arg-type]
    result = sim.run(until=3 * 86_400.0)
    assert result.metrics["doses_due"]["total"] == 12
    assert result.metrics["doses_missed"]["total"] == 12
