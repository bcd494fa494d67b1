"""A session that breaks off: `opspec study --participant` keeps what was recorded apart at
once, as VARIANT.partial-N.*, and names it, so that VARIANT.json is only ever a whole
session (docs/walkthrough.md, A study). The participant's terminal is replaced by an app
that records a little and quits early; the Pilot-driven sessions are tests/study/test_study.py.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from opspec.cli import main
from opspec.tui import study


class _QuitEarly:
    """What session_app returns: an app that records the start of the session and quits,
    and its walk, which did not reach the end."""

    ended = False
    failure = None

    def __init__(self, session: Any) -> None:
        self.session = session

    def run(self) -> None:
        self.session.recording.parent.mkdir(parents=True, exist_ok=True)
        self.session.recording.write_text('{"otherwise": "wait", "steps": []}\n',
                                          encoding="utf-8")
        self.session.trace.write_text('{"format": "opspec-trace", "version": 1}\n',
                                      encoding="utf-8")

    def close(self) -> None:
        pass


def test_a_broken_off_session_is_kept_apart_and_named(protocol_file: Path, capsys,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    def session_app(protocol: Any, session: Any) -> tuple[Any, Any]:
        study._move_partial(session)
        app = _QuitEarly(session)
        return app, app

    monkeypatch.setattr(study, "session_app", session_app)
    assert main(["study", str(protocol_file), "--participant", "P01"]) == 1
    out = capsys.readouterr().out
    folder = protocol_file.parent / "rec" / "P01"
    kept = folder / "A.partial-1.json"
    assert f"kept apart as {kept}" in out and "A.partial-1.trace.jsonl" in out
    assert kept.is_file() and (folder / "A.partial-1.trace.jsonl").is_file()
    # nothing under the name of a whole session: a fit of the folder does not take it
    assert not (folder / "A.json").exists() and not (folder / "A.trace.jsonl").exists()
    # the second attempt breaks off too: kept beside the first, not over it
    assert main(["study", str(protocol_file), "--participant", "P01"]) == 1
    assert "A.partial-2.json" in capsys.readouterr().out
    assert kept.is_file() and (folder / "A.partial-2.json").is_file()
