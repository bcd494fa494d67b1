"""A participant's session performed through Textual's Pilot (the terminal walkthrough)."""

from __future__ import annotations

from typing import Any


async def perform(app: Any, walk: Any, *, until_end: bool = True) -> str:
    """The participant reads the briefing, starts, hands the lane to the model (a stand-in
    for their own key presses) and skips to the end; or quits half-way."""
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        told = str(app.screen.query_one("#brief-text").render())
        assert walk.paused                           # the clock waits for the briefing
        await pilot.press("enter")
        assert not walk.paused
        await pilot.press("h")
        if until_end:
            for _ in range(500):                     # a bound, not a time limit
                if walk.ended:
                    break
                await pilot.press("u")
                await pilot.pause()
            assert walk.ended
        await pilot.press("q")
    return told
