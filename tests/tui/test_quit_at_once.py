"""A session quit before its clock first moved (``q`` at once, or paused from the start)
printed ``opspec run SPEC --until 0.0 --script REC`` and ``opspec walkthrough SPEC --replay
REC --until 0.0``: both commands refuse ``--until 0.0`` ("must be a positive number of
seconds"). Such a session has nothing to replay: the summary says so, and every command it
prints runs."""

from __future__ import annotations

import shlex

import pytest

from walkthrough_inputs import SPEC
from opspec.cli import main
from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession


def _commands(lines: list[str]) -> list[list[str]]:
    """The commands the summary tells the person to run, split as a shell splits them."""
    return [shlex.split(line.split(":", 1)[1]) for line in lines
            if line.strip().startswith(("Replay it with: opspec", "or: opspec"))]


@pytest.mark.asyncio
async def test_quit_at_once_prints_no_command_that_fails(compiled, tmp_path, capsys):
    record = tmp_path / "at once.json"
    session = WalkSession(compiled, record=record, spec_path=str(SPEC))
    session.paused = True                         # the clock never moves
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.press("q")
    assert session.now == 0.0
    lines = session.summary_lines()
    text = "\n".join(lines)
    assert "--until 0.0" not in text
    assert f"Recording: {record}" in text
    assert "Nothing to replay: the session stopped before its clock moved." in text
    for words in _commands(lines):
        assert main(words[1:]) == 0, words


@pytest.mark.asyncio
async def test_quit_a_moment_later_still_prints_commands_that_run(compiled, tmp_path, capsys):
    record = tmp_path / "later.json"
    session = WalkSession(compiled, record=record, spec_path=str(SPEC))
    session.paused = True
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.press("w")                    # 30 simulated seconds
        await pilot.press("q")
    lines = session.summary_lines()
    commands = _commands(lines)
    assert [words[:2] for words in commands] == [["opspec", "walkthrough"], ["opspec", "run"]]
    run = commands[1]
    assert run[run.index("--until") + 1] == "30.0"
    assert main(run[1:]) == 0


def test_the_summary_so_far_at_0_s_does_not_say_the_session_stopped(compiled, tmp_path):
    session = WalkSession(compiled, record=tmp_path / "so far.json", spec_path=str(SPEC))
    lines = session.summary_lines(final=False)       # s, before the clock moved
    session.close()
    assert lines[-1] == "Nothing to replay yet: the clock has not moved."
    assert not _commands(lines)
