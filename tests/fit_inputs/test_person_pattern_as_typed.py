"""A --person-pattern that is wrong is quoted as it was typed: '(P\\d+' with one backslash,
which pasted back is the same pattern (Python's repr doubled it: '(P\\\\d+')."""

from __future__ import annotations

import json
from pathlib import Path

from opspec.cli import main


def test_a_broken_pattern_is_quoted_as_typed(tmp_path, capsys) -> None:
    trace = tmp_path / "P07-day2.jsonl"
    trace.write_text(json.dumps({"format": "opspec-trace", "version": 1}) + "\n",
                     encoding="utf-8")
    assert main(["fit", str(trace), "-o", str(tmp_path / "m.users.toml"),
                 "--person-pattern", r"(P\d+"]) == 2
    err = capsys.readouterr().err
    assert r"--person-pattern '(P\d+' is not a regular expression" in err
    assert main(["fit", str(trace), "-o", str(tmp_path / "m.users.toml"),
                 "--person-pattern", r"Q(\d+)"]) == 2
    err = capsys.readouterr().err
    assert f"{trace}: --person-pattern 'Q(\\d+)' does not match this file's path" in err
    assert "Traceback" not in err and not Path(tmp_path / "m.users.toml").exists()
