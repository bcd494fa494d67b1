"""``h`` with nothing to hand over says why: a spec without a user lane (the vacuum cleaner),
or a run that has ended.

It said "No user model: start with --user-model FILE|PRESET.", sending the coordinator off
to restart the session with a model that would have had nothing to do; with a model given,
it "handed over" a lane that does not exist."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.engine.compiled import compile_package
from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

VACUUM = Path(__file__).resolve().parents[2] / "specs" / "vacuum_cleaner.xpdl"


@pytest.mark.asyncio
@pytest.mark.parametrize("with_model", [False, True])
async def test_h_says_the_spec_has_no_user_lane(with_model, model_factory):
    session = WalkSession(compile_package(open_spec(VACUUM)),
                          model_factory=model_factory if with_model else None)
    assert not session.has_user_lane
    app = WalkthroughApp(session, title="Automatic vacuum cleaner")
    said: list[str] = []
    async with app.run_test(size=(80, 24)) as pilot:
        app.notify = lambda message, **_: said.append(message)   # type: ignore[method-assign]
        await pilot.press("space", "h")
        await pilot.pause()
        assert said == ["This spec has no user lane: there is nothing to hand over."]
        assert not session.handed_over
        assert "no user lane" in str(app.query_one("#status").render())


@pytest.mark.asyncio
async def test_h_after_the_end_of_the_run_hands_nothing_over(compiled, model_factory):
    """After the run ended, h said "The user model performs your lane; press h to take it
    back." and the status line "[ENDED] | model performs your lane"."""
    session = WalkSession(compiled, days=0.25, model_factory=model_factory)   # to 06:00
    app = WalkthroughApp(session, title="Smart medication dispenser")
    said: list[str] = []
    async with app.run_test(size=(80, 24)) as pilot:
        app.notify = lambda message, **_: said.append(message)   # type: ignore[method-assign]
        await pilot.press("space", "u")                # nothing calls before 06:00: the end
        for _ in range(100):
            if session.ended:
                break
            await pilot.pause(0.02)
        assert session.ended
        await pilot.press("escape", "h")               # close the summary; hand over
        await pilot.pause()
        assert said == ["The run has ended: there is nothing to hand over (q quits)."]
        assert not session.handed_over
        assert "you perform the lane" in str(app.query_one("#status").render())


@pytest.mark.asyncio
async def test_a_replay_of_it_does_not_say_the_recording_performs_your_lane(tmp_path):
    """A replay of a vacuum-cleaner session said "replaying the recording", "(the recording
    performs your lane: …)" and, in its help, "the recording performs your lane": the spec
    has no user lane, and the recording holds no step."""
    from opspec.tui.replay import load_recording

    compiled = compile_package(open_spec(VACUUM))
    script = tmp_path / "vacuum.json"
    script.write_text('{"otherwise": "wait", "steps": []}', encoding="utf-8")
    session = WalkSession(compiled, replay=load_recording(script, compiled))
    session.paused = True
    app = WalkthroughApp(session, title="Automatic vacuum cleaner")
    async with app.run_test(size=(100, 50)) as pilot:
        await pilot.pause()
        assert "|  no user lane  |" in str(app.query_one("#status").render())
        assert str(app.query_one("#call").render()) == (
            "(this spec has no user lane: watch the device; u skips to the end)")
        await pilot.press("question_mark")
        await pilot.pause()
        shown = " ".join(app.screen.text.split())
        assert "This is a replay: this spec has no user lane, so nothing waits" in shown
        assert "performs your lane" not in shown
        await pilot.press("escape")
        await pilot.press("q")
