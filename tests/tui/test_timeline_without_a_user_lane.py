"""``l`` on a spec without a user lane (the vacuum cleaner): it cycled to "showing: user", an
empty timeline, and to "showing: device", the same events as "all"; the help offered "all
lanes / device / user". Now the timeline says there is no user lane, ``l`` says so too and
leaves it showing every event, and the help leaves ``l`` out (with ``--large`` it still
hides and shows the timeline)."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.engine.compiled import compile_package
from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

VACUUM = Path(__file__).resolve().parents[2] / "specs" / "vacuum_cleaner.xpdl"


def timeline_box(app: WalkthroughApp) -> list[str]:
    return str(app.query_one("#timeline").render()).splitlines()


@pytest.mark.asyncio
async def test_l_says_there_is_no_user_lane_and_the_timeline_stays_whole():
    session = WalkSession(compile_package(open_spec(VACUUM)))
    session.paused = True
    app = WalkthroughApp(session, title="Automatic vacuum cleaner")
    said: list[str] = []
    async with app.run_test(size=(100, 30)) as pilot:
        app.notify = lambda message, **_: said.append(message)   # type: ignore[method-assign]
        await pilot.press("w")                           # 30 s of events
        await pilot.pause()
        before = timeline_box(app)
        assert before[0] == "showing: all (this spec has no user lane)"
        assert len(before) > 3
        for _ in range(3):
            await pilot.press("l")
            await pilot.pause()
            assert timeline_box(app) == before
        assert said == ["This spec has no user lane: the timeline shows all its events."] * 3
        await pilot.press("question_mark")
        await pilot.pause()
        assert "timeline:" not in app.screen.text
        await pilot.press("escape", "q")


@pytest.mark.asyncio
async def test_large_l_shows_and_hides_the_timeline_of_a_spec_without_a_user_lane():
    session = WalkSession(compile_package(open_spec(VACUUM)))
    session.paused = True
    app = WalkthroughApp(session, title="Automatic vacuum cleaner", large=True)
    async with app.run_test(size=(100, 40)) as pilot:
        await pilot.press("w")
        timeline = app.query_one("#timeline")
        assert timeline.has_class("hidden")              # hidden at start with --large
        await pilot.press("l")
        await pilot.pause()
        assert not timeline.has_class("hidden")
        assert timeline_box(app)[0] == "showing: all (no user lane; l: hide)"
        await pilot.press("l")
        await pilot.pause()
        assert timeline.has_class("hidden")
        await pilot.press("question_mark")
        await pilot.pause()
        assert "timeline: shown / hidden" in app.screen.text
        await pilot.press("escape", "q")


@pytest.mark.asyncio
async def test_with_a_user_lane_l_still_cycles_the_lanes(compiled):
    session = WalkSession(compiled)
    session.paused = True
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        shown = []
        for _ in range(4):
            shown.append(timeline_box(app)[0])
            await pilot.press("l")
            await pilot.pause()
        assert shown == ["showing: all (l: change)", "showing: device (l: change)",
                         "showing: user (l: change)", "showing: all (l: change)"]
        await pilot.press("q")
