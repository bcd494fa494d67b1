"""On a terminal narrower than the help's 72-column box (``--large`` works down to 64 x 20,
whose help box is 64 wide) Textual wrapped the help's lines at the box's first column:
"click it)", "stop)", "back" stood under the keys, as if they were keys. The help is now
written for the width its box has: no line is wrapped by the screen, and what a key does
continues under what it does."""

from __future__ import annotations

import pytest
from rich.text import Text

from opspec.tui.app import WalkthroughApp
from opspec.tui.modals import HelpScreen
from opspec.tui.session import WalkSession


async def _shown(app: WalkthroughApp, pilot) -> list[str]:
    await pilot.press("question_mark")
    await pilot.pause()
    assert isinstance(app.screen, HelpScreen)
    widget = app.screen.query_one("#help-text")
    lines = app.screen.text.splitlines()
    inner = widget.content_region
    assert inner.height == len(lines), "a help line wrapped"
    assert max(Text.from_markup(line).cell_len for line in lines) <= inner.width
    return [Text.from_markup(line).plain for line in lines]


@pytest.mark.asyncio
@pytest.mark.parametrize(("size", "large"), [((64, 20), True), ((60, 20), False)])
async def test_the_help_is_written_for_a_narrow_box(compiled, model_factory, size, large):
    session = WalkSession(compiled, model_factory=model_factory)     # every key works
    session.paused = True
    app = WalkthroughApp(session, large=large)
    async with app.run_test(size=size) as pilot:
        lines = await _shown(app, pilot)
        start = lines.index("  a b c…  do the action shown next to its letter (or")
        assert lines[start + 1] == " " * 10 + "click it)"
        # a line of the keys that names no key is the text of the key above it
        keys = lines[2:lines.index("", 2)]
        assert all(line.startswith(" " * 10) for line in keys if line.startswith(" " * 3))
        await pilot.press("q")


@pytest.mark.asyncio
async def test_the_help_follows_the_terminal_when_it_is_resized(compiled, model_factory):
    session = WalkSession(compiled, model_factory=model_factory)
    session.paused = True
    app = WalkthroughApp(session, large=True)
    async with app.run_test(size=(64, 20)) as pilot:
        narrow = await _shown(app, pilot)
        await pilot.resize_terminal(100, 40)
        await pilot.pause()
        wide = [Text.from_markup(line).plain for line in app.screen.text.splitlines()]
        assert "  a b c…  do the action shown next to its letter (or click it)" in wide
        assert len(wide) < len(narrow)
        await pilot.press("q")
