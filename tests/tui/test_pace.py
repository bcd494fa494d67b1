"""The status line says the speed the clock really keeps when the engine cannot simulate the
spec at the speed asked.

The vacuum cleaner at ``--speed 600`` ran at about 80x in a real terminal (its sensing loops
are many events per simulated second; the engine runs in slices so that keys are read), while
the status line said "600x": a coordinator timing a session by it was misled eightfold."""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec.tui.app as app_module
from opspec.engine.compiled import compile_package
from opspec.tui.app import WalkthroughApp
from opspec.tui.pace import Pace
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

VACUUM = Path(__file__).resolve().parents[2] / "specs" / "vacuum_cleaner.xpdl"


def status(app: WalkthroughApp) -> str:
    return str(app.query_one("#status").render())


@pytest.mark.asyncio
async def test_a_clock_that_falls_behind_says_its_real_speed(monkeypatch):
    # one engine step per tick: no machine simulates the vacuum at 600x so (one slice of
    # the usual size per tick was not enough: a fast machine with the compiled engine kept
    # up, and the test then failed on a quiet machine only; and until _run_slices read
    # SLICE_S at the call, its default had bound the usual 0.08 s, so a tick stepped one
    # event at a time for that long: once the engine's periodic path was 6 % faster, it
    # kept 94 % of 600x so, short of the 90 % that is said, and the test failed in CI)
    monkeypatch.setattr(app_module, "SLICE_S", 0.0)
    monkeypatch.setattr(app_module, "SLICE_STEPS", 1)
    session = WalkSession(compile_package(open_spec(VACUUM)))
    session.speed = 600.0
    app = WalkthroughApp(session, title="Automatic vacuum cleaner")
    async with app.run_test(size=(100, 24)) as pilot:
        await pilot.pause(3.0)
        shown = status(app)
        assert "600x (really " in shown, shown
        rate = float(shown.split("(really ", 1)[1].split("x)", 1)[0])
        assert 0 < rate < 540
        await pilot.press("space")                 # paused: nothing to measure
        await pilot.pause()
        assert "really" not in status(app) and "600x  PAUSED" in status(app)


@pytest.mark.asyncio
async def test_a_clock_that_keeps_up_says_nothing_more(compiled):
    session = WalkSession(compiled)                # the dispenser, idle until 08:00
    session.speed = 600.0
    app = WalkthroughApp(session, title="Smart medication dispenser")
    async with app.run_test(size=(100, 24)) as pilot:
        await pilot.pause(2.5)
        assert "600x  running" in status(app)


def test_the_pace_is_said_after_two_seconds_at_one_speed():
    pace = Pace()
    for _ in range(10):
        pace.ran(0.1, 8.0, 600.0)                  # 80x for one second
    assert pace.shown() == ""                      # not measured long enough
    for _ in range(10):
        pace.ran(0.1, 8.0, 600.0)
    assert pace.shown() == " (really 80x)"
    pace.ran(0.1, 0.1, 1.0)                        # another speed: measured afresh
    assert pace.shown() == ""
    for _ in range(30):
        pace.ran(0.1, 58.0, 600.0)                 # 580x: close enough to say nothing
    assert pace.shown() == ""
