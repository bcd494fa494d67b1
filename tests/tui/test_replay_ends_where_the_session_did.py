"""`opspec walkthrough SPEC --replay REC` of a session the person quit early ends where the
session ended, as `opspec run SPEC --until T --script REC` (the command the summary prints)
does: a replay reproduces the session, not the rest of the day without the person.

The recording's script has no place for the end (a script file holds ``steps`` and
``otherwise``), so the trace beside the recording keeps it: the run's end in its header
(``until``), and a ``walkthrough.quit`` event where the person quit; recordings made before
that replay to the run's end as they did.
``--until`` (or ``--days``) on the command line says where a replay ends instead.
Before, every replay ran on to the end of the day: every later dose missed.
"""

from __future__ import annotations

import json
import shlex
import sys
from pathlib import Path
from typing import Any, ClassVar

import pytest

import opspec.tui.app
from walkthrough_inputs import SPEC
from opspec.cli import main
from opspec.tui.replay import recorded_end
from opspec.tui.session import WalkSession
from opspec.tui.summary import replay_commands

DOSE_TAKEN = 8 * 3600 + 600          # the 08:00 dose answered, then the person quit


class _Terminal:
    """A stream that says it is a terminal (the walkthrough refuses to start otherwise)."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def isatty(self) -> bool:
        return True

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


class _WatchTheReplay:
    """Stands in for the Textual app: lets the replay run until it ends by itself."""

    sessions: ClassVar[list[WalkSession]] = []

    def __init__(self, session: WalkSession, **_kw: Any) -> None:
        self.session = session
        _WatchTheReplay.sessions.append(session)

    def run(self) -> None:
        for _ in range(10_000):
            if self.session.ended:
                return
            self.session.run_to(self.session.horizon)
        raise AssertionError("the replay never ended")


def _quit_after_the_first_dose(compiled, record: Path) -> WalkSession:
    session = WalkSession(compiled, record=record, spec_path=str(SPEC))
    session.skip_until_user()                                   # 08:00: the alarm
    for activity in ("hear_alarm", "walk_to_dispenser", "choose_button", "take_pill"):
        while not any(o.item.activity == activity for o in session.offers):
            session.skip_to_next_event()
        offer = next(o for o in session.offers if o.item.activity == activity)
        session.act(offer if activity != "choose_button" else next(
            o for o in session.offers if o.choice == "press_report"))
    session.run_to(DOSE_TAKEN)
    session.close()                                             # q
    assert not session.ended
    return session


def _metric_lines(lines: list[str]) -> list[str]:
    return [line for line in lines if line.startswith("  ") and (
        "doses" in line or "alarms" in line or "latency" in line)]


@pytest.fixture
def replay(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]):
    """Run ``opspec walkthrough ARGS`` (on a terminal, the app watching): the replay's
    session and what the command printed."""
    monkeypatch.setattr(opspec.tui.app, "WalkthroughApp", _WatchTheReplay)

    def walk(*args: str) -> tuple[WalkSession, str]:
        _WatchTheReplay.sessions.clear()
        capsys.readouterr()
        with monkeypatch.context() as terminal:     # (capture sets its streams per test)
            terminal.setattr(sys, "stdin", _Terminal(sys.stdin))
            terminal.setattr(sys, "stdout", _Terminal(sys.stdout))
            assert main(["walkthrough", *args, "--sound", "off"]) == 0
        (session,) = _WatchTheReplay.sessions
        return session, capsys.readouterr().out

    return walk


def test_the_replay_of_a_session_quit_early_ends_where_it_was_quit(compiled, tmp_path,
                                                                  replay):
    record = tmp_path / "P07.json"
    walked = _quit_after_the_first_dose(compiled, record)
    quitted, ended = map(json.loads, record.with_suffix(".trace.jsonl").read_text(
        encoding="utf-8").splitlines()[-2:])
    assert quitted["kind"] == "walkthrough.quit" and quitted["data"] == {"until": walked.now}
    assert ended["kind"] == "run.ended" and ended["time"] == walked.now   # the run ends there
    assert recorded_end(record) == walked.now                   # exactly
    shown = _metric_lines(walked.summary_lines())
    assert any(line.split() == ["doses_missed", "0"] for line in shown)

    session, out = replay(str(SPEC), "--replay", str(record))
    assert session.replaying and session.now == walked.now
    assert "The run ended at d1 08:10:00." in out
    assert _metric_lines(out.splitlines()) == shown             # the numbers of the session

    # the replay command the session printed says so too (robust when the trace is gone)
    walk = next(line for line in walked.summary_lines() if line.startswith("Replay it with:"))
    command = shlex.split(walk.split(":", 1)[1])
    assert command[command.index("--until") + 1] == "8h10m"
    session, _out = replay(*command[2:])
    assert session.now == walked.now


def test_a_recording_without_its_end_replays_the_whole_run_as_before(compiled, tmp_path,
                                                                     replay):
    record = tmp_path / "old.json"
    _quit_after_the_first_dose(compiled, record)
    trace = record.with_suffix(".trace.jsonl")
    # a recording made before sessions wrote their end: the same trace without it
    header, *events = trace.read_text(encoding="utf-8").splitlines(keepends=True)
    old = json.loads(header)
    del old["until"]
    trace.write_text(json.dumps(old) + "\n" + "".join(
        line for line in events if "walkthrough.quit" not in line), encoding="utf-8")
    assert recorded_end(record) is None
    session, out = replay(str(SPEC), "--replay", str(record))
    assert session.now == 86_400.0 and "The run ended at d2 00:00:00." in out
    trace.unlink()                                              # or no trace at all
    assert recorded_end(record) is None
    assert replay(str(SPEC), "--replay", str(record))[0].now == 86_400.0


def test_until_or_days_on_the_command_line_say_where_the_replay_ends(compiled, tmp_path,
                                                                    replay):
    record = tmp_path / "r.json"
    _quit_after_the_first_dose(compiled, record)
    assert replay(str(SPEC), "--replay", str(record), "--until", "9h")[0].now == 9 * 3600.0
    assert replay(str(SPEC), "--replay", str(record), "--days", "0.5")[0].now == 43_200.0


def test_until_and_days_together_are_a_usage_error(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["walkthrough", str(SPEC), "--days", "1", "--until", "9h"])
    assert stop.value.code == 2
    assert "not allowed with argument" in capsys.readouterr().err


def test_a_session_that_ran_to_its_end_records_its_end(compiled, tmp_path):
    record = tmp_path / "whole.json"
    session = WalkSession(compiled, record=record, days=0.5, spec_path=str(SPEC))
    session.hand_over()
    while not session.ended:
        session.run_to(session.horizon)
    session.close()
    header, *events = (json.loads(line) for line in
                       record.with_suffix(".trace.jsonl").read_text(encoding="utf-8")
                       .splitlines())
    assert header["until"] == 43_200.0
    assert not any(event["kind"] == "walkthrough.quit" for event in events)
    assert recorded_end(record) == 43_200.0
    # its own end, not the spec's day: both printed replays stop there
    walk, run = (line.split(":", 1)[1] for line in session.summary_lines()
                 if line.strip().startswith(("Replay it with:", "or:")))
    assert "--until 12h" in walk and "--until 12h" in run


def test_the_printed_replays_run_the_session_s_seed():
    walk, run = replay_commands("pill.xpdl", "r.json", seed=7)
    assert shlex.split(walk)[3:] == ["--replay", "r.json", "--seed", "7"]
    assert shlex.split(run)[3:] == ["--seed", "7", "--script", "r.json"]
    assert "--seed" not in "".join(replay_commands("pill.xpdl", "r.json"))    # 0: as before


def test_a_session_quit_before_its_clock_moved_has_nothing_to_replay(compiled, tmp_path,
                                                                     replay, capsys):
    """Its replay ran the whole day without the person (every dose missed): not the session,
    which ran nothing. It is refused, saying why; ``--until`` still replays to then."""
    record = tmp_path / "at once.json"
    WalkSession(compiled, record=record, spec_path=str(SPEC)).close()     # q at 0 s
    assert recorded_end(record) == 0.0
    capsys.readouterr()
    assert main(["walkthrough", str(SPEC), "--replay", str(record), "--sound", "off"]) == 2
    err = capsys.readouterr().err
    assert "the session was quit before its clock moved: there is nothing to replay" in err
    assert replay(str(SPEC), "--replay", str(record), "--until", "9h")[0].now == 9 * 3600.0
