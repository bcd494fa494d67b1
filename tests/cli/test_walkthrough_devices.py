"""`opspec walkthrough --bind`: when the session ends (or Ctrl+C stops it), the words after
the app say how the bound devices did, as `opspec run` does: round trips, faults and the work
left unfinished. Before, a walkthrough with hardware ended with the metrics only."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

import opspec.tui.app
from opspec.cli import main

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"
SILENT = "emulator://medication_dispenser?fault=silent"


class _Terminal:
    """A stream that says it is a terminal (the walkthrough refuses to start otherwise)."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def isatty(self) -> bool:
        return True

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def _app_that(action: str) -> type:
    class App:
        """Stands in for the Textual app: runs the session to the first alarm, then ends
        (``quit``) or is interrupted (``ctrl-c``)."""

        def __init__(self, session: Any, **_kw: Any) -> None:
            self.session = session

        def run(self) -> None:
            self.session.sim.run(until=28800.01)
            if action == "ctrl-c":
                raise KeyboardInterrupt

    return App


@pytest.mark.parametrize(("action", "when", "status"), [("quit", "when the session was quit", 0),
                                                        ("ctrl-c", "when interrupted", 130)])
def test_the_walkthrough_ends_saying_how_the_devices_did(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
        action: str, when: str, status: int) -> None:
    monkeypatch.setattr(opspec.tui.app, "WalkthroughApp", _app_that(action))
    monkeypatch.setattr(sys, "stdin", _Terminal(sys.stdin))
    monkeypatch.setattr(sys, "stdout", _Terminal(sys.stdout))
    assert main(["walkthrough", str(SPEC), "--no-record", "--sound", "off",
                 "--speed", "1000000", "--bind", f"alarm={SILENT}"]) == status
    out = capsys.readouterr().out
    assert (f"device alarm (medication_dispenser on {SILENT}): alarm device; "
            "no commands answered; 0 fault(s)") in out
    assert (f"unfinished {when}: alarm: sound_alarm (instance 2) sent 'ALARM ON', "
            "no reply yet (attempt 1)") in out
