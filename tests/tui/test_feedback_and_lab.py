"""What the person sees of their own actions (a wrong button, a report nobody waited for),
lapsed alarms leaving the Running list, and the lab options: large text, high contrast,
the sound cue."""

from __future__ import annotations

import html
import re
import wave

import pytest

from opspec.tui.app import HIGH_CONTRAST, WalkthroughApp
from opspec.tui.session import WalkSession
from opspec.tui.sound import Cue

ALARM = 8 * 3600.0


def run_until(session: WalkSession, target: float) -> None:
    while session.now < target and not session.ended:
        session.run_to(target)


def offer(session, activity=None, choice=None):
    return next(o for o in session.offers
                if (choice is None or o.choice == choice)
                and (activity is None or o.item.activity == activity))


def walk_to_the_buttons(session: WalkSession) -> None:
    run_until(session, ALARM)
    session.act(offer(session, "hear_alarm"))
    session.act(offer(session, "walk_to_dispenser"))


def test_a_wrong_button_says_nothing_was_sent_and_what_is_asked_again(compiled):
    session = WalkSession(compiled)
    walk_to_the_buttons(session)
    session.act(offer(session, choice="press_wrong_button"))
    assert session.aftermath.text() == ("you: Press the wrong button at 08:00 -> your own "
                                        "action, nothing sent to the device -> asked next: "
                                        "Press a button")


def test_hearing_the_alarm_is_the_persons_own_action_not_a_fault(compiled):
    session = WalkSession(compiled)
    run_until(session, ALARM)
    session.act(offer(session, "hear_alarm"))
    text = session.aftermath.text()
    assert text.startswith("you: Hear the alarm at 08:00 -> your own action, nothing sent "
                           "to the device")
    assert "reached" not in text


def test_the_report_says_what_the_device_did(compiled):
    session = WalkSession(compiled)
    walk_to_the_buttons(session)
    session.act(offer(session, choice="press_report"))
    text = session.aftermath.text()
    assert "sent trg_1" in text and "Dispense the dose" in text
    assert text.endswith("asked next: Take the pill")


def test_a_report_nobody_waits_for_says_so(compiled):
    session = WalkSession(compiled)
    run_until(session, ALARM)
    run_until(session, ALARM + 16 * 60)             # the morning dose is missed
    session.act(offer(session, "hear_alarm"))
    session.act(offer(session, "walk_to_dispenser"))
    session.act(offer(session, choice="press_report"))
    assert "but the device was not waiting for trg_1" in session.aftermath.text()


def test_an_unanswered_alarms_instance_leaves_the_running_list(compiled):
    session = WalkSession(compiled)
    run_until(session, ALARM)
    first = offer(session, "hear_alarm").item.instance
    assert first in session.current
    run_until(session, ALARM + 301)                 # the 08:05 re-alarm supersedes it
    assert first not in session.current and first in session.lapsed_instances
    newer = offer(session, "hear_alarm").item.instance
    assert newer in session.current and newer != first


@pytest.mark.asyncio
async def test_the_running_list_on_screen_drops_the_lapsed_instance(compiled):
    session = WalkSession(compiled)
    session.paused = True
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        run_until(session, ALARM + 601)             # three alarms, none answered
        app.refresh_views()
        await pilot.pause()
        device = str(app.query_one("#device").render())
        assert device.count("user_workflow#") == 1 and "#6 at hear_alarm" in device


@pytest.mark.asyncio
async def test_large_puts_the_person_first_with_a_big_clock_and_tall_buttons(compiled):
    session = WalkSession(compiled)
    session.paused = True
    app = WalkthroughApp(session, large=True)
    async with app.run_test(size=(64, 20)) as pilot:
        await pilot.press("u")
        await pilot.pause()
        person, device = app.query_one("#person"), app.query_one("#device")
        assert person.region.y < device.region.y and person.region.width > 60
        assert app.query_one("#bigclock").display and not app.query_one("#timeline").display
        button = app.query_one(".offer")
        assert button.region.height == 3                     # a bordered button
        first = str(device.render()).splitlines()[:2]     # the countdown, then the alarm
        assert first[0].startswith("deadline wait_report") and "(!) alarm: ((( RINGING )))" in first[1]
        await pilot.press("l")                               # the coordinator's timeline
        await pilot.pause()
        assert app.query_one("#timeline").display


@pytest.mark.asyncio
async def test_large_at_80x24_keeps_the_deadline_countdown_in_sight(compiled):
    """--large in the usual lab terminal: the device panel has four lines, and the countdown
    to the device's deadline is among the lines shown (not cut off below the alarm)."""
    session = WalkSession(compiled)
    session.paused = True
    app = WalkthroughApp(session, large=True)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("u")                               # 08:00: the alarm, 5 min to go
        await pilot.pause()
        device = app.query_one("#device")
        visible = str(device.render()).splitlines()[:device.content_size.height]
        assert "deadline wait_report (#2) in 05:00" in visible
        assert any("(!) alarm: ((( RINGING )))" in line for line in visible)
        await pilot.press("w", "w", "w")                     # 90 s pass
        await pilot.pause()
        visible = str(device.render()).splitlines()[:device.content_size.height]
        assert "deadline wait_report (#2) in 03:30" in visible
        # and it is on the screen, not only in the widget
        screen = html.unescape(re.sub(r"<[^>]+>", "", app.export_screenshot()))
        assert "deadline wait_report (#2) in 03:30" in screen.replace("\xa0", " ")


