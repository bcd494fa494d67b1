"""A SIGINT from outside the terminal (``kill -INT``, a supervisor stopping the session) ends
the walkthrough as ``q`` does, and the command exits with status 130, as docs/walkthrough.md
says.

In a real terminal it exited with status 0: asyncio's runner took the signal and cancelled
the app's task, so the session ended as if it had run to its end (a bound device's work
"unfinished at the end", not "when interrupted")."""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path
from typing import Any

import pytest

import opspec.tui.app
from opspec.cli import main
from opspec.tui.app import WalkthroughApp
from opspec.tui.session import WalkSession

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"


@pytest.mark.asyncio
async def test_sigint_from_outside_quits_the_app_as_interrupted(compiled, tmp_path):
    record = tmp_path / "walk.json"
    session = WalkSession(compiled, record=record)
    app = WalkthroughApp(session)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.press("space")
        os.kill(os.getpid(), signal.SIGINT)
        await pilot.pause(0.2)
        assert app.interrupted
    assert app.return_value == str(record)            # quit as q does: the recording kept
    # once the app is gone, a SIGINT is Python's KeyboardInterrupt again
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


class _Terminal:
    """A stream that says it is a terminal (the walkthrough refuses to start otherwise)."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def isatty(self) -> bool:
        return True

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


class _InterruptedApp:
    """Stands in for the app in a terminal: a SIGINT came while it ran; it quit."""

    def __init__(self, session: Any, **_kw: Any) -> None:
        self.session = session
        self.interrupted = False

    def run(self) -> None:
        self.interrupted = True


def test_the_command_exits_130_when_the_app_was_interrupted(monkeypatch, capsys):
    monkeypatch.setattr(opspec.tui.app, "WalkthroughApp", _InterruptedApp)
    monkeypatch.setattr(sys, "stdin", _Terminal(sys.stdin))
    monkeypatch.setattr(sys, "stdout", _Terminal(sys.stdout))
    assert main(["walkthrough", str(SPEC), "--no-record", "--sound", "off"]) == 130
    assert "The spec's metrics" in capsys.readouterr().out
