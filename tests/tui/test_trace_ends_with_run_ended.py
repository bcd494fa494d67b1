"""A walkthrough's trace ends as `opspec run`'s does: with ``run.ended`` (``open``,
``deadlocks``), however the session ended — at the end of its run, or quit before it by `q`,
by the app's Ctrl+C, or by an interrupt from outside (status 130). A session quit early says
so first (``walkthrough.quit``), and a bound device's unfinished work (``device.pending``)
comes after ``run.ended``, as in `opspec run`'s trace.

Before, no walkthrough trace had ``run.ended``: readers that take the run's end from it
(:func:`opspec.properties.evaluator.trace_end`) took the last event's time instead (at
d1 22:10 for a run that ended at d2 00:00), so what was pending at the end was judged too
early; and a quit session's device report came before its quit."""

from __future__ import annotations

import asyncio
import os
import signal
import sys
from pathlib import Path
from typing import Any, ClassVar

import pytest

import opspec.tui.app
from walkthrough_inputs import ROOT, SPEC
from opspec.cli import main
from opspec.engine.trace_sinks import read_trace
from opspec.properties.evaluator import trace_end
from opspec.tui.session import WalkSession
from opspec.usermodels.fitting import collect

UNTIL = 9 * 3600.0                 # past the 08:00 dose
SILENT = "emulator://medication_dispenser?fault=silent"


def _events(record: Path) -> list[Any]:
    return list(read_trace(record.with_suffix(".trace.jsonl")))


def _run_ended_of_opspec_run(tmp_path: Path, record: Path, until: float) -> Any:
    """The ``run.ended`` of `opspec run SPEC --until T --script REC --trace FILE`."""
    trace = tmp_path / "run.trace.jsonl"
    assert main(["run", str(SPEC), "--until", repr(until), "--script", str(record),
                 "--trace", str(trace)]) == 0
    (ended,) = [e for e in read_trace(trace) if e.kind == "run.ended"]
    return ended


def test_a_whole_sessions_trace_ends_with_the_run_ended_of_opspec_run(
        compiled, tmp_path, model_factory, capsys):
    record = tmp_path / "whole.json"
    session = WalkSession(compiled, until=UNTIL, record=record, spec_path=str(SPEC),
                          model_factory=model_factory)
    session.hand_over()
    while not session.ended:
        session.run_to(UNTIL)
    session.close()
    events = _events(record)
    last = events[-1]
    assert last.kind == "run.ended" and last.time == UNTIL
    assert [e.kind for e in events].count("run.ended") == 1
    assert trace_end(events) == UNTIL            # not the last event's time before it
    same = _run_ended_of_opspec_run(tmp_path, record, UNTIL)
    assert (last.time, last.data) == (same.time, same.data)
    capsys.readouterr()


def test_a_quit_sessions_trace_ends_with_its_quit_then_run_ended(compiled, tmp_path, capsys):
    record = tmp_path / "quit.json"
    session = WalkSession(compiled, record=record, spec_path=str(SPEC))
    session.skip_until_user()                     # 08:00: the alarm
    session.act(next(o for o in session.offers if o.item.activity == "hear_alarm"))
    session.run_to(session.now + 60.0)
    quit_at = session.now
    session.close()                               # q
    session.close()                               # (the command closes it again)
    events = _events(record)
    assert [(e.kind, e.time) for e in events[-2:]] == [("walkthrough.quit", quit_at),
                                                       ("run.ended", quit_at)]
    assert [e.kind for e in events].count("run.ended") == 1
    same = _run_ended_of_opspec_run(tmp_path, record, quit_at)
    assert events[-1].data == same.data
    # opspec fit reads it: the answer is there
    obs = collect([record.with_suffix(".trace.jsonl")])
    assert obs.durations.get("hear_alarm") or obs.unusable.get("hear_alarm")
    capsys.readouterr()


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
    the alarm and quits (``how``) while the board has not answered."""

    how: ClassVar[str] = "q"

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
            if self.how == "sigint":                     # kill -INT from outside
                os.kill(os.getpid(), signal.SIGINT)
                for _ in range(100):
                    if self.interrupted:
                        break
                    await pilot.pause(0.02)
            else:
                await pilot.press(self.how)


@pytest.mark.parametrize(("how", "status", "when"), [
    ("q", 0, "when the session was quit"),
    ("ctrl+c", 0, "when the session was quit"),
    ("sigint", 130, "when interrupted")])
def test_a_session_quit_with_a_bound_device_ends_its_trace_whole(
        how, status, when, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    monkeypatch.setattr(opspec.tui.app, "WalkthroughApp", _QuitWhileTheDeviceWorks)
    monkeypatch.setattr(_QuitWhileTheDeviceWorks, "how", how)
    record = tmp_path / "walk.json"
    with monkeypatch.context() as terminal:         # (capture sets its streams per test)
        terminal.setattr(sys, "stdin", _Terminal(sys.stdin))
        terminal.setattr(sys, "stdout", _Terminal(sys.stdout))
        got = main(["walkthrough", str(SPEC), "--bind", f"alarm={SILENT}",
                    "--devices", str(ROOT / "devices"), "--record", str(record),
                    "--speed", "10000", "--sound", "off"])
    printed = capsys.readouterr()
    assert got == status, printed.err
    events = _events(record)
    kinds = [e.kind for e in events]
    # the person quit, the run ended there, and then what the device left unfinished
    assert kinds[-3:] == ["walkthrough.quit", "run.ended", "device.pending"], kinds[-5:]
    assert kinds.count("run.ended") == 1
    quit_at = events[-3].data["until"]
    assert events[-2].time == quit_at == trace_end(events)
    assert set(events[-2].data) == {"open", "deadlocks"}
    assert events[-1].data["pending"][0]["command"] == "ALARM ON"
    # the words after the app say when the device's work was found unfinished: not "at the
    # end" (of the run, d2 00:00) for a session left at 08:00
    assert f"unfinished {when}: alarm: sound_alarm (instance" in printed.out
    assert "unfinished at the end" not in printed.out
    # and that the printed replays simulate the device instead
    assert ("Both replays simulate alarm, performed here by a bound device: their numbers "
            "may differ from this session's.") in printed.out
