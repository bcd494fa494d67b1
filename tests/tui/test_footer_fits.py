"""The footer names every key it shows, on the usual 80-column lab terminal too.

At 80 x 24 the spaced-out footer ran past the edge: "h model/me" (hand the lane to the user
model) was cut and only reachable through the help screen."""

from __future__ import annotations

import pytest
from textual.widgets import Footer
from textual.widgets._footer import FooterKey

from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession


def _app(compiled) -> WalkthroughApp:
    session = WalkSession(compiled)
    session.paused = True
    return WalkthroughApp(session, title="Smart medication dispenser")


@pytest.mark.asyncio
@pytest.mark.parametrize("width", [80, 100, 132])
async def test_every_footer_key_is_on_screen(compiled, width):
    app = _app(compiled)
    async with app.run_test(size=(width, 24)) as pilot:
        await pilot.pause()
        keys = list(app.query_one(Footer).query(FooterKey))
        shown = {key.key for key in keys}
        # the keys a person needs to run the session: pause, help, quit, speed, wait, step,
        # until me, hand over
        assert {"space", "question_mark", "q", "1", "w", "n", "u", "h"} <= shown
        for key in keys:
            assert key.region.right <= width, f"{key.key} is cut at {width} columns"


@pytest.mark.asyncio
async def test_footer_closes_up_only_when_it_must(compiled):
    app = _app(compiled)
    async with app.run_test(size=(120, 24)) as pilot:
        await pilot.pause()
        assert not app.query_one(Footer).compact
        await pilot.resize_terminal(80, 24)
        await pilot.pause()
        assert app.query_one(Footer).compact
        await pilot.resize_terminal(120, 24)
        await pilot.pause()
        assert not app.query_one(Footer).compact


@pytest.mark.asyncio
async def test_every_footer_key_of_a_spec_without_a_user_lane_fits_64_columns_large():
    """With --large at 64 x 20 (the smallest it is made for) the footer of a spec without a
    user lane (or of a replay) ended in "u to the e": its last key's words were cut."""
    from pathlib import Path

    from opspec.engine.compiled import compile_package
    from opspec.xpdl.open_spec import open_spec

    vacuum = Path(__file__).resolve().parents[2] / "specs" / "vacuum_cleaner.xpdl"
    session = WalkSession(compile_package(open_spec(vacuum)))
    session.paused = True
    app = WalkthroughApp(session, title="Automatic vacuum cleaner", large=True)
    async with app.run_test(size=(64, 20)) as pilot:
        await pilot.pause()
        keys = list(app.query_one(Footer).query(FooterKey))
        assert "u" in {key.key for key in keys}
        for key in keys:
            assert key.region.right <= 64, f"{key.key} is cut at 64 columns"
