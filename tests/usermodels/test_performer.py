"""StochasticUser on the dispenser's user lane, driven by a fake session (no engine)."""

from __future__ import annotations

import bisect
import math
from pathlib import Path

import numpy as np
import pytest

from opspec.engine.performers import Performer
from opspec.errors import UserModelError
from opspec.usermodels import ActivityModel, StochasticUser, UserModel, load_user_model
from opspec.usermodels.distributions import Constant, LogNormal
from opspec.usermodels.errors import Busy, Commission, ExtraDelay, Omission, Repetition

from .fakes import DispenserLane, FakeSession, make_item

DAY = 86_400.0
DOSE_TIMES = (8 * 3600.0, 12 * 3600.0, 18 * 3600.0, 22 * 3600.0)
CHOICES = ("press_report", "press_wrong_button")


def run_days(model: UserModel, seed: int, days: int) -> tuple[FakeSession, DispenserLane]:
    session = FakeSession()
    lane = DispenserLane(session, model.performer(np.random.default_rng(seed)))
    for day in range(days):
        for t in DOSE_TIMES:
            lane.dose(day * DAY + t)
    session.run()
    return session, lane


@pytest.fixture(scope="module")
def reference_run() -> tuple[FakeSession, DispenserLane]:
    path = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.users.toml"
    return run_days(load_user_model(path), seed=2024, days=2500)  # 10,000 dose cycles


def test_stochastic_user_is_a_performer() -> None:
    model = load_user_model("dispenser-reference")
    assert isinstance(model.performer(np.random.default_rng(0)), Performer)


def test_alarms_are_not_heard_at_the_rate_of_the_model(reference_run) -> None:
    session, _ = reference_run
    heard_offers = [o for o in session.omitted if o[1].activity == "hear_alarm"]
    not_heard = sum(1 for o in heard_offers if o[2] == "not heard")
    busy = sum(1 for o in heard_offers if o[2] == "busy")
    decided = sum(1 for c in session.completed if c[1].activity == "hear_alarm") + not_heard
    rate = not_heard / decided
    assert rate == pytest.approx(0.15, abs=5 * math.sqrt(0.15 * 0.85 / decided))
    assert busy > 0


def test_a_user_on_the_way_ignores_the_next_alarm(reference_run) -> None:
    session, lane = reference_run
    walking: dict[int, tuple[float, float]] = {}
    starts = {i.instance: i.offered_at for i in lane.offers if i.activity == "walk_to_dispenser"}
    for time, item, _ in session.completed:
        if item.activity == "press_report":
            walking[item.instance] = (starts[item.instance], time)
    intervals = sorted(walking.values())
    begins = [a for a, _ in intervals]
    for time, _item, reason in session.omitted:
        # Walks do not overlap (a walking user ignores alarms), so check the latest start.
        i = bisect.bisect_left(begins, time) - 1
        on_the_way = i >= 0 and intervals[i][0] < time < intervals[i][1]
        assert (reason == "busy") == on_the_way, (time, reason)


def test_the_wrong_button_is_pressed_first_at_the_rate_of_the_model(reference_run) -> None:
    session, _ = reference_run
    picks: dict[int, list[str]] = {}
    for _, item, choice in session.completed:
        if item.activity == "choose_button":
            picks.setdefault(item.instance, []).append(choice)
    n = len(picks)
    wrong_first = sum(1 for p in picks.values() if p[0] == "press_wrong_button")
    assert wrong_first / n == pytest.approx(0.05, abs=5 * math.sqrt(0.05 * 0.95 / n))
    # At most one wrong press per instance, always followed by the report.
    assert all(p in (["press_report"], ["press_wrong_button", "press_report"])
               for p in picks.values())
    wrong_traced = [t for t in session.traces if t[1] == "user.wrong_choice"]
    assert len(wrong_traced) == wrong_first


@pytest.mark.parametrize(("activity", "median", "sigma"),
                         [("walk_to_dispenser", 60.0, 0.6), ("take_pill", 20.0, 0.4)],
                         ids=["walk", "pill"])
def test_durations_have_the_model_median(reference_run, activity: str, median: float,
                                         sigma: float) -> None:
    session, lane = reference_run
    offered = {i.key: i.offered_at for i in lane.offers}
    logs = np.log([t - offered[i.key] for t, i, _ in session.completed if i.activity == activity])
    assert logs.mean() == pytest.approx(math.log(median), abs=5 * sigma / math.sqrt(logs.size))
    assert logs.std() == pytest.approx(sigma, rel=0.05)


def test_reference_scenario_matches_its_closed_form(reference_run) -> None:
    """bench/analytic.py: alarms per dose 1.1762, report latency mean 122.2 s."""
    _, lane = reference_run
    alarms = np.array([d["alarms"] for d in lane.doses])
    latency = np.array([d["report"] - d["first_alarm"] for d in lane.doses
                        if d["report"] is not None])
    assert alarms.mean() == pytest.approx(1.1762, abs=5 * alarms.std() / math.sqrt(alarms.size))
    assert latency.mean() == pytest.approx(122.2, abs=5 * latency.std() / math.sqrt(latency.size))


def _decisions(session: FakeSession) -> list[tuple]:
    return ([(t, i.activity, i.instance, c) for t, i, c in session.completed]
            + [(t, i.activity, i.instance, r) for t, i, r in session.omitted])


