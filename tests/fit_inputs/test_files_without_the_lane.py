"""A trace with no event of the lane fitted or checked (a trace of another spec, a devices-only
run) is read, said, and not counted as a person: counted, it added a person with nothing
observed to the persons a fit names, writes in [fitted_on] and resamples (five or more
persons switch the redraws to resampling persons), and to the group size model-check
simulates."""

from __future__ import annotations

import json
import random
from pathlib import Path

from opspec.cli import main

from .trace_files import walks, write_trace


def _person(path: Path, person: str, seed: int) -> Path:
    rng = random.Random(seed)
    return write_trace(path, walks(rng.lognormvariate(3.5, 0.3) for _ in range(15)),
                       person=person)


def _devices_only(path: Path) -> Path:
    """The trace of another spec: only its device lane did anything."""
    lines = [{"format": "opspec-trace", "version": 1, "spec": "vacuum_cleaner.xpdl"},
             {"time": 0.0, "kind": "run.started"},
             {"time": 1.0, "kind": "activity.started", "activity": "sense", "lane": "device",
              "instance": 1},
             {"time": 2.0, "kind": "activity.completed", "activity": "sense",
              "lane": "device", "instance": 1}]
    path.write_text("".join(json.dumps(x) + "\n" for x in lines), encoding="utf-8")
    return path


def _traces(tmp_path: Path) -> Path:
    folder = tmp_path / "traces"
    folder.mkdir()
    for i in range(4):
        _person(folder / f"P{i}.jsonl", f"P{i}", i)
    _devices_only(folder / "vacuum.jsonl")
    return folder


def test_fit_leaves_out_and_says_a_trace_without_the_lane(tmp_path, capsys) -> None:
    folder = _traces(tmp_path)
    model = tmp_path / "m.users.toml"
    assert main(["fit", str(folder), "-o", str(model), "--draws", "20", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["persons"]["count"] == 4
    assert doc["persons"]["sessions"] == 4
    assert [x["file"] for x in doc["left_out_without_lane"]] == [str(folder / "vacuum.jsonl")]
    assert doc["left_out_without_lane"][0]["lanes_seen"] == ["device"]
    text = model.read_text(encoding="utf-8")
    assert "vacuum" not in text.split("[fitted_on]")[1].split("[uncertainty]")[0]
    # four persons: their observations are resampled within each, not persons
    assert 'resampled = "observations within each person"' in text

    assert main(["fit", str(folder), "-o", str(tmp_path / "n.users.toml"),
                 "--draws", "0"]) == 0
    out = capsys.readouterr().out
    assert "persons: 4 person(s), 4 session(s)" in out
    assert "left out 1 trace file(s) with no activity of lane 'user'" in out
    assert "vacuum.jsonl: lanes seen device" in out


def test_model_check_counts_only_people_of_the_lane(tmp_path, capsys) -> None:
    folder = _traces(tmp_path)
    model = tmp_path / "m.users.toml"
    assert main(["fit", *map(str, sorted(folder.glob("P*.jsonl"))), "-o", str(model),
                 "--draws", "0"]) == 0
    capsys.readouterr()
    status = main(["model-check", str(model), str(folder), "--replicates", "99", "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert status in (0, 1)
    assert doc["persons"] == 4 and doc["sessions"] == 4
    assert any("vacuum.jsonl" in n and "not counted as persons" in n for n in doc["notes"])
