"""When the device calls the person the clock drops to real time (or pauses), so a person can
answer the first alarm; the speed comes back when the call is over; `n` jumps while the clock
runs; the clock stands while the help or the summary is open."""

from __future__ import annotations

import pytest

from opspec.errors import ConfigurationError
from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession

ALARM = 8 * 3600.0                     # the morning dose: 08:00, re-alarms 08:05 and 08:10


def run_until(session: WalkSession, target: float) -> None:
    """Step to ``target``: run_to stops where a call begins (the clock changes pace there)."""
    while session.now < target and not session.ended:
        session.run_to(target)


def offer(session: WalkSession, activity: str):
    return next(o for o in session.offers if o.item.activity == activity)


def test_the_clock_drops_to_real_time_at_the_alarm_and_comes_back_when_all_is_done(compiled):
    session = WalkSession(compiled)
    assert session.speed == 60.0
    session.run_to(ALARM - 60)
    assert session.speed == 60.0                       # no call yet
    session.run_to(ALARM + 10)
    assert session.now == ALARM                        # it stopped at the call...
    assert session.speed == 1.0 and session.calling    # ...in real time
    session.act(offer(session, "hear_alarm"))
    session.run_to(session.now + 5)
    session.act(offer(session, "walk_to_dispenser"))
    session.act(next(o for o in session.offers if o.choice == "press_report"))
    assert not session.calling and session.speed == 1.0   # the pill still waits for me
    session.act(offer(session, "take_pill"))
    assert session.speed == 60.0 and not session.offers   # done: the speed I had


def test_an_alarm_let_pass_gives_the_speed_back_when_its_episode_ends(compiled):
    session = WalkSession(compiled)
    session.run_to(ALARM + 1)
    run_until(session, ALARM + 302)                    # the 08:05 re-alarm calls again
    assert session.speed == 1.0 and session.calling
    run_until(session, ALARM + 15 * 60 + 1)            # 08:15: missed, the alarm stops
    assert not session.calling and session.speed == 60.0


def test_a_speed_chosen_during_a_call_is_kept_until_the_next_alarm(compiled):
    session = WalkSession(compiled)
    session.run_to(ALARM + 1)
    session.speed = 600.0                              # the coordinator fast-forwards
    run_until(session, ALARM + 299)
    assert session.speed == 600.0 and session.calling
    run_until(session, ALARM + 301)                    # the 08:05 re-alarm: a new call
    assert session.speed == 1.0


@pytest.mark.parametrize(("mode", "speed", "paused"), [("pause", 60.0, True),
                                                        ("keep", 60.0, False)])
def test_on_call_pause_and_keep(compiled, mode, speed, paused):
    session = WalkSession(compiled, on_call=mode)
    session.skip_until_user()
    assert session.calling and session.speed == speed and session.paused is paused


def test_a_clock_the_call_paused_says_so(compiled):
    """With --on-call pause the status line said only PAUSED at the alarm: the person did not
    know the device had stopped the clock, or how to go on. A pause of their own is PAUSED."""
    session = WalkSession(compiled, on_call="pause")
    session.skip_until_user()
    assert session.paused and session.paused_words == "PAUSED: the device calls (space resumes)"
    mine = WalkSession(compiled)
    mine.paused = True
    assert mine.paused_words == "PAUSED"


def test_a_model_performing_the_lane_is_not_slowed_down(compiled, model_factory):
    session = WalkSession(compiled, model_factory=model_factory)
    session.hand_over()
    run_until(session, ALARM + 1)
    assert session.speed == 60.0


def test_an_unknown_on_call_mode_is_refused(compiled):
    with pytest.raises(ConfigurationError, match="--on-call takes one of realtime, pause"):
        WalkSession(compiled, on_call="slow")


def test_next_event_jumps_after_the_clock_ran(compiled):
    session = WalkSession(compiled)
    session.run_to(6.0)                                # as a running clock's tick does
    session.skip_to_next_event()
    assert session.now == ALARM


@pytest.mark.asyncio
async def test_n_works_while_the_clock_runs_and_the_status_says_real_time(compiled):
    session = WalkSession(compiled)
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause(0.35)                        # a few ticks at 60x
        assert 0 < session.now < 60 and not session.paused
        await pilot.press("n")
        # at the alarm, not at the next event (the re-alarm, 300 s on); from there the clock
        # runs at 1x, so the bound is the wall time the press took (over 1 s on a loaded CI
        # machine), not a simulated minute
        assert ALARM <= session.now < ALARM + 5
        await pilot.pause(0.3)
        status = str(app.query_one("#status").render())
        assert "1x" in status and "real time: the device calls" in status
        # real time: seconds, where 60x would have gone on at least 18 s in the 0.3 s pause
        assert ALARM < session.now < ALARM + 10


@pytest.mark.asyncio
async def test_the_clock_stands_while_the_summary_is_open(compiled):
    session = WalkSession(compiled)
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.press("s")
        await pilot.pause(0.3)
        text = str(app.screen.query_one("#summary-text").render())
        assert session.paused and text.startswith("So far, at d1 00:00")
        stood = session.now
        await pilot.pause(0.3)
        assert session.now == stood
        await pilot.press("escape")
        await pilot.pause(0.3)
        assert not session.paused and session.now > stood


def test_handing_over_during_a_call_gives_the_speed_back_and_taking_back_drops_it(
        compiled, model_factory):
    """The lane handed to the model while the alarm rings: the clock stayed at 1x, so the
    model walked over and reported in real time, minutes, while the status said "model
    performs your lane" (a model is never slowed down, says docs/walkthrough.md). Taken back
    while it still rings, the person answers in real time."""
    session = WalkSession(compiled, model_factory=model_factory)
    session.skip_until_user()
    assert session.now == ALARM and session.speed == 1.0 and session.call_mode
    session.act(offer(session, "hear_alarm"))
    assert session.speed == 1.0                        # the person is in the call
    assert session.hand_over()
    assert session.speed == 60.0 and not session.call_mode
    session.take_back()
    assert session.calling and session.speed == 1.0 and session.call_mode
