"""A walkthrough with a bound device that the person quits (`q`) traces what the device had
not finished, as one ``device.pending`` event in the recording's trace, as `opspec run` does:
the trace is where nothing lost is checked (an ALARM ON sent and never answered may have
rung). Before, the app closed the session, and its trace, when the person pressed `q`, and
`opspec walkthrough` took the devices' report only afterwards: tracing it into the closed
trace file ended the command with an internal error (exit 70, "I/O operation on closed
file") instead of the summary, and the trace never held it.

The terminal's app is the real one, driven by Textual's Pilot from the command: the person
waits for the 08:00 alarm, whose ALARM ON goes to a board that never answers, and quits."""

from __future__ import annotations

import asyncio
import sys
from pathlib import Path
from typing import Any

import pytest

import opspec.tui.app
from walkthrough_inputs import ROOT, SPEC
from opspec.cli import main
from opspec.engine.trace_sinks import read_trace

SILENT = "emulator://medication_dispenser?fault=silent"


class _Terminal:
    """A stream that says it is a terminal (the walkthrough refuses to start otherwise)."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def isatty(self) -> bool:
        return True

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


class _QuitWhileTheDeviceWorks(opspec.tui.app.WalkthroughApp):
    """The walkthrough's app as the command runs it; its ``run`` is a person who skips to
    the alarm and presses q while the board has not answered its command."""

    def run(self, *_args: Any, **_kw: Any) -> None:
        asyncio.run(self._person())

    async def _person(self) -> None:
        session = self.session
        async with self.run_test(size=(100, 30)) as pilot:
            await pilot.press("u")                       # skip until something needs me
            for _ in range(200):
                if session.device_work:
                    break
                await pilot.pause(0.02)
            assert session.device_work, "the alarm's command never went out"
            await pilot.press("q")


def test_quitting_traces_the_devices_unfinished_work(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
        tmp_path: Path) -> None:
    monkeypatch.setattr(opspec.tui.app, "WalkthroughApp", _QuitWhileTheDeviceWorks)
    record = tmp_path / "walk.json"
    with monkeypatch.context() as terminal:         # (capture sets its streams per test)
        terminal.setattr(sys, "stdin", _Terminal(sys.stdin))
        terminal.setattr(sys, "stdout", _Terminal(sys.stdout))
        status = main(["walkthrough", str(SPEC), "--bind", f"alarm={SILENT}",
                       "--devices", str(ROOT / "devices"), "--record", str(record),
                       "--speed", "10000", "--sound", "off"])
    printed = capsys.readouterr()
    out = printed.out
    assert status == 0, printed.err
    # the summary says it (when the session was quit: not "at the end" of its run)
    assert "unfinished when the session was quit: alarm: sound_alarm (instance" in out
    events = list(read_trace(record.with_suffix(".trace.jsonl")))
    pending = [e for e in events if e.kind == "device.pending"]
    assert len(pending) == 1, [e.kind for e in events[-5:]]
    assert pending[0].data["device"] and pending[0].data["pending"][0]["command"] == "ALARM ON"
    # the session quit early still says where it ended (a replay stops there), and the run
    # ends there, before the device's report as in opspec run's trace
    assert [e.kind for e in events[-3:]] == ["walkthrough.quit", "run.ended", "device.pending"]
