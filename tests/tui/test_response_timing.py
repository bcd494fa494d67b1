"""Response times measured in a walkthrough are real: each answer records the wall-clock time
the person took, and whether its simulated duration (what `opspec fit` reads) is real — the
clock ran in real time from the offer to the answer — and fit uses only those."""

from __future__ import annotations

import json

import pytest

from opspec.tui.session import WalkSession
from opspec.tui.timing import OfferTimes
from opspec.usermodels.fitting import collect

ALARM = 8 * 3600.0


class WallClock:
    """A wall clock the test moves (monotonic seconds)."""

    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


def at_alarm(compiled, tmp_path, name="t.json", **options):
    session = WalkSession(compiled, record=tmp_path / name, **options)
    wall = WallClock()
    session.times = OfferTimes(wall)
    while session.now < ALARM and not session.offers:
        session.run_to(ALARM)
    assert session.speed == 1.0                     # the call: real time
    return session, wall


def real_seconds(session: WalkSession, wall: WallClock, seconds: float) -> None:
    """``seconds`` pass on the wall, and the clock (at 1x) follows, as the app's ticks do."""
    wall.now += seconds
    session.advance(seconds)


def actions(session: WalkSession) -> list[dict]:
    session.close()
    lines = session.record_path.with_suffix(".trace.jsonl").read_text().splitlines()
    return [e["data"] for e in map(json.loads, lines[1:]) if e["kind"] == "walkthrough.action"]


def offer(session, activity):
    return next(o for o in session.offers if o.item.activity == activity)


def test_an_answer_in_real_time_is_usable_and_says_how_long_it_took(compiled, tmp_path):
    session, wall = at_alarm(compiled, tmp_path)
    real_seconds(session, wall, 4.5)
    session.act(offer(session, "hear_alarm"))
    real_seconds(session, wall, 12.0)
    session.act(offer(session, "walk_to_dispenser"))
    first, second = actions(session)
    assert first["usable"] and first["response_wall_s"] == pytest.approx(4.5)
    assert second["usable"] and second["response_wall_s"] == pytest.approx(12.0)
    assert (first["instance"], first["activity"]) == (4, "hear_alarm")


def test_time_spent_paused_is_not_zero_and_the_answer_is_not_usable(compiled, tmp_path):
    session, wall = at_alarm(compiled, tmp_path)
    session.paused = True
    real_seconds(session, wall, 7.0)                # the clock stands; the person thinks
    session.act(offer(session, "hear_alarm"))
    (data,) = actions(session)
    assert data["response_wall_s"] == pytest.approx(7.0)     # what the person took
    assert data["usable"] is False and data["why"] == "the clock was paused"
    assert session.responses[0].wall_s == pytest.approx(7.0)


@pytest.mark.parametrize(("disturb", "why"), [
    (lambda s: setattr(s, "speed", 60.0), "the clock ran at 60x"),
    (lambda s: s.skip_to_next_event(), "skipped to the next event"),
    (lambda s: s.spoil_timing("waited 30 s with w"), "waited 30 s with w"),
], ids=["fast", "next-event", "wait"])
def test_a_fast_forward_or_a_jump_makes_the_answer_unusable(compiled, tmp_path, disturb, why):
    session, wall = at_alarm(compiled, tmp_path)
    session.act(offer(session, "hear_alarm"))
    real_seconds(session, wall, 2.0)
    disturb(session)                                # while "walk" waits for the person
    real_seconds(session, wall, 1.0)
    session.act(offer(session, "walk_to_dispenser"))
    heard, walked = actions(session)
    assert heard["usable"] is True
    assert walked["usable"] is False and walked["why"] == why


def test_the_speed_dropping_at_the_call_does_not_spoil_the_offer_it_brought(compiled,
                                                                          tmp_path):
    session, wall = at_alarm(compiled, tmp_path)    # 60x until the very instant of the call
    real_seconds(session, wall, 3.0)
    session.act(offer(session, "hear_alarm"))
    assert actions(session)[0]["usable"] is True


def test_the_models_answers_are_not_the_persons(compiled, tmp_path, model_factory):
    session = WalkSession(compiled, record=tmp_path / "m.json", model_factory=model_factory)
    session.hand_over()
    while session.now < ALARM + 900:
        session.run_to(ALARM + 900)
    data = actions(session)
    assert data and all(d["by"] == "model" and d["usable"] is False for d in data)


def test_fit_leaves_out_what_was_not_timed_in_real_time(compiled, tmp_path, capsys):
    """Two answers at 1x (4.5 s and 9 s) and one while paused: fit sees 4.5 and 9 only."""
    session, wall = at_alarm(compiled, tmp_path)
    real_seconds(session, wall, 4.5)
    session.act(offer(session, "hear_alarm"))
    real_seconds(session, wall, 9.0)
    session.act(offer(session, "walk_to_dispenser"))
    session.paused = True
    real_seconds(session, wall, 6.0)
    session.act(next(o for o in session.offers if o.choice == "press_report"))
    session.close()
    obs = collect([session.record_path.with_suffix(".trace.jsonl")])
    assert obs.durations["hear_alarm"] == [pytest.approx(4.5)]
    assert obs.durations["walk_to_dispenser"] == [pytest.approx(9.0)]
    assert "choose_button" not in obs.durations and obs.unusable["choose_button"] == 1
    assert obs.picks["choose_button"] == [["press_report"]]  # the choice itself still counts
    # opspec fit says what it left out, of which activity
    from opspec.cli import main

    assert main(["fit", str(session.record_path.with_suffix(".trace.jsonl")), "-o",
                 str(tmp_path / "fitted.users.toml")]) == 0
    out = capsys.readouterr().out
    assert ("left out: 1 walkthrough duration(s) not timed in real time (choose_button 1)"
            in out)


def test_sessions_of_one_participant_count_as_one_person_in_fit(compiled, tmp_path):
    """`walkthrough --person P07` writes the person into the trace header: two sessions of
    P07 and one of P09 are two persons, three sessions, for opspec fit."""
    traces = []
    for name, person, took in (("a.json", "P07", 4.0), ("b.json", "P07", 6.0),
                               ("c.json", "P09", 5.0)):
        session, wall = at_alarm(compiled, tmp_path, name, person=person)
        real_seconds(session, wall, took)
        session.act(offer(session, "hear_alarm"))
        session.close()
        trace = session.record_path.with_suffix(".trace.jsonl")
        assert json.loads(trace.read_text().splitlines()[0])["person"] == person
        traces.append(trace)
    obs = collect(traces)
    assert obs.persons == ["P07", "P09"]
    assert obs.sessions == 3
    by_person = obs.lists_by_person(obs.user_durations["hear_alarm"])
    assert sorted(by_person["P07"]) == [pytest.approx(4.0), pytest.approx(6.0)]
    assert by_person["P09"] == [pytest.approx(5.0)]


def test_without_person_each_session_is_its_own_person(compiled, tmp_path):
    traces = []
    for name in ("a.json", "b.json"):
        session, wall = at_alarm(compiled, tmp_path, name)
        real_seconds(session, wall, 3.0)
        session.act(offer(session, "hear_alarm"))
        session.close()
        trace = session.record_path.with_suffix(".trace.jsonl")
        assert "person" not in json.loads(trace.read_text().splitlines()[0])
        traces.append(trace)
    assert len(collect(traces).persons) == 2
