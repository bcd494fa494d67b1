"""The help screen (``?``) shows each line of its text on one line of the screen.

Its box is 70 columns wide (64 for the text inside border and padding); lines written wider
wrapped mid-sentence ("… (or pauses," / "with --on-call pause) …", "(x) a device fault," /
"> what …"), which read as broken on every terminal size."""

from __future__ import annotations

import pytest
from rich.text import Text

from opspec.tui.app import HELP, WalkthroughApp
from opspec.tui.modals import HelpScreen
from opspec.tui.session import WalkSession


@pytest.mark.asyncio
@pytest.mark.parametrize("size", [(80, 40), (120, 40)])
async def test_help_lines_are_not_wrapped(compiled, model_factory, size):
    session = WalkSession(compiled, model_factory=model_factory)   # every key works
    session.paused = True
    app = WalkthroughApp(session, title="Smart medication dispenser")
    async with app.run_test(size=size) as pilot:
        await pilot.press("question_mark")
        await pilot.pause()
        assert isinstance(app.screen, HelpScreen)
        shown = app.screen.text
        assert len(shown.splitlines()) == len(HELP.splitlines())   # (it records nothing)
        help_text = app.screen.query_one("#help-text")
        inner = help_text.content_region
        assert inner.height == len(shown.splitlines()), "a help line wrapped"
        widest = max(Text.from_markup(line).cell_len for line in shown.splitlines())
        assert widest <= inner.width
