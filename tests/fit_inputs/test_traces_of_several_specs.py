"""Traces recorded with more than one spec (a study's two variants, found together under its
recordings folder) are fitted into one model: said in one line, and per spec in --json. It
was said nowhere."""

from __future__ import annotations

import json
from pathlib import Path

from opspec.cli import main

from .trace_files import walks, write_trace


def _session(path: Path, person: str, spec: str) -> Path:
    return write_trace(path, walks(20.0 + (i * 7 + len(person)) % 30 for i in range(1, 13)),
                       person=person, spec=spec)


def test_two_variants_fitted_together_are_said(tmp_path, capsys) -> None:
    rec = tmp_path / "recordings"
    for person in ("P01", "P02", "P03"):
        _session(rec / person / "A.trace.jsonl", person, "/study/dispenser.xpdl")
        _session(rec / person / "B.trace.jsonl", person, "/study/dispenser-30s.xpdl")
    assert main(["fit", str(rec), "-o", str(tmp_path / "m.users.toml"), "--draws", "0"]) == 0
    out = capsys.readouterr().out
    assert ("specs: the traces were recorded with 2 specs (dispenser-30s.xpdl: 3 file(s); "
            "dispenser.xpdl: 3 file(s)): one model is fitted over all of them") in out
    assert main(["fit", str(rec), "-o", str(tmp_path / "n.users.toml"), "--draws", "0",
                 "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["specs"] == {"dispenser-30s.xpdl": 3, "dispenser.xpdl": 3}


def test_one_spec_says_nothing_of_specs(tmp_path, capsys) -> None:
    rec = tmp_path / "recordings"
    for person in ("P01", "P02"):
        _session(rec / person / "A.trace.jsonl", person, "/study/dispenser.xpdl")
    assert main(["fit", str(rec), "-o", str(tmp_path / "m.users.toml"), "--draws", "0"]) == 0
    assert "specs:" not in capsys.readouterr().out
