"""A walkthrough recorded under any name replays with exactly the command the walkthrough
prints, through `opspec run --script`, to the same trace and the same metrics.

The recording is made by pressing keys in the app (Textual's Pilot), the command is taken
from the summary the session prints on quit, split as a shell would split it, and run
through the CLI's entry point."""

from __future__ import annotations

import json
import shlex

import pytest
from walkthrough_inputs import SPEC

from opspec.cli import main
from opspec.run_rules import parse_until
from opspec.testing.script import load_script, script_format
from opspec.tui.app import SummaryScreen, WalkthroughApp
from opspec.tui.session import WalkSession

KINDS = ("activity.", "process.", "trigger.", "deadline.", "data.")


def events(lines: list[str], before: float) -> list[tuple]:
    """The engine's events of a JSON Lines trace (not the walkthrough's own), before
    ``before`` (what the walkthrough had run when it was quit)."""
    out = []
    for line in lines[1:]:
        event = json.loads(line)
        if event["kind"].startswith(KINDS) and event["time"] < before:
            out.append((event["time"], event["kind"], event.get("process"),
                        event.get("instance"), event.get("activity"), event.get("data")))
    return out


def printed_run_command(session: WalkSession) -> list[str]:
    line = next(x for x in session.summary_lines() if x.strip().startswith("or: opspec run"))
    return shlex.split(line.split(":", 1)[1])


@pytest.mark.asyncio
async def test_a_recording_named_anything_replays_with_the_printed_command(compiled, tmp_path,
                                                                         capsys):
    record = tmp_path / "lab 3" / "participant 7.rec"      # spaces, no .json
    session = WalkSession(compiled, record=record, spec_path=str(SPEC))
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.press("space")                          # time moves by keys only
        await pilot.press("u", "a", "w", "a", "b")          # the wrong button first
        await pilot.press("a", "w", "a")                    # then "report", take the pill
        await pilot.press("u", "w", "w", "x")               # the noon alarm: not now
        await pilot.press("q")
    stopped = session.now
    assert stopped > 12 * 3600
    command = printed_run_command(session)
    assert command[:2] == ["opspec", "run"] and command[-2:] == ["--script", str(record)]
    # stopped before the end of the day: the run stops there too, so that its numbers are
    # those the summary showed, not those of a day that goes on without the person
    assert parse_until(command[command.index("--until") + 1]) == stopped   # exactly
    assert script_format(record.read_bytes(), str(record)) == "JSON"
    shown = [line for line in session.summary_lines() if line.startswith("  ") and (
        "doses" in line or "alarms" in line or "latency" in line)]
    assert any(line.split() == ["doses_missed", "0"] for line in shown)

    run_trace = tmp_path / "run.jsonl"
    capsys.readouterr()
    assert main([*command[1:], "--trace", str(run_trace), "--timeline", "none"]) == 0
    printed = capsys.readouterr().out.splitlines()
    for line in shown:                                      # word for word
        assert line in printed
    walked = record.with_suffix(".trace.jsonl").read_text(encoding="utf-8").splitlines()
    ran = run_trace.read_text(encoding="utf-8").splitlines()
    mine = events(walked, stopped)
    assert len(mine) > 100 and mine == events(ran, stopped)


@pytest.mark.asyncio
async def test_the_summary_at_the_end_has_the_numbers_opspec_run_prints(compiled, tmp_path,
                                                                       capsys):
    record = tmp_path / "whole day.rec"
    session = WalkSession(compiled, record=record, spec_path=str(SPEC))
    app = WalkthroughApp(session)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.press("space", "u", "a", "w", "a", "a", "w", "a")   # the 08:00 dose
        for _ in range(40):                                  # let the others go by
            if session.ended:
                break
            await pilot.press("u")
            while session.skipping:
                await pilot.pause(0.05)
        await pilot.pause(0.2)
        assert session.ended
        assert isinstance(app.screen, SummaryScreen)         # it opened by itself
        shown = str(app.screen.query_one("#summary-text").render())
        await pilot.press("q")
    assert "The run ended at d2 00:00:00." in shown and "Recording:" in shown
    mine = [line for line in session.summary_lines() if line.startswith("  ") and (
        "doses" in line or "alarms" in line or "latency" in line or "rate" in line)]
    assert any(line.split() == ["doses_taken", "1"] for line in mine)
    assert any(line.split() == ["doses_missed", "3"] for line in mine)

    capsys.readouterr()
    assert main([*printed_run_command(session)[1:], "--timeline", "none"]) == 0
    printed = capsys.readouterr().out.splitlines()
    for line in mine:                                        # word for word
        assert line in printed


def test_the_script_format_is_told_from_the_content(tmp_path):
    steps = '{"otherwise": "wait", "steps": [["at 28830.0", "complete hear_alarm"]]}'
    for name in ("rec.json", "rec.rec", "rec.toml", "rec"):
        path = tmp_path / name
        path.write_text("\ufeff  \n" + steps, encoding="utf-8")      # a BOM, blank lines
        assert [s.target for s in load_script(path).steps] == ["hear_alarm"], name
    toml = tmp_path / "script.rec"
    toml.write_text('otherwise = "wait"\nsteps = [["at 28830.0", "hear_alarm"]]\n',
                    encoding="utf-8")
    assert load_script(toml).otherwise == "wait"
