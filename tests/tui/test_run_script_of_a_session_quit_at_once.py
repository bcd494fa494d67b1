"""``opspec run SPEC --script REC`` of a walkthrough quit before its clock moved ran the whole
day without the person (four doses due, every one missed) and exit 0, where the session's
summary said "Nothing to replay" and ``opspec walkthrough --replay`` refused it. It is refused
in the same words; ``--until`` or ``--days`` still run to then without the person, and a
recording of a session that ran runs as before."""

from __future__ import annotations

from walkthrough_inputs import SPEC
from opspec.cli import main
from opspec.tui.session import WalkSession

REFUSED = "the session was quit before its clock moved: there is nothing to replay"


def test_run_script_refuses_a_session_quit_at_once(compiled, tmp_path, capsys):
    record = tmp_path / "at once.json"
    WalkSession(compiled, record=record, spec_path=str(SPEC)).close()     # q at 0 s
    capsys.readouterr()
    assert main(["run", str(SPEC), "--script", str(record)]) == 2
    captured = capsys.readouterr()
    assert f"--script {record}: {REFUSED}" in captured.err
    assert "--until T or --days D replays to then without the person" in captured.err
    assert "doses_due" not in captured.out                   # nothing ran
    # the walkthrough says the same, with its own option
    assert main(["walkthrough", str(SPEC), "--replay", str(record), "--sound", "off"]) == 2
    assert f"--replay {record}: {REFUSED}" in capsys.readouterr().err


def test_run_script_with_an_end_runs_a_session_quit_at_once(compiled, tmp_path, capsys):
    record = tmp_path / "at-once.json"
    WalkSession(compiled, record=record, spec_path=str(SPEC)).close()
    capsys.readouterr()
    assert main(["run", str(SPEC), "--script", str(record), "--until", "9h",
                 "--timeline", "none"]) == 0
    assert "doses_due" in capsys.readouterr().out


def test_run_script_of_a_session_that_ran_is_not_refused(compiled, tmp_path, capsys):
    record = tmp_path / "ran.json"
    session = WalkSession(compiled, record=record, spec_path=str(SPEC))
    session.run_to(3600.0)
    session.close()
    capsys.readouterr()
    assert main(["run", str(SPEC), "--script", str(record), "--timeline", "none"]) == 0
    assert "doses_due" in capsys.readouterr().out
