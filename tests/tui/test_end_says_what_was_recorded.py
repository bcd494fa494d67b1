"""When the run has ended the person's panel says what quitting keeps: a recorded session
keeps its recording; a replay records nothing, nor does a session run with `--no-record`.
Before, every ended run said "the recording is kept", a replay's too."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.tui.app import SummaryScreen, WalkthroughApp
from opspec.tui.replay import load_recording
from opspec.tui.session import WalkSession

UNTIL = 9 * 3600.0          # past the 08:00 dose


async def _ended_panel(session: WalkSession) -> str:
    """The person's panel once the run has ended (the summary that opens by itself
    closed)."""
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.press("space")                  # time moves by keys only
        for _ in range(50):
            if session.ended:
                break
            await pilot.press("u")
            while session.skipping:
                await pilot.pause(0.05)
        await pilot.pause(0.2)
        assert session.ended
        if isinstance(app.screen, SummaryScreen):
            await pilot.press("escape")
        text = str(app.query_one("#call").render())
        await pilot.press("q")
    return text


def _recording(tmp_path: Path) -> Path:
    record = tmp_path / "walk.json"
    record.write_text('{"otherwise": "wait", "steps": [["at 28830.0", "complete hear_alarm"],'
                      ' ["at 28890.0", "complete walk_to_dispenser"],'
                      ' ["at 28890.0", "choose press_report"],'
                      ' ["at 28900.0", "complete take_pill"]]}', encoding="utf-8")
    return record


@pytest.mark.asyncio
async def test_a_replay_that_has_ended_does_not_say_a_recording_is_kept(compiled, tmp_path):
    session = WalkSession(compiled, until=UNTIL,
                          replay=load_recording(_recording(tmp_path), compiled))
    text = await _ended_panel(session)
    assert "recording is kept" not in text
    assert text == "(the replay has ended: q quits; a replay records nothing)"


@pytest.mark.asyncio
async def test_a_session_ended_says_whether_its_recording_is_kept(compiled, tmp_path,
                                                                 model_factory):
    recorded = WalkSession(compiled, until=UNTIL, record=tmp_path / "kept.json",
                           model_factory=model_factory)
    recorded.hand_over()
    assert await _ended_panel(recorded) == "(the run has ended: q quits, the recording is kept)"
    unrecorded = WalkSession(compiled, until=UNTIL, model_factory=model_factory)
    unrecorded.hand_over()
    assert await _ended_panel(unrecorded) == "(the run has ended: q quits; nothing was recorded)"