def test_same_seed_gives_the_same_decisions() -> None:
    model = load_user_model("dispenser-reference")
    a, _ = run_days(model, seed=9, days=30)
    b, _ = run_days(model, seed=9, days=30)
    c, _ = run_days(model, seed=10, days=30)
    assert _decisions(a) == _decisions(b)
    assert a.traces == b.traces
    assert _decisions(a) != _decisions(c)


def simple_model(**activity: ActivityModel) -> UserModel:
    return UserModel(name="t", activities=activity)


def test_offer_before_attach_is_an_error() -> None:
    user = simple_model(a=ActivityModel()).performer(np.random.default_rng(0))
    with pytest.raises(UserModelError, match="before attach"):
        user.offer(make_item("a"))


def test_an_uncovered_activity_names_the_fix(session: FakeSession) -> None:
    user = simple_model(a=ActivityModel()).performer(np.random.default_rng(0))
    user.attach(session)
    with pytest.raises(UserModelError, match=r"add \[activities.b\]"):
        user.offer(make_item("b"))


def test_a_withdrawn_item_is_never_completed(session: FakeSession) -> None:
    user = simple_model(a=ActivityModel(duration=Constant(10))).performer(
        np.random.default_rng(0))
    user.attach(session)
    kept, dropped = make_item("a", 1), make_item("a", 2)
    user.offer(kept)
    user.offer(dropped)
    user.withdraw(dropped, "deadline")
    session.run()
    assert [(t, i.key) for t, i, _ in session.completed] == [(10.0, kept.key)]


def test_busy_omits_prompts_of_other_instances_only(session: FakeSession) -> None:
    model = UserModel(name="t", activities={
        "hear": ActivityModel(), "walk": ActivityModel(duration=Constant(100))},
        busy=Busy(frozenset({"walk"}), ignore=frozenset({"hear"})))
    user = model.performer(np.random.default_rng(0))
    user.attach(session)
    user.offer(make_item("walk", 1))
    user.offer(make_item("hear", 2))          # another alarm while walking: ignored
    user.offer(make_item("walk", 3))          # not in `ignore`: performed
    session.run()
    assert [(i.instance, r) for _, i, r in session.omitted] == [(2, "busy")]
    assert ("user.omitted" in [k for _, k, _ in session.traces])
    user.offer(make_item("hear", 4))          # the walks are over: heard again
    session.run()
    assert len(session.omitted) == 1


def test_choice_probabilities_are_followed(session: FakeSession) -> None:
    model = simple_model(c=ActivityModel(probabilities=(("x", 0.3), ("y", 0.7))))
    user = model.performer(np.random.default_rng(1))
    user.attach(session)
    n = 4000
    for i in range(n):
        user.offer(make_item("c", i, choices=("x", "y")))
    session.run()
    share = sum(1 for *_, c in session.completed if c == "x") / n
    assert share == pytest.approx(0.3, abs=5 * math.sqrt(0.21 / n))


def test_commission_recovery_is_owed_at_the_next_pick(session: FakeSession) -> None:
    model = simple_model(c=ActivityModel(intended="ok", commission=Commission(
        1.0, recovery=Constant(7.0), alternatives=("bad",))))
    user = model.performer(np.random.default_rng(0))
    user.attach(session)
    user.offer(make_item("c", 1, choices=("ok", "bad")))
    session.run()
    user.offer(make_item("c", 1, choices=("ok", "bad")))
    session.run()
    assert [(t, c) for t, _, c in session.completed] == [(0.0, "bad"), (7.0, "ok")]


def test_repetition_delay_and_slip_lengthen_the_activity(session: FakeSession) -> None:
    model = simple_model(a=ActivityModel(
        duration=Constant(5.0), repetition=Repetition(1.0),
        delay=ExtraDelay(1.0, Constant(20.0)),
        commission=Commission(1.0, recovery=Constant(3.0))))
    user = model.performer(np.random.default_rng(0))
    user.attach(session)
    user.offer(make_item("a"))
    session.run()
    assert session.completed[0][0] == 5 + 5 + 20 + 3
    assert {k for _, k, _ in session.traces} == {"user.repeated", "user.delayed", "user.slip"}


def test_omission_reason_comes_from_the_model(session: FakeSession) -> None:
    model = simple_model(a=ActivityModel(omission=Omission(1.0, reason="forgot"), prompt=True))
    user = model.performer(np.random.default_rng(0))
    user.attach(session)
    user.offer(make_item("a"))
    assert session.omitted[0][2] == "forgot"


def test_durations_are_never_negative(session: FakeSession) -> None:
    from opspec.usermodels.distributions import ExGaussian

    model = simple_model(a=ActivityModel(duration=ExGaussian(0.0, 5.0, 0.1)))
    user = StochasticUser(model, np.random.default_rng(0))
    user.attach(session)
    for i in range(200):
        user.offer(make_item("a", i))
    session.run()
    assert len(session.completed) == 200 and session.now >= 0.0


def test_lognormal_durations_scale_with_a_modifier() -> None:
    base = load_user_model("dispenser-reference")
    slow = load_user_model("older-adults", base=base)
    walk = slow.activities["walk_to_dispenser"].duration
    assert isinstance(walk, LogNormal) and walk.median == pytest.approx(90.0)
