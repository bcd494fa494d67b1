"""The status line says why the clock runs in real time: while the device calls, and after
its alarm stopped, while something still waits for the person (the call goes on until then).

Before, after "Press report" stopped the alarm, the status line went on saying "running in
real time: the device calls" over a panel that no longer said so, until the pill was taken."""

from __future__ import annotations

import pytest

from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession


@pytest.mark.asyncio
async def test_the_status_line_says_the_call_goes_on_while_something_waits(compiled):
    session = WalkSession(compiled)
    app = WalkthroughApp(session)
    async with app.run_test(size=(120, 30)) as pilot:
        await pilot.press("u")                                   # 08:00: the alarm
        for _ in range(100):
            if session.offers:
                break
            await pilot.pause(0.02)
        status = str(app.query_one("#status").render())
        assert "1x  running in real time: the device calls" in status
        await pilot.press("a", "a", "a")          # hear it, walk over, press "report"
        await pilot.pause()
        assert not session.calling and [o.label for o in session.offers] == ["Take the pill"]
        status = str(app.query_one("#status").render())
        assert "1x  running in real time while something waits for you" in status
        assert "THE DEVICE CALLS YOU" not in str(app.query_one("#call").render())
        await pilot.press("a")                                   # the pill: the call is over
        await pilot.pause()
        status = str(app.query_one("#status").render())
        assert "60x" in status and "real time" not in status
        await pilot.press("q")
