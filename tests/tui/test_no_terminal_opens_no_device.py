"""A walkthrough refused for having no terminal opens no device first: opening a serial port
may reset the board behind it (an Arduino restarts when its port opens), for a run that was
never going to start. The spec's own errors still come first."""

from __future__ import annotations

import io
import sys
from typing import Any

import pytest

import opspec.bindings.attach
from walkthrough_inputs import SPEC
from opspec.cli import main

BIND = "alarm=emulator://medication_dispenser"


class _NoTerminal(io.StringIO):
    def isatty(self) -> bool:
        return False


def test_no_device_is_opened_for_a_run_refused_for_no_terminal(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
        tmp_path: Any) -> None:
    opened: list[Any] = []
    attach = opspec.bindings.attach.attach_devices

    def attach_devices(*args: Any, **kwargs: Any) -> Any:
        opened.append(args)
        return attach(*args, **kwargs)

    monkeypatch.setattr(opspec.bindings.attach, "attach_devices", attach_devices)
    monkeypatch.setattr(sys, "stdin", _NoTerminal())
    monkeypatch.chdir(tmp_path)
    assert main(["walkthrough", str(SPEC), "--bind", BIND]) == 2
    err = capsys.readouterr().err
    assert err.startswith("opspec walkthrough: the walkthrough needs a terminal"), err
    assert opened == []
    assert not (tmp_path / "walkthroughs").exists()          # nothing recorded, as before


def test_a_port_that_cannot_open_is_not_tried_without_a_terminal(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(sys, "stdin", _NoTerminal())
    assert main(["walkthrough", str(SPEC), "--no-record",
                 "--bind", "alarm=/dev/opspec-no-such-port"]) == 2
    err = capsys.readouterr().err
    assert "needs a terminal" in err and "no-such-port" not in err
