"""Below the smallest terminal the layout is made for (80 x 24; 64 x 20 with --large) a line
at the top says so and what size to make it, for as long as the terminal is smaller.

At 60 x 15 the footer's keys were cut mid-word ("u un"), the panels scrolled and the timeline
dropped off, with nothing saying why or what to do."""

from __future__ import annotations

import pytest
from textual.widgets import Footer

from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession

WARNING = "#too-small"


def _app(compiled, large: bool = False) -> WalkthroughApp:
    session = WalkSession(compiled)
    session.paused = True
    return WalkthroughApp(session, title="Smart medication dispenser", large=large)


def _said(app: WalkthroughApp) -> str:
    line = app.screen_stack[0].query_one(WARNING)
    return str(line.render()) if line.display else ""


@pytest.mark.asyncio
@pytest.mark.parametrize(("size", "large", "least"), [
    ((60, 15), False, "80x24"), ((79, 24), False, "80x24"), ((80, 23), False, "80x24"),
    ((60, 15), True, "64x20"), ((63, 20), True, "64x20")])
async def test_a_terminal_too_small_is_told_what_size_to_be(compiled, size, large, least):
    app = _app(compiled, large)
    async with app.run_test(size=size) as pilot:
        await pilot.pause()
        width, height = size
        assert _said(app) == (f"Terminal {width}x{height} is too small: make it at least "
                              f"{least}")
        line = app.screen_stack[0].query_one(WARNING)
        assert line.region.y == 0                    # on top: read first, never under the
        assert not line.region.overlaps(app.query_one(Footer).region)    # footer


@pytest.mark.asyncio
@pytest.mark.parametrize(("size", "large"), [((80, 24), False), ((120, 40), False),
                                             ((64, 20), True)])
async def test_at_the_documented_sizes_nothing_is_said(compiled, size, large):
    app = _app(compiled, large)
    async with app.run_test(size=size) as pilot:
        await pilot.pause()
        assert _said(app) == ""
        status = app.screen_stack[0].query_one("#status")
        assert status.region.y == 0                  # the layout as it was


@pytest.mark.asyncio
async def test_the_line_goes_when_the_terminal_is_made_bigger(compiled):
    app = _app(compiled)
    async with app.run_test(size=(60, 15)) as pilot:
        await pilot.pause()
        assert _said(app)
        await pilot.press("question_mark")          # under the help screen too
        await pilot.resize_terminal(100, 30)
        await pilot.pause()
        await pilot.press("escape")
        await pilot.pause()
        assert _said(app) == ""
        await pilot.resize_terminal(70, 24)
        await pilot.pause()
        assert _said(app).startswith("Terminal 70x24 is too small")
