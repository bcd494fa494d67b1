"""A walkthrough answer whose duration is not timed in real time (the clock ran fast, the
model had the lane) is left out of the durations but still answered its offer: the omission
rate's denominator counts it. It did not: 6 omissions beside 24 completions, 12 of them
untimed, were written as 6/18 = 0.33 where the people missed 6 of 30 = 0.2 (and the
redraws of the same file were centred on 0.2)."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import pytest

from opspec.cli import main

from .trace_files import write_trace


def _session(path: Path, person: str) -> Path:
    """Ten alarms: two missed, eight heard; of those, every other one not timed."""
    lines: list[dict] = []
    t = 0.0
    for i in range(1, 11):
        lines.append({"time": t, "kind": "activity.offered", "activity": "hear",
                      "lane": "user", "instance": i})
        t += 5.0 + i
        if i <= 2:
            lines.append({"time": t, "kind": "activity.omitted", "activity": "hear",
                          "lane": "user", "instance": i, "data": {"reason": "not noticed"}})
        else:
            if i % 2:
                lines.append({"time": t, "kind": "walkthrough.action", "data": {
                    "usable": False, "instance": i, "activity": "hear"}})
            lines.append({"time": t, "kind": "activity.completed", "activity": "hear",
                          "lane": "user", "instance": i})
        t += 100
    return write_trace(path, lines, person=person)


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    out = tmp_path / "rec"
    out.mkdir()
    for p in ("P01", "P02", "P03"):
        _session(out / f"{p}.jsonl", p)
    return out


def test_the_omission_rate_counts_every_answered_offer(folder, tmp_path, capsys) -> None:
    model = tmp_path / "m.users.toml"
    assert main(["fit", str(folder), "-o", str(model), "--draws", "0", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    hear = doc["activities"]["hear"]
    assert (hear["omission"]["omitted"], hear["omission"]["answered"]) == (6, 30)
    assert hear["omission"]["rate"] == pytest.approx(0.2)
    assert hear["n"] == 12 and doc["unusable_durations"] == {"hear": 12}
    written = tomllib.loads(model.read_text(encoding="utf-8"))
    assert written["activities"]["hear"]["omission"]["probability"] == pytest.approx(0.2)


def test_an_activity_never_timed_says_so(tmp_path, capsys) -> None:
    path = _session(tmp_path / "P01.jsonl", "P01")
    text = path.read_text(encoding="utf-8").replace(
        '"kind": "activity.completed"',
        '"kind": "activity.completed", "data": {}').splitlines()
    # every completion untimed
    out = []
    for line in text:
        event = json.loads(line)
        if event.get("kind") == "activity.completed":
            out.append(json.dumps({"time": event["time"], "kind": "walkthrough.action",
                                   "data": {"usable": False, "instance": event["instance"],
                                            "activity": "hear"}}))
        if event.get("kind") != "walkthrough.action":
            out.append(line)
    path.write_text("\n".join(out) + "\n", encoding="utf-8")
    assert main(["fit", str(path), "-o", str(tmp_path / "m.users.toml"), "--draws", "0"]) == 0
    printed = capsys.readouterr().out
    assert "no duration timed in real time (8 completion(s) left out)" in printed
    assert "omission: 2/10 = 0.2000" in printed


def test_activities_never_timed_are_named_as_not_in_the_model(tmp_path, capsys) -> None:
    """Every walk untimed (the model had the lane): the walk is not in the model, and the
    line that said 'their choices still count' says so."""
    lines: list[dict] = [{"format": "opspec-trace", "version": 1, "person": "P01"},
                         {"time": 0.0, "kind": "run.started"}]
    for i in range(1, 6):
        t = 1000.0 * i
        lines += [{"time": t, "kind": "activity.offered", "activity": "hear", "lane": "user",
                   "instance": i},
                  {"time": t + 5, "kind": "activity.completed", "activity": "hear",
                   "lane": "user", "instance": i},
                  {"time": t + 5, "kind": "activity.offered", "activity": "walk",
                   "lane": "user", "instance": i},
                  {"time": t + 60, "kind": "walkthrough.action", "data": {
                      "usable": False, "instance": i, "activity": "walk"}},
                  {"time": t + 60, "kind": "activity.completed", "activity": "walk",
                   "lane": "user", "instance": i}]
    path = tmp_path / "P01.jsonl"
    path.write_text("".join(json.dumps(x) + "\n" for x in lines), encoding="utf-8")
    assert main(["fit", str(path), "-o", str(tmp_path / "m.users.toml"), "--draws", "0"]) == 0
    out = capsys.readouterr().out
    assert "wrote" in out and "(1 activities: hear)" in out
    assert "not in the model, none of their answers timed: walk" in out
