"""Daily routine windows and drifts over days, driven by simulated time."""

from __future__ import annotations

import math

import numpy as np
import pytest

from opspec.errors import UserModelError
from opspec.usermodels import ActivityModel, UserModel
from opspec.usermodels.distributions import Constant
from opspec.usermodels.errors import Omission
from opspec.usermodels.routine import DAY, Drift, Routine, RoutineTracker, Window

from .fakes import FakeSession, make_item

ASLEEP = Window("asleep", "23:00", "07:00", notice_factor=0.0)
OUT = Window("out", "14:00", "16:00", notice_factor=0.0, defer=True)


@pytest.mark.parametrize(("t", "inside"), [
    (22 * 3600, False), (23 * 3600, True), (DAY + 2 * 3600, True), (DAY + 7 * 3600, False),
    (2 * 3600, True), (12 * 3600, False)], ids=["22h", "23h", "2h-next-day", "7h", "2h-day0",
                                                 "noon"])
def test_a_window_over_midnight_contains_the_night(t: float, inside: bool) -> None:
    assert (ASLEEP.occurrence(t) is not None) == inside


def test_the_night_belongs_to_the_evening_it_started() -> None:
    assert ASLEEP.occurrence(DAY + 2 * 3600) == (0, DAY + 7 * 3600)


def user_with(routine: Routine, **activity: ActivityModel) -> tuple[FakeSession, object]:
    session = FakeSession()
    user = UserModel(name="t", activities=activity, routine=routine).performer(
        np.random.default_rng(3))
    user.attach(session)
    return session, user


def test_an_asleep_user_does_not_hear_and_the_reason_is_traced() -> None:
    session, user = user_with(Routine((ASLEEP,)),
                              hear=ActivityModel(omission=Omission(0.0)))
    session.now = 2 * 3600.0
    user.offer(make_item("hear"))
    session.now = 9 * 3600.0
    user.offer(make_item("hear"))
    assert [r for _, _, r in session.omitted] == ["asleep"]
    assert session.traces[0][2]["reason"] == "asleep"


def test_an_out_user_starts_when_back() -> None:
    session, user = user_with(Routine((OUT,)), walk=ActivityModel(duration=Constant(60)))
    session.now = 15 * 3600.0
    user.offer(make_item("walk"))
    session.run()
    assert session.completed[0][0] == 16 * 3600.0 + 60


def test_a_window_slows_durations() -> None:
    meal = Window("meal", "12:00", "13:00", duration_factor=2.0)
    session, user = user_with(Routine((meal,)), walk=ActivityModel(duration=Constant(60)))
    session.now = 12.5 * 3600
    user.offer(make_item("walk"))
    session.run()
    assert session.completed[0][0] == 12.5 * 3600 + 120


def test_a_probabilistic_window_happens_on_that_share_of_days() -> None:
    tracker = RoutineTracker(Routine((Window("out", "10:00", "11:00", notice_factor=0.0,
                                             probability=0.3),)), np.random.default_rng(1))
    days = 3000
    out = sum(tracker.state(d * DAY + 10.5 * 3600).notice_factor == 0.0 for d in range(days))
    assert out / days == pytest.approx(0.3, abs=5 * math.sqrt(0.21 / days))


def test_adherence_decays_and_learning_shortens_over_days() -> None:
    drift = Drift(notice_factor_per_day=0.99, min_notice_factor=0.5,
                  duration_factor_per_day=0.98, min_duration_factor=0.8)
    tracker = RoutineTracker(Routine(drift=drift), np.random.default_rng(0))
    assert tracker.state(0.0).notice_factor == 1.0
    assert tracker.state(30 * DAY).notice_factor == pytest.approx(0.99 ** 30)
    assert tracker.state(300 * DAY).notice_factor == 0.5
    assert tracker.state(5 * DAY).duration_factor == pytest.approx(0.98 ** 5)
    assert tracker.state(100 * DAY).duration_factor == 0.8


def test_adherence_decay_shows_in_omissions_with_its_own_reason() -> None:
    drift = Drift(notice_factor_per_day=0.98)
    session, user = user_with(Routine(drift=drift), hear=ActivityModel(omission=Omission(0.0)))
    n = 3000
    session.now = 60 * DAY
    for i in range(n):
        user.offer(make_item("hear", i))
    expected = 1 - 0.98 ** 60
    missed = len(session.omitted) / n
    assert missed == pytest.approx(expected, abs=5 * math.sqrt(expected * (1 - expected) / n))
    assert {r for *_, r in session.omitted} == {"adherence"}


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"start": "25:00"}, r"start: cannot read time of day '25:00': it is past 24:00"),
    ({"start": "7h"}, r"start: cannot read time of day '7h': expected HH:MM"),
    ({"notice_factor": 1.5}, r"notice_factor: must be a probability"),
    ({"duration_factor": 0}, r"duration_factor: must be > 0"),
    ({"end": "23:00"}, r"end: must differ from start"),
], ids=["hour-25", "not-hh-mm", "notice-above-1", "zero-duration-factor", "empty-window"])
def test_bad_windows_name_the_parameter(kwargs: dict, message: str) -> None:
    params = {"name": "w", "start": "23:00", "end": "07:00", **kwargs}
    with pytest.raises(UserModelError, match=message):
        Window(**params)
