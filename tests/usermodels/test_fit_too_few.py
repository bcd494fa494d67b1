"""Too few observations to fit: one duration is not "all durations equal" (a statement about
a spread one value cannot show); `opspec fit` says it is one value, written as the model's
constant, and asks for more sessions."""

from __future__ import annotations

import json
from pathlib import Path

from opspec.cli import main
from opspec.usermodels.duration_family import fit_duration_families


def test_one_duration_is_said_to_be_one(tmp_path: Path, capsys) -> None:
    trace = tmp_path / "P01.jsonl"
    lines = [{"format": "opspec-trace", "version": 1, "person": "P01"},
             {"time": 0.0, "kind": "run.started"},
             {"time": 10.0, "kind": "activity.offered", "activity": "walk", "lane": "user",
              "instance": 1},
             {"time": 47.5, "kind": "activity.completed", "activity": "walk", "lane": "user",
              "instance": 1}]
    trace.write_text("".join(json.dumps(x) + "\n" for x in lines), encoding="utf-8")
    model = tmp_path / "m.users.toml"
    assert main(["fit", str(trace), "-o", str(model), "--draws", "0"]) == 0
    out = capsys.readouterr().out
    assert "walk: 1 observed duration(s); one duration only: too few to fit a distribution" \
        in out
    assert "all durations equal" not in out
    assert "one duration only" in model.read_text(encoding="utf-8")


def test_equal_durations_are_still_all_equal() -> None:
    _, chosen, fits, note = fit_duration_families([4.0, 4.0, 4.0])
    assert (chosen, fits, note) == ("constant", (), "all durations equal")
    assert fit_duration_families([4.0])[3].startswith("one duration only")
