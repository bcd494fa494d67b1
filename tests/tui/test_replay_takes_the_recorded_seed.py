"""`opspec walkthrough SPEC --replay REC` runs the recorded session's seed, which the trace
beside the recording keeps in its header (``"seed"``): the device's draws of another seed are
another session, which the recorded actions do not fit. Before, a replay without `--seed` ran
seed 0 whatever the session's, silently: a session of the vacuum cleaner (its world draws the
range sensor's noise from the seed) recorded with seed 7 replayed to other numbers.

`--seed` given says which seed runs; when it is not the recorded one the command says so.
A recording without its trace (an old one, or any script) replays with seed 0, as before."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any, ClassVar

import pytest

import opspec.tui.app
from walkthrough_inputs import ROOT
from opspec.cli import main
from opspec.engine.compiled import compile_package
from opspec.tui.replay import recorded_seed
from opspec.tui.session import WalkSession
from opspec.xpdl.open_spec import open_spec

VACUUM = ROOT / "specs" / "vacuum_cleaner.xpdl"
SEED = 7


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

    seen: ClassVar[list[tuple[WalkSession, list[str]]]] = []

    def __init__(self, session: WalkSession, notes: Any = (), **_kw: Any) -> None:
        self.session = session
        _WatchTheReplay.seen.append((session, list(notes)))

    def run(self) -> None:
        for _ in range(10_000):
            if self.session.ended:
                return
            self.session.run_to(self.session.horizon)
        raise AssertionError("the replay never ended")


@pytest.fixture
def replay(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]):
    """Run ``opspec walkthrough VACUUM --replay ARGS`` on a terminal, the app watching: the
    replay's session, the notes the app was given, and what the command printed."""
    monkeypatch.setattr(opspec.tui.app, "WalkthroughApp", _WatchTheReplay)

    def walk(*args: str) -> tuple[WalkSession, list[str], str, str]:
        _WatchTheReplay.seen.clear()
        capsys.readouterr()
        with monkeypatch.context() as terminal:     # (capture sets its streams per test)
            terminal.setattr(sys, "stdin", _Terminal(sys.stdin))
            terminal.setattr(sys, "stdout", _Terminal(sys.stdout))
            assert main(["walkthrough", str(VACUUM), "--replay", *args, "--sound", "off"]) == 0
        ((session, notes),) = _WatchTheReplay.seen
        printed = capsys.readouterr()
        return session, notes, printed.out, printed.err

    return walk


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    """Five minutes of the vacuum cleaner watched with seed 7: the recording and the spec's
    metrics the session ended with."""
    record = tmp_path_factory.mktemp("walk") / "vacuum.json"
    session = WalkSession(compile_package(open_spec(VACUUM)), seed=SEED, until=300.0,
                          record=record, spec_path=str(VACUUM))
    while not session.ended:
        session.run_to(session.horizon)
    session.close()
    return record, _metric_lines(session.summary_lines())


def _metric_lines(lines: list[str]) -> list[str]:
    names = ("cells_covered", "collisions", "manoeuvres", "dockings")
    return [line for line in lines if line.split()[:1] and line.split()[0] in names]


def test_a_replay_runs_the_seed_the_session_was_recorded_with(recorded, replay) -> None:
    record, shown = recorded
    assert recorded_seed(record) == SEED
    session, notes, out, err = replay(str(record))
    assert session.seed == SEED
    assert _metric_lines(out.splitlines()) == shown        # the numbers of the session
    assert "seed" not in err and not any("seed" in note for note in notes)
    # --seed the same as the recording's: nothing to say
    session, notes, _out, err = replay(str(record), "--seed", str(SEED))
    assert session.seed == SEED and "seed" not in err


def test_another_seed_given_runs_and_says_it_is_not_the_recorded_one(recorded,
                                                                      replay) -> None:
    record, shown = recorded
    session, notes, out, err = replay(str(record), "--seed", "0")
    assert session.seed == 0
    said = ("--seed 0 is used, not the recorded session's seed 7: the device's draws are not "
            "those the recording was made with (leave out --seed to replay the session as it "
            "was)")
    assert f"opspec walkthrough: {said}" in err
    assert said in notes                                    # and on the screen
    assert _metric_lines(out.splitlines()) != shown         # why it matters


def test_a_recording_without_its_trace_replays_with_seed_0_as_before(recorded, replay,
                                                                     tmp_path) -> None:
    record, _shown = recorded
    old = tmp_path / "old.json"
    old.write_bytes(record.read_bytes())                    # no trace beside it
    assert recorded_seed(old) is None
    session, _notes, _out, err = replay(str(old), "--until", "60")
    assert session.seed == 0 and "seed" not in err
