"""The lead's specs/medication_dispenser.xpdl, read by the XPDL front end, runs on the engine
with the same outcomes as the Python-built model."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.engine.builtin_performers import ScriptedUser
from opspec.engine.simulation import Simulation

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"


@pytest.fixture(scope="module")
def spec() -> object:
    loader = pytest.importorskip("opspec.xpdl.loader")
    if not SPEC.exists():
        pytest.skip("specs/medication_dispenser.xpdl is not there")
    return loader.load_spec(SPEC)


def test_spec_user_reporting_after_90_s_takes_the_dose(spec: object) -> None:
    user = ScriptedUser([(0, "complete hear_alarm"), (90, "complete walk_to_dispenser"),
                         (0, "choose press_report"), (20, "complete take_pill")])
    result = Simulation(spec, performers={"user": user}).run(until=8 * 3600 + 3600)  # type: ignore[arg-type]
    assert result.metrics["doses_taken"]["total"] == 1
    assert result.metrics["report_latency_s"]["mean"] == pytest.approx(90.0)


def test_spec_user_who_never_reports_is_missed_with_three_alarms(spec: object) -> None:
    result = Simulation(spec, performers={"user": ScriptedUser([], default="omit")}  # type: ignore[arg-type]
                        ).run(until=86_400.0)
    metrics = result.metrics
    assert metrics["doses_due"]["total"] == 4
    assert metrics["doses_missed"]["total"] == 4
    assert metrics["caregiver_notified"]["total"] == 4
    assert metrics["alarms_per_dose"]["value"] == 3.0
