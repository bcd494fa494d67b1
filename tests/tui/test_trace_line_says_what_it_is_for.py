"""The summary of a session of a spec without a user lane (the vacuum cleaner) called its
trace "Trace (for opspec fit)": ``opspec fit`` on it fails ("no activity of lane 'user'"),
since nobody performed a lane to fit. It says ``Trace:`` there, and "for opspec fit" where
the spec has a user lane."""

from __future__ import annotations

from pathlib import Path

import pytest

from walkthrough_inputs import SPEC
from opspec.engine.compiled import compile_package
from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

VACUUM = Path(__file__).resolve().parents[2] / "specs" / "vacuum_cleaner.xpdl"


async def _trace_line(session: WalkSession) -> str:
    session.paused = True
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.press("w", "q")
    return next(line for line in session.summary_lines() if line.startswith("Trace"))


@pytest.mark.asyncio
async def test_without_a_user_lane_the_trace_is_not_for_opspec_fit(tmp_path):
    record = tmp_path / "vacuum.json"
    session = WalkSession(compile_package(open_spec(VACUUM)), record=record,
                          spec_path=str(VACUUM))
    assert await _trace_line(session) == f"Trace: {tmp_path / 'vacuum.trace.jsonl'}"


@pytest.mark.asyncio
async def test_with_a_user_lane_it_is(compiled, tmp_path):
    record = tmp_path / "pill.json"
    session = WalkSession(compiled, record=record, spec_path=str(SPEC))
    assert (await _trace_line(session)
            == f"Trace (for opspec fit): {tmp_path / 'pill.trace.jsonl'}")
