"""Which trace files `opspec fit` and `opspec model-check` read from a command line: a
study's recordings folder (RECORDINGS/PARTICIPANT/VARIANT.trace.jsonl) is searched with its
subfolders, its broken-off sessions (VARIANT.partial-N.trace.jsonl) are left out and said,
and a file reached twice is read once (docs/fitting.md)."""

from __future__ import annotations

import json
import random
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.usermodels.trace_reader import expand_traces


def _session(path: Path, person: str, seed: int, walks: int = 12) -> Path:
    """One session of ``person``: ``walks`` walks offered and completed, 20 s to 60 s."""
    rng = random.Random(seed)
    lines = [{"format": "opspec-trace", "version": 1, "person": person},
             {"time": 0.0, "kind": "run.started"}]
    t = 0.0
    for i in range(1, walks + 1):
        lines.append({"time": t, "kind": "activity.offered", "activity": "walk",
                      "lane": "user", "instance": i})
        t += rng.uniform(20, 60)
        lines.append({"time": t, "kind": "activity.completed", "activity": "walk",
                      "lane": "user", "instance": i})
        t += 100
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(json.dumps(x) + "\n" for x in lines), encoding="utf-8")
    return path


@pytest.fixture
def recordings(tmp_path: Path) -> Path:
    """A study's recordings: three participants, two variants each; P03 broke off A once."""
    rec = tmp_path / "recordings"
    for p, person in enumerate(("P01", "P02", "P03")):
        for v, variant in enumerate("AB"):
            _session(rec / person / f"{variant}.trace.jsonl", person, 10 * p + v)
    _session(rec / "P03" / "A.partial-1.trace.jsonl", "P03", 99, walks=2)
    return rec


def test_a_study_folder_is_searched_with_its_subfolders(recordings: Path) -> None:
    paths, left_out = expand_traces([str(recordings)])
    assert [p.relative_to(recordings).as_posix() for p in paths] == [
        "P01/A.trace.jsonl", "P01/B.trace.jsonl", "P02/A.trace.jsonl", "P02/B.trace.jsonl",
        "P03/A.trace.jsonl", "P03/B.trace.jsonl"]
    assert left_out == [recordings / "P03" / "A.partial-1.trace.jsonl"]
    # named itself, a broken-off session is read
    partial = recordings / "P03" / "A.partial-1.trace.jsonl"
    paths, left_out = expand_traces([str(recordings), str(partial)])
    assert partial in paths and left_out == []


def test_a_file_reached_twice_is_read_once(recordings: Path) -> None:
    one = recordings / "P01" / "A.trace.jsonl"
    paths, _ = expand_traces([str(recordings), str(one), str(recordings / "P01")])
    assert len(paths) == 6
    assert expand_traces([str(one), str(one)])[0] == [one]


def test_fit_reads_a_study_recordings_folder(recordings: Path, tmp_path: Path,
                                            capsys) -> None:
    out = tmp_path / "people.users.toml"
    assert main(["fit", str(recordings), "-o", str(out), "--draws", "0", "--json"]) == 0
    captured = capsys.readouterr()
    doc = json.loads(captured.out)
    assert doc["persons"]["count"] == 3
    assert doc["persons"]["sessions_per_person"] == {"P01": 2, "P02": 2, "P03": 2}
    assert "left out 1 trace(s) of study sessions that broke off" in captured.err
    assert "A.partial-1.trace.jsonl" in captured.err
    # the folder and one of its files: P01's session A is not counted twice
    assert main(["fit", str(recordings), str(recordings / "P01" / "A.trace.jsonl"),
                 "-o", str(out), "--draws", "0", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["persons"]["sessions_per_person"]["P01"] == 2


def test_model_check_reads_a_study_recordings_folder(recordings: Path, tmp_path: Path,
                                                     capsys) -> None:
    model = tmp_path / "people.users.toml"
    assert main(["fit", str(recordings / "P01"), str(recordings / "P02"), "-o", str(model),
                 "--draws", "0"]) == 0
    capsys.readouterr()
    main(["model-check", str(model), str(recordings / "P03"), "--replicates", "19",
          "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert doc["persons"] == 1 and doc["sessions"] == 2
    assert [Path(p).name for p in doc["traces"]] == ["A.trace.jsonl", "B.trace.jsonl"]
