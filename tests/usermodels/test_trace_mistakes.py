"""What `opspec fit` and `opspec model-check` say to a researcher who gives the wrong file: a
walkthrough's recording (the script beside its trace), a trace whose last line was cut when
the recording stopped. Each names file:line and what to do."""

from __future__ import annotations

import json
from pathlib import Path

from opspec.cli import main


def _trace(path: Path, cut: bool = False) -> Path:
    lines = [json.dumps({"format": "opspec-trace", "version": 1, "person": "P01"}),
             json.dumps({"time": 0.0, "kind": "run.started"})]
    for i in range(1, 4):
        lines.append(json.dumps({"time": 100.0 * i, "kind": "activity.offered",
                                 "activity": "walk", "lane": "user", "instance": i}))
        lines.append(json.dumps({"time": 100.0 * i + 30 + i, "kind": "activity.completed",
                                 "activity": "walk", "lane": "user", "instance": i}))
    text = "\n".join(lines) + "\n"
    path.write_text(text[:-25] if cut else text, encoding="utf-8")
    return path


def test_a_walkthrough_recording_names_its_trace(tmp_path: Path, capsys) -> None:
    recording = tmp_path / "A.json"
    recording.write_text('{"otherwise": "wait", "steps": [\n  ["at 5.0", "complete walk #1"]\n'
                         ']}\n', encoding="utf-8")
    _trace(tmp_path / "A.trace.jsonl")
    for command in (["fit", str(recording), "-o", str(tmp_path / "m.toml")],
                    ["model-check", "dispenser-reference", str(recording)]):
        assert main(command) == 2
        err = capsys.readouterr().err
        assert f"{recording}:1: a walkthrough recording or script" in err
        assert f"its trace is {tmp_path / 'A.trace.jsonl'}" in err
    assert not (tmp_path / "m.toml").exists()


def test_a_script_without_its_trace_says_what_to_give(tmp_path: Path, capsys) -> None:
    script = tmp_path / "steps.json"
    script.write_text('{"steps": [], "otherwise": "wait"}\n', encoding="utf-8")
    assert main(["fit", str(script), "-o", str(tmp_path / "m.toml")]) == 2
    err = capsys.readouterr().err
    assert "not a trace" in err and "NAME.trace.jsonl" in err


def test_a_cut_last_line_is_named_as_cut(tmp_path: Path, capsys) -> None:
    trace = _trace(tmp_path / "P01.jsonl", cut=True)
    assert main(["fit", str(trace), "-o", str(tmp_path / "m.toml")]) == 2
    err = capsys.readouterr().err
    assert f"{trace}:8: not valid JSON" in err
    assert "last line is cut short" in err and "remove that last line" in err
