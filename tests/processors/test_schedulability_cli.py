"""`opspec check --schedulability`: the response-time analysis beside the preemptive
engine's simulation, on the task sets of test_preemptive.py."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from test_preemptive import task_set

from opspec.cli import main


def test_a_schedulable_set_prints_analysis_and_simulation_that_agree(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = task_set(tmp_path, [("t1", 1.0, 4.0, 3), ("t2", 2.0, 6.0, 2), ("t3", 3.0, 12.0, 1)])
    assert main(["check", str(path), "--schedulability", "--json"]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    [table] = [line for line in lines if "schedulability" in line]
    assert table["hyperperiod_s"] == 12.0
    assert [(r["workflow"], r["analysis_s"], r["simulated_worst_s"])
            for r in table["schedulability"]] == [("t1", 1.0, 1.0), ("t2", 3.0, 3.0),
                                                  ("t3", 10.0, 10.0)]


def test_an_unschedulable_set_is_reported_and_exits_1(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = task_set(tmp_path, [("t1", 2.0, 4.0, 3), ("t2", 2.0, 6.0, 2), ("t3", 3.0, 12.0, 1)])
    assert main(["check", str(path), "--schedulability"]) == 1
    out = capsys.readouterr().out
    [row] = [line for line in out.splitlines() if line.strip().startswith("t3")]
    assert "> D" in row and ">= 12" in row and "MISSES its deadline" in row
