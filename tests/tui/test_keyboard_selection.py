"""A participant who does not use the letters can pick an action with the arrow keys (or
Tab) and do it with Enter, the way buttons are worked without a mouse.

Tab, the arrows and Enter did nothing at all: the offers (tall bordered buttons with
``--large``) could only be done by their letter or a click."""

from __future__ import annotations

import pytest

from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession


async def offers_text(pilot, app: WalkthroughApp) -> str:
    await pilot.pause()                 # the offers are mounted anew at each refresh
    return "\n".join(str(w.render()) for w in app.query(".offer"))


@pytest.mark.asyncio
async def test_arrows_or_tab_pick_an_action_and_enter_does_it(compiled, tmp_path):
    session = WalkSession(compiled, record=tmp_path / "walk.json")
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space", "u")                 # 08:00: the alarm
        await pilot.pause()
        assert "<- Enter" not in await offers_text(pilot, app)       # nothing picked: Enter does nothing
        await pilot.press("enter")
        assert [o.item.activity for o in session.offers] == ["hear_alarm"]
        await pilot.press("down")
        assert "[a] Hear the alarm  <- Enter" in await offers_text(pilot, app)
        await pilot.press("enter", "tab", "enter")      # heard; walked over
        await pilot.pause()
        assert [o.label for o in session.offers] == ['Press "report"',
                                                     "Press the wrong button"]
        await pilot.press("tab", "tab")                 # the second button
        assert '[b] Press the wrong button  <- Enter' in await offers_text(pilot, app)
        await pilot.press("shift+tab", "up")            # back to the first; wraps round
        assert '[b] Press the wrong button  <- Enter' in await offers_text(pilot, app)
        await pilot.press("up", "enter")                # Press "report"
        await pilot.pause()
        assert [o.item.activity for o in session.offers] == ["take_pill"]
        await pilot.press("down")                       # "Take the pill" picked
        assert "[a] Take the pill  <- Enter" in await offers_text(pilot, app)
        await pilot.press("question_mark", "down", "tab", "enter")   # the help: not done
        await pilot.pause()
        assert [o.item.activity for o in session.offers] == ["take_pill"]
    steps = (tmp_path / "walk.json").read_text(encoding="utf-8")
    assert "choose press_report #4" in steps and "press_wrong_button" not in steps
