"""``opspec run SPEC --script REC`` of a walkthrough recording ran, without a word, the whole
day and seed 0, where ``opspec walkthrough --replay REC`` of the same file ended where the
session did and ran its seed: two numbers for one recording. The script cannot carry the
end or the seed (its trace does), so the run keeps its own, and says what differs and how
to replay the session."""

from __future__ import annotations

from walkthrough_inputs import SPEC
from opspec.cli import main
from opspec.tui.session import WalkSession


def recording(compiled, tmp_path, *, seed: int = 0, until: float | None = 9 * 3600.0,
              days: float | None = None):
    record = tmp_path / "rec.json"
    session = WalkSession(compiled, record=record, spec_path=str(SPEC), seed=seed, days=days)
    target = session.horizon if until is None else until
    while session.now < target and not session.ended:     # (it stops where the device calls)
        session.run_to(target)
    session.close()
    return record


def notes(capsys) -> list[str]:
    return [line for line in capsys.readouterr().err.splitlines()
            if line.startswith("opspec run: note: ")]


def test_a_session_quit_early_with_another_seed_is_said(compiled, tmp_path, capsys):
    record = recording(compiled, tmp_path, seed=7)
    capsys.readouterr()
    assert main(["run", str(SPEC), "--script", str(record), "--timeline", "none"]) == 0
    end = (f"opspec run: note: {record} records a walkthrough that ended at d1 09:00:00: "
           "this run goes on to d2 00:00:00 without the person (--until 9h ends where the "
           "session did)")
    seed = (f"opspec run: note: {record} records a walkthrough run with seed 7, this run "
            "has seed 0 (--seed 7 replays the session's device draws)")
    assert notes(capsys) == [end, seed]
    # the commands the summary prints say nothing more
    assert main(["run", str(SPEC), "--seed", "7", "--until", "9h", "--script", str(record),
                 "--timeline", "none"]) == 0
    assert notes(capsys) == []


def test_a_session_that_ran_to_its_end_is_replayed_without_a_note(compiled, tmp_path, capsys):
    record = recording(compiled, tmp_path, until=None, days=0.25)
    capsys.readouterr()
    assert main(["run", str(SPEC), "--days", "0.25", "--script", str(record),
                 "--timeline", "none"]) == 0
    assert notes(capsys) == []
    assert main(["run", str(SPEC), "--script", str(record), "--timeline", "none"]) == 0
    end = (f"opspec run: note: {record} records a walkthrough that ended at d1 06:00:00: "
           "this run goes on to d2 00:00:00 without the person (--until 6h ends where the "
           "session did)")
    assert notes(capsys) == [end]


def test_any_other_script_gets_no_note(tmp_path, capsys):
    script = tmp_path / "plain.json"
    script.write_text('{"otherwise": "wait", "steps": []}', encoding="utf-8")
    assert main(["run", str(SPEC), "--script", str(script), "--timeline", "none"]) == 0
    assert notes(capsys) == []
