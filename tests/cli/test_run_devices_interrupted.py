"""Ctrl+C during a run with a bound device: the run says what the device had not finished
(a command sent and never answered may have done its work, a dose dropped) and traces it, as
a run that ends does, instead of only ``interrupted``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from opspec.bindings.exchanges import Exchanges
from opspec.cli import main
from opspec.engine.trace_sinks import read_trace

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"
SILENT = "emulator://medication_dispenser?fault=silent"


@pytest.fixture
def ctrl_c_after_the_first_command(monkeypatch: pytest.MonkeyPatch) -> None:
    """Ctrl+C arrives the moment the first command is on the line."""
    send = Exchanges._send

    def send_then_interrupt(self: Any, job: Any) -> None:
        send(self, job)
        raise KeyboardInterrupt

    monkeypatch.setattr(Exchanges, "_send", send_then_interrupt)


@pytest.mark.usefixtures("ctrl_c_after_the_first_command")
def test_ctrl_c_says_and_traces_the_command_left_without_a_reply(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    trace = tmp_path / "run.jsonl"
    status = main(["run", str(SPEC), "--until", "36000", "--speed", "1000000",
                   "--bind", f"alarm={SILENT}", "--bind", f"dispenser={SILENT}",
                   "--trace", str(trace)])
    assert status == 130
    err = capsys.readouterr().err
    assert ("unfinished when interrupted: alarm: sound_alarm (instance 2) sent 'ALARM ON', "
            "no reply yet (attempt 1)") in err
    assert err.index("unfinished when interrupted") < err.index("opspec run: interrupted")
    last = list(read_trace(trace))[-1]
    assert last.kind == "device.pending"
    assert last.data["pending"][0]["state"] == "sent"


def test_a_run_that_ends_still_says_at_the_end(capsys: pytest.CaptureFixture[str]) -> None:
    status = main(["run", str(SPEC), "--until", "28800.01", "--speed", "1000000",
                   "--bind", f"alarm={SILENT}", "--bind", f"dispenser={SILENT}"])
    assert status == 0
    out = capsys.readouterr().out
    assert "unfinished at the end: alarm: sound_alarm (instance 2) sent 'ALARM ON'" in out
