"""The help (``?``) lists the keys that do something in the session shown, and says what a
replay lets the person do; the footer and the person's panel say the same.

In a replay the help listed "a–z do the action shown next to the letter", x, the arrows and
Enter, "h hand your lane to the user model" and "u skip until something new needs you",
none of which does anything there (the recording performs the lane: nothing is offered to
the person, nothing can be handed over, and u runs to the end of the replay), and said that
the clock drops to real time when the device calls, which a replay never does. The footer
showed "u until me" and "h model/me". The same for a spec without a user lane, and "h" for a
session without a user model. When a run ended while its alarm rang, the person's panel
went on saying "(!) THE DEVICE CALLS YOU" over a run that had ended, and hid the line that
says so."""

from __future__ import annotations

from pathlib import Path

import pytest

from walkthrough_inputs import ROOT
from opspec.engine.compiled import compile_package
from opspec.tui.app import WalkthroughApp
from opspec.tui.modals import HelpScreen
from opspec.tui.replay import load_recording
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

VACUUM = ROOT / "specs" / "vacuum_cleaner.xpdl"
ANSWERING = ("do the action", "an omission", "pick an action", "hand your lane",
             "something new needs you", "your response times")


def _replay(compiled, tmp_path: Path, until: float | None = None) -> WalkSession:
    script = tmp_path / "walk.json"
    script.write_text('{"otherwise": "wait", "steps": [["at 28830.0", "complete hear_alarm"]]}',
                      encoding="utf-8")
    return WalkSession(compiled, replay=load_recording(script, compiled), until=until)


async def _help_and_footer(session: WalkSession, **app_options) -> tuple[str, set[str]]:
    """The help's text as the person reads it, and the footer's keys with their words."""
    session.paused = True
    app = WalkthroughApp(session, **app_options)
    async with app.run_test(size=(100, 50)) as pilot:
        footer = {f"{binding.key} {binding.description}"
                  for _node, binding, enabled, _tip in app.active_bindings.values()
                  if enabled and binding.show}
        await pilot.press("question_mark")
        await pilot.pause()
        assert isinstance(app.screen, HelpScreen)
        text = str(app.screen.query_one("#help-text").render())
        await pilot.press("escape", "q")
    return text, footer


@pytest.mark.asyncio
async def test_the_help_of_a_replay_lists_what_a_replay_does(compiled, tmp_path):
    text, footer = await _help_and_footer(_replay(compiled, tmp_path, until=8 * 3600 + 60.0))
    for words in ANSWERING:
        assert words not in text
    assert "u       skip to the end of the replay (again: stop)" in text
    assert "s       the summary so far (the spec's metrics)" in text
    assert "drops to real time" not in text
    said = " ".join(text.split())
    assert ("This is a replay: the recording performs your lane, so nothing waits for your "
            "answer. Watch it, pause it, change its speed or skip ahead (w, n, u); it is "
            "never slowed down when the device calls, and it ends at d1 08:01:00.") in said
    assert "u to end" in footer and "u until me" not in footer
    assert not any(key.startswith("h ") for key in footer)


@pytest.mark.asyncio
async def test_the_help_of_a_live_session_lists_its_keys(compiled, tmp_path, model_factory):
    text, footer = await _help_and_footer(
        WalkSession(compiled, record=tmp_path / "r.json", model_factory=model_factory))
    for words in ANSWERING[:-1]:
        assert words in text
    assert "This is a replay" not in text
    assert "the clock drops to real time" in " ".join(text.split())
    assert {"u until me", "h model/me"} <= footer

    # without a user model, h hands nothing over: not in the help
    text, _footer = await _help_and_footer(WalkSession(compiled, record=tmp_path / "s.json"))
    assert "hand your lane" not in text and "something new needs you" in text
    # --on-call keep and pause: what the clock does then; --large: l also hides
    text, _footer = await _help_and_footer(WalkSession(compiled, on_call="keep"))
    assert "When the device calls you, the clock keeps its speed." in text
    text, _footer = await _help_and_footer(WalkSession(compiled, on_call="pause"),
                                           large=True)
    said = " ".join(text.split())
    assert "When the device calls you, the clock pauses (space resumes it)." in said
    assert "timeline: all lanes / device / user / hidden" in text


@pytest.mark.asyncio
async def test_the_help_of_a_spec_without_a_user_lane(model_factory):
    session = WalkSession(compile_package(open_spec(VACUUM)), model_factory=model_factory)
    text, footer = await _help_and_footer(session)
    for words in ANSWERING:
        assert words not in text
    assert "u       skip to the end of the run (again: stop)" in text
    assert "This spec has no user lane" in text
    assert "u to end" in footer and not any(key.startswith("h ") for key in footer)


@pytest.mark.asyncio
async def test_h_in_a_replay_still_says_why_it_hands_nothing_over(compiled, tmp_path):
    session = _replay(compiled, tmp_path)
    app = WalkthroughApp(session)
    said: list[str] = []
    async with app.run_test(size=(100, 30)) as pilot:
        app.notify = lambda message, **_: said.append(message)   # type: ignore[method-assign]
        await pilot.press("space", "h")
        await pilot.pause()
        await pilot.press("q")
    assert said == ["The recording performs your lane: there is nothing to hand over."]


@pytest.mark.asyncio
async def test_a_run_that_ended_while_the_alarm_rang_calls_nobody(compiled, tmp_path):
    session = _replay(compiled, tmp_path, until=8 * 3600 + 60.0)   # the 08:00 alarm rings
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.press("u")                          # to the end of the replay
        for _ in range(200):
            if session.ended:
                break
            await pilot.pause(0.02)
        assert session.ended and session.board.ringing
        await pilot.press("escape")                     # the summary that opened
        await pilot.pause()
        panel = str(app.query_one("#call").render())
        device = app._device_text().plain
        await pilot.press("q")
    assert "THE DEVICE CALLS YOU" not in panel
    assert panel == "(the replay has ended: q quits; a replay records nothing)"
    # the device panel shows the state the run ended in, with no countdown that never ends
    assert "alarm: at the end: ((( RINGING ))) since 08:00" in device
    assert "deadline " not in device and "Running when the run ended:" in device
