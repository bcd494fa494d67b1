"""Time controls never block the keys: a skip runs in slices between key presses, the run
is as long as the spec says (opspec:RunLength), and the end shows at 80 columns."""

from __future__ import annotations

import pytest
from walkthrough_inputs import ROOT

from opspec.engine.compiled import compile_package
from opspec.errors import ConfigurationError
from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

VACUUM = ROOT / "specs" / "vacuum_cleaner.xpdl"


@pytest.fixture(scope="module")
def vacuum():
    return compile_package(open_spec(VACUUM))


def status(app: WalkthroughApp) -> str:
    return str(app.query_one("#status").render())


def test_the_run_is_as_long_as_the_specs_run_length_unless_days_say_otherwise(vacuum,
                                                                               compiled):
    assert vacuum.package.run_length == 4500.0
    assert WalkSession(vacuum).horizon == 4500.0          # PT75M, as `opspec run` does
    assert WalkSession(vacuum, days=0.5).horizon == 43_200.0
    assert WalkSession(compiled).horizon == 86_400.0      # no RunLength: one day


@pytest.mark.parametrize("days", [0, -1, float("inf")], ids=["zero", "negative", "infinite"])
def test_days_that_are_not_positive_are_refused(compiled, days):
    with pytest.raises(ConfigurationError, match="days must be a positive number"):
        WalkSession(compiled, days=days)


def test_a_bounded_skip_stops_early_and_goes_on_where_it_stopped(vacuum):
    session = WalkSession(vacuum, days=0.002)           # 172.8 s: a few thousand events
    session.skip_until_user(budget=50)
    assert session.skipping and not session.ended     # 50 events: far from the end
    first = session.now
    session.advance(0.0, budget=50)
    assert session.now >= first and session.skipping
    for _ in range(100_000):
        if not session.skipping:
            break
        session.advance(0.0, budget=500)
    assert session.ended and session.now == pytest.approx(172.8)


@pytest.mark.asyncio
async def test_skipping_on_a_spec_without_a_user_lane_leaves_the_keys_working(vacuum):
    session = WalkSession(vacuum)
    app = WalkthroughApp(session, title="vacuum")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space")
        await pilot.press("u")
        # the key returned at once: the skip goes on in slices between key presses
        assert session.skipping and not session.ended
        assert "skipping" in status(app) and "no user lane" in status(app)
        await pilot.press("u")                          # u again stops the skip
        assert not session.skipping
        stopped = session.now
        await pilot.pause(0.3)
        assert session.now == stopped                   # (paused)
        await pilot.press("q")
    assert app.return_value is None


@pytest.mark.asyncio
async def test_the_end_of_the_run_shows_at_80_columns(compiled):
    session = WalkSession(compiled, days=0.05)
    app = WalkthroughApp(session, title="Smart medication dispenser and its user")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space", "u")
        await pilot.pause()
        assert session.ended
        assert "[ENDED]" in status(app)
        assert "press u" not in str(app.query_one("#call").render())


@pytest.mark.parametrize(("args", "message"), [
    (["--days", "-1"], "--days must be a positive number, not -1"),
    (["--days", "0"], "--days must be a positive number, not 0"),
    (["--record", "/proc/no/such/walk.json"], "cannot write the recording /proc/no/such"),
], ids=["negative-days", "zero-days", "unwritable-record"])
def test_the_command_refuses_bad_options_with_a_clear_message(args, message, capsys):
    from walkthrough_inputs import SPEC

    from opspec.cli import main

    assert main(["walkthrough", str(SPEC), *args]) == 2
    err = capsys.readouterr().err
    assert message in err and "internal error" not in err


@pytest.mark.asyncio
async def test_after_the_end_nothing_is_offered_and_keys_do_nothing(compiled, tmp_path):
    session = WalkSession(compiled, days=0.35, record=tmp_path / "end.json")   # to 08:24
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space")
        for _ in range(6):                             # 08:00, 08:05, 08:10, the end
            if not session.ended:
                await pilot.press("u")
        assert session.ended and session.offers        # the engine still holds the offer
        assert not app.query("#offers Static")
        await pilot.press("a", "x")
        assert "hear_alarm" not in (tmp_path / "end.json").read_text(encoding="utf-8")
