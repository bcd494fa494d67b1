"""The help (``?``) and the summary (``s``, and at the end of the run) say how to close them
and can be read whole on the usual 80 x 24 lab terminal, with the keys alone.

Neither fits in 24 rows. The help was a plain text box cut at the bottom: its last lines,
"Press escape or ? to close." among them, could not be reached by any key, and nothing on
the screen said how to get back to the session. The summary scrolled, but said how to close
it only at its very end, below the edge of the screen."""

from __future__ import annotations

import html
import re

import pytest
from textual.containers import VerticalScroll

from opspec.tui.app import HELP, WalkthroughApp
from opspec.tui.session import WalkSession


def visible(app: WalkthroughApp) -> str:
    """The text on the screen as the participant sees it (cut where the terminal ends)."""
    svg = app.export_screenshot()
    return html.unescape(re.sub(r"<[^>]+>", "", svg)).replace("\xa0", " ")


def _app(compiled, model_factory=None) -> WalkthroughApp:
    session = WalkSession(compiled, model_factory=model_factory)
    session.paused = True
    return WalkthroughApp(session, title="Smart medication dispenser")


@pytest.mark.asyncio
@pytest.mark.parametrize("size", [(80, 24), (64, 20)])
async def test_help_says_how_to_close_and_scrolls_to_its_end(compiled, model_factory, size):
    app = _app(compiled, model_factory)             # every key: the longest help
    async with app.run_test(size=size) as pilot:
        await pilot.press("question_mark")
        await pilot.pause()
        assert "escape or ?: close" in visible(app)
        assert "Press escape or ? to close." not in visible(app)   # it does not fit
        for _ in range(len(HELP.splitlines())):
            await pilot.press("down")
        await pilot.pause()
        assert "Press escape or ? to close." in visible(app)
        if size[0] >= 80:       # the scrollbar does not wrap the help's lines
            inner = app.screen.query_one("#help-text").content_region
            assert inner.height == len(HELP.splitlines()), "a help line wrapped"
        await pilot.press("escape")
        await pilot.pause()
        assert not app.screen.query(VerticalScroll) or "escape or ?" not in visible(app)


@pytest.mark.asyncio
async def test_end_summary_says_how_to_close_at_80x24(compiled, model_factory, tmp_path):
    session = WalkSession(compiled, record=tmp_path / "walk.json", model_factory=model_factory)
    app = WalkthroughApp(session, title="Smart medication dispenser")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space", "h")        # paused; the model performs the lane
        for _ in range(400):                   # skip call by call to the end of the day
            if session.ended:
                break
            if not session.skipping:
                await pilot.press("u")
            await pilot.pause(0.05)
        await pilot.pause()
        assert session.ended
        text = visible(app)
        assert "The run ended at" in text
        assert "escape: close" in text
