"""`--days 0.7` ends the run at 16:48:00, not 16:47:59.

0.7 days in seconds as a float product is 60479.99999999999, and the clock, shown to the
whole second, said the run ended at d1 16:47:59: on the status line and in the summary. The
walkthrough takes the days as the decimal number written."""

from __future__ import annotations

import pytest

from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession


def _to_the_end(session: WalkSession) -> WalkSession:
    session.hand_over()
    while not session.ended:
        session.run_to(session.horizon)
    return session


@pytest.mark.parametrize(("days", "seconds", "shown"), [
    (0.7, 60_480.0, "d1 16:48:00"),
    (0.35, 30_240.0, "d1 08:24:00"),
    (2.3, 198_720.0, "d3 07:12:00"),
    (0.5, 43_200.0, "d1 12:00:00"),
])
def test_a_fractional_day_ends_on_its_second(compiled, model_factory, days, seconds, shown):
    session = _to_the_end(WalkSession(compiled, days=days, model_factory=model_factory))
    assert session.horizon == seconds and session.now == seconds
    assert session.summary_lines()[0] == f"The run ended at {shown}."


@pytest.mark.asyncio
async def test_the_status_line_shows_the_end_of_a_fractional_day(compiled, model_factory):
    session = _to_the_end(WalkSession(compiled, days=0.7, model_factory=model_factory))
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        status = str(app.screen_stack[0].query_one("#status").render())
        assert status.startswith("d1 16:48:00") and "[ENDED]" in status