def _luminance(hex_colour: str) -> float:
    """WCAG 2.x relative luminance (https://www.w3.org/TR/WCAG21/#dfn-relative-luminance)."""
    channels = [int(hex_colour[i:i + 2], 16) / 255 for i in (1, 3, 5)]
    linear = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in channels]
    return 0.2126 * linear[0] + 0.7152 * linear[1] + 0.0722 * linear[2]


def _contrast(a: str, b: str) -> float:
    high, low = sorted((_luminance(a), _luminance(b)), reverse=True)
    return (high + 0.05) / (low + 0.05)


def test_the_high_contrast_colours_pass_wcag_aaa():
    # WCAG 2.1 success criterion 1.4.6 (AAA): at least 7:1; white on black is 21:1
    assert _contrast("#FFFFFF", "#000000") == pytest.approx(21.0)
    for colour in (HIGH_CONTRAST.foreground, HIGH_CONTRAST.primary, HIGH_CONTRAST.warning,
                   HIGH_CONTRAST.accent):
        assert _contrast(colour, HIGH_CONTRAST.background) >= 7.0, colour


@pytest.mark.asyncio
async def test_high_contrast_uses_its_theme_and_dims_nothing(compiled):
    session = WalkSession(compiled)
    session.paused = True
    app = WalkthroughApp(session, high_contrast=True)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        assert app.theme == "opspec-high-contrast"
        timeline = app.query_one("#timeline").render()
        assert all("dim" not in str(span.style) for span in timeline.spans)


class Bells:
    def __init__(self) -> None:
        self.rung = 0

    def bell(self) -> None:
        self.rung += 1


def test_sound_off_is_silent_and_bell_rings():
    app = Bells()
    Cue("off").play(app)
    assert app.rung == 0
    Cue("bell").play(app)
    assert app.rung == 1


def test_the_system_sound_is_a_real_tone_played_by_the_player(tmp_path):
    played = tmp_path / "played.wav"
    player = tmp_path / "player"
    player.write_text(f'#!/bin/sh\ncp "$1" {played}\n')
    player.chmod(0o755)
    cue = Cue("system", player=(str(player),))
    app = Bells()
    cue.play(app)
    assert cue._playing is not None
    cue._playing.wait(timeout=10)
    cue.close()
    assert app.rung == 1                              # the bell too
    with wave.open(str(played)) as tone:
        assert (tone.getnchannels(), tone.getframerate()) == (1, 22_050)
        assert tone.getnframes() / tone.getframerate() == pytest.approx(0.4)


def test_a_player_that_cannot_start_leaves_the_bell():
    cue = Cue("system", player=("/nonexistent/player",))
    app = Bells()
    cue.play(app)
    cue.play(app)
    assert app.rung == 2 and cue.player is None
    cue.close()


@pytest.mark.asyncio
async def test_the_alarm_cue_sounds_at_each_alarm(compiled):
    app_cue = Cue("off")
    session = WalkSession(compiled)
    session.paused = True
    app = WalkthroughApp(session, sound=app_cue)
    async with app.run_test(size=(80, 24)):
        run_until(session, ALARM + 601)               # 08:00, 08:05, 08:10
    assert app_cue.played == 0                        # off: nothing at all
    counted = Cue("bell")
    session = WalkSession(compiled)
    session.paused = True
    app = WalkthroughApp(session, sound=counted)
    async with app.run_test(size=(80, 24)):
        run_until(session, ALARM + 601)
    assert counted.played == 3


def test_a_trigger_caught_with_no_device_activity_at_once_is_not_called_lost():
    from opspec.engine.trace import TraceEvent
    from opspec.tui.feedback import Aftermath

    aftermath = Aftermath(lambda process, activity: activity)
    aftermath.acted("Press the button", None, 60.0)
    # caught by a device start event (quiet): neither kept nor lost, no device work yet
    aftermath(TraceEvent(60.0, "trigger.raised", lane="user", data={"name": "trg_9"}))
    assert aftermath.text() == ("you: Press the button at 00:01 -> sent trg_9 -> no device "
                                "activity at once")


@pytest.mark.asyncio
async def test_x_at_a_choice_names_the_choice_it_leaves_undone(compiled, tmp_path):
    """``x`` at "Press a button" omits the whole choice (the recording says ``omit
    choose_button``): the panel said 'you: not: Press "report"', as if the person had
    passed on one button and the other were still theirs to press."""
    session = WalkSession(compiled, record=tmp_path / "walk.json")
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space", "u", "a", "a")   # 08:00: heard, walked over
        await pilot.pause()
        assert [o.label for o in session.offers] == ['Press "report"',
                                                     "Press the wrong button"]
        await pilot.press("x")
        await pilot.pause()
        said = session.aftermath.text()
        assert said.startswith("you did not: Press a button at 08:00"), said
        assert not session.offers
    assert "omit choose_button #4" in (tmp_path / "walk.json").read_text(encoding="utf-8")


@pytest.mark.asyncio
async def test_x_is_not_called_your_own_action(compiled):
    """``x`` at "Hear the alarm" said 'you: not: Hear the alarm at 08:00 -> your own action,
    nothing sent to the device': an action the person did not do is not their action."""
    session = WalkSession(compiled)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space", "u")             # 08:00: the alarm
        await pilot.pause()
        assert [o.label for o in session.offers] == ["Hear the alarm"]
        await pilot.press("x")
        await pilot.pause()
        assert session.aftermath.text() == ("you did not: Hear the alarm at 08:00 -> nothing "
                                            "sent to the device")
