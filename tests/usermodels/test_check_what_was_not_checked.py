"""`opspec model-check` says what its verdict does not cover: activities of the model that the
traces never show (traces of another spec share only some activities with it), and, with
--spec, traces recorded with another spec (a study's other variant) whose metrics it would
replay with this spec's definitions."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from opspec.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def _walks(path: Path, activity: str) -> Path:
    lines = [{"format": "opspec-trace", "version": 1, "person": path.stem},
             {"time": 0.0, "kind": "run.started"}]
    for i in range(1, 6):
        lines.append({"time": 100.0 * i, "kind": "activity.offered", "activity": activity,
                      "lane": "user", "instance": i})
        lines.append({"time": 100.0 * i + 20 + i, "kind": "activity.completed",
                      "activity": activity, "lane": "user", "instance": i})
    path.write_text("".join(json.dumps(x) + "\n" for x in lines), encoding="utf-8")
    return path


def test_activities_of_the_model_the_traces_never_show_are_named(tmp_path: Path,
                                                                 capsys) -> None:
    model = tmp_path / "m.users.toml"
    model.write_text('format = "opspec-user-model"\nversion = 1\nname = "m"\n'
                     '[activities.walk]\nduration = { kind = "lognormal", median = 23, '
                     'sigma = 0.1 }\n[activities.take_pill]\nduration = { kind = "lognormal", '
                     'median = 20, sigma = 0.3 }\n', encoding="utf-8")
    traces = [_walks(tmp_path / f"P{i}.jsonl", "walk") for i in range(3)]
    main(["model-check", str(model), *map(str, traces), "--replicates", "19", "--json"])
    notes = json.loads(capsys.readouterr().out)["notes"]
    assert "in the model but not in these traces (not checked): take_pill" in notes


def test_traces_of_another_spec_are_named_with_spec(tmp_path: Path, capsys) -> None:
    other = tmp_path / "dispenser-30s.xpdl"
    other.write_text(SPEC.read_text(encoding="utf-8").replace("PT300S", "PT30S"),
                     encoding="utf-8")
    shutil.copy(SPEC.with_name("medication_dispenser.users.toml"),
                tmp_path / "dispenser-30s.users.toml")
    a, b = tmp_path / "A.jsonl", tmp_path / "B.jsonl"
    assert main(["run", str(SPEC), "--days", "1", "--trace", str(a)]) == 0
    assert main(["run", str(other), "--days", "1", "--trace", str(b)]) == 0
    capsys.readouterr()
    main(["model-check", "dispenser-reference", str(a), str(b), "--spec", str(SPEC),
          "--days", "1", "--runs", "4", "--replicates", "19", "--json"])
    notes = json.loads(capsys.readouterr().out)["notes"]
    said = [n for n in notes if "recorded with another spec" in n]
    assert len(said) == 1
    assert said[0].startswith(f"1 of 2 trace file(s) were recorded with another spec than "
                              f"--spec {SPEC} (dispenser-30s.xpdl: {b})")
    # the traces of the spec itself: nothing to say
    main(["model-check", "dispenser-reference", str(a), "--spec", str(SPEC), "--days", "1",
          "--runs", "4", "--replicates", "19", "--json"])
    assert not [n for n in json.loads(capsys.readouterr().out)["notes"]
                if "another spec" in n]
