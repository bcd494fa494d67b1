"""Runs started together (a script that starts one evaluation per seed) each keep their own
results. Without --out they all wanted runs/<spec>-<date-time>, to the second: all but the
first were refused (exit 2) or, started closer together, let into one results.sqlite. Now the
default folder of a later one is <name>-2, -3…, and a store is created in one step that
refuses a second run into the same --out."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import pytest

from opspec.cli import main
from opspec.commands import evaluate_run
from opspec.errors import EvaluationError
from opspec.evaluation.store import ResultStore

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def test_a_default_folder_already_taken_gives_the_next_one(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    monkeypatch.chdir(tmp_path)
    taken = Path("runs") / "medication_dispenser-20260105-080000"
    monkeypatch.setattr(evaluate_run, "default_out", lambda spec: taken)
    taken.mkdir(parents=True)
    (taken / "results.sqlite").write_bytes(b"")          # the run started a moment before
    assert main(["evaluate", str(SPEC), "--users", "2", "--days", "0.25", "--seed", "2",
                 "--workers", "1", "--quiet"]) == 0
    mine = taken.with_name(taken.name + "-2")
    assert f"results: {mine / 'results.sqlite'}" in capsys.readouterr().out
    with sqlite3.connect(mine / "results.sqlite") as db:
        assert db.execute("SELECT value FROM run WHERE key = 'seed'").fetchone() == ("2",)
    assert (taken / "results.sqlite").read_bytes() == b""     # the other run's, untouched


def test_a_second_new_store_in_one_folder_is_refused(tmp_path: Path) -> None:
    with ResultStore(tmp_path, create=True, new=True), \
            pytest.raises(EvaluationError, match="already holds an evaluation"):
        ResultStore(tmp_path, create=True, new=True)
