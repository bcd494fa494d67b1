"""The summary so far (``s``) prints the commands that replay the session up to where it
stands: with ``--until`` the second it shows, so that they print the numbers it shows.

Before, they had ``--until`` only once the session was quit: opened at 08:00:30, the
summary so far showed one dose due and none missed, and its `opspec run ... --script REC`
ran the recording on to d2 00:00, every later dose missed."""

from __future__ import annotations

import shlex

import pytest

from walkthrough_inputs import SPEC
from opspec.cli import main
from opspec.run_rules import parse_until
from opspec.tui.app import SummaryScreen, WalkthroughApp
from opspec.tui.session import WalkSession


def _metrics(lines: list[str]) -> list[str]:
    return [line for line in lines if line.startswith("  ") and (
        "doses" in line or "alarms" in line or "rate" in line)]


@pytest.mark.asyncio
async def test_the_summary_so_far_replays_to_where_the_session_stands(compiled, tmp_path,
                                                                     capsys):
    record = tmp_path / "walk.json"
    session = WalkSession(compiled, record=record, spec_path=str(SPEC))
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 40)) as pilot:
        await pilot.press("space", "u", "a", "w")         # 08:00: hear the alarm; 30 s
        await pilot.press("s")
        await pilot.pause()
        assert isinstance(app.screen, SummaryScreen)
        shown = app.screen.lines
        at = session.now
        await pilot.press("escape", "q")
    assert shown[0].startswith("So far, at d1 08:00:")
    walk, run = (shlex.split(line.split(":", 1)[1]) for line in shown
                 if line.startswith(("Replay it with:", "           or:")))
    assert parse_until(walk[walk.index("--until") + 1]) == at          # exactly
    assert parse_until(run[run.index("--until") + 1]) == at
    mine = _metrics(shown)
    assert any(line.split() == ["doses_due", "1"] for line in mine)

    capsys.readouterr()
    assert main([*run[1:], "--timeline", "none"]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert mine == _metrics(printed)                      # the numbers it showed
