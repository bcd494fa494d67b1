"""A spec without a user lane (the vacuum cleaner): ``h`` says there is no lane to hand over.

It said "No user model: start with --user-model FILE|PRESET.", sending the coordinator off
to restart the session with a model that would have had nothing to do; with a model given,
it "handed over" a lane that does not exist."""

from __future__ import annotations

from pathlib import Path

import pytest

from opspec.engine.compiled import compile_package
from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

VACUUM = Path(__file__).resolve().parents[2] / "specs" / "vacuum_cleaner.xpdl"


@pytest.mark.asyncio
@pytest.mark.parametrize("with_model", [False, True])
async def test_h_says_the_spec_has_no_user_lane(with_model, model_factory):
    session = WalkSession(compile_package(open_spec(VACUUM)),
                          model_factory=model_factory if with_model else None)
    assert not session.has_user_lane
    app = WalkthroughApp(session, title="Automatic vacuum cleaner")
    said: list[str] = []
    async with app.run_test(size=(80, 24)) as pilot:
        app.notify = lambda message, **_: said.append(message)   # type: ignore[method-assign]
        await pilot.press("space", "h")
        await pilot.pause()
        assert said == ["This spec has no user lane: there is nothing to hand over."]
        assert not session.handed_over
        assert "no user lane" in str(app.query_one("#status").render())
