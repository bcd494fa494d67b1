"""Once the run has ended, the footer offered "space pause  1-4 speed  w wait 30s  n step
u until me  h model/me" and the help listed them too: keys that did nothing any more (the
clock has nowhere to go). The footer now shows what is left, with the summary, which was only
in the help; the help lists what is left and says why the rest is gone; ``h`` still says why
there is nothing to hand over."""

from __future__ import annotations

import pytest
from textual.widgets import Footer
from textual.widgets._footer import FooterKey

from opspec.tui.app import WalkthroughApp
from opspec.tui.modals import SummaryScreen
from opspec.tui.session import WalkSession


def footer_keys(app: WalkthroughApp) -> set[str]:
    return {key.key for key in app.query_one(Footer).query(FooterKey)}


@pytest.mark.asyncio
async def test_after_the_end_the_footer_and_help_offer_what_is_left(compiled, model_factory):
    session = WalkSession(compiled, days=0.25, model_factory=model_factory)   # to 06:00
    app = WalkthroughApp(session, title="Smart medication dispenser")
    said: list[str] = []
    async with app.run_test(size=(100, 30)) as pilot:
        app.notify = lambda message, **_: said.append(message)   # type: ignore[method-assign]
        await pilot.press("space")
        await pilot.pause()
        assert {"space", "1", "w", "n", "u", "h"} <= footer_keys(app)
        assert "s" not in footer_keys(app)
        await pilot.press("u")                           # nothing calls before 06:00: the end
        for _ in range(100):
            if session.ended:
                break
            await pilot.pause(0.02)
        await pilot.pause()
        assert isinstance(app.screen, SummaryScreen)     # opened by itself
        await pilot.press("escape")
        await pilot.pause()
        assert footer_keys(app) == {"question_mark", "q", "s"}
        await pilot.press("s")                           # the summary comes back
        await pilot.pause()
        assert isinstance(app.screen, SummaryScreen)
        await pilot.press("escape", "h")
        await pilot.pause()
        assert said == ["The run has ended: there is nothing to hand over (q quits)."]
        await pilot.press("question_mark")
        await pilot.pause()
        text = app.screen.text
        assert "The run has ended" in text
        for gone in ("pause / resume", "speed:", "30 simulated seconds", "step:", "skip"):
            assert gone not in text
        assert "the summary of the run" in text and "quit (the recording" not in text
        await pilot.press("escape", "q")
