"""``opspec evaluate --workers W`` runs at most as many worker processes as the cores it may
run on, and says so in one line: the results are the same for any number of workers
(docs/evaluation.md), so a process more than the cores only costs memory and start-up
(``--workers 100`` forked 100 processes on a machine of two cores)."""

from __future__ import annotations

from pathlib import Path

import opspec.commands.evaluate as command
from opspec.evaluation import runner

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "medication_dispenser.xpdl"


def _pools(monkeypatch) -> list[int]:
    """The ``max_workers`` of every process pool the run opens."""
    sizes: list[int] = []
    real = runner.cf.ProcessPoolExecutor

    def pool(*args, max_workers=None, **kwargs):
        sizes.append(max_workers)
        return real(*args, max_workers=max_workers, **kwargs)

    monkeypatch.setattr(runner.cf, "ProcessPoolExecutor", pool)
    return sizes


def test_more_workers_than_cores_run_as_many_as_the_cores(evaluate, monkeypatch, tmp_path):
    monkeypatch.setattr(command, "_local_cores", lambda: 2)
    pools = _pools(monkeypatch)
    status, doc, err = evaluate(str(SPEC), "--users", "4", "--days", "1", "--workers", "100",
                                "--out", str(tmp_path / "o"), "--quiet", report=False)
    assert status == 0 and doc is not None
    assert doc["workers"] == 2 and pools == [2]
    said = [line for line in err.splitlines() if "--workers 100" in line]
    assert said == [("opspec evaluate: --workers 100: this process may run on 2 cores, so 2 "
                     "workers run (the results are the same for any number of workers)")]


def test_workers_up_to_the_cores_are_taken_as_given(evaluate, monkeypatch, tmp_path):
    monkeypatch.setattr(command, "_local_cores", lambda: 2)
    pools = _pools(monkeypatch)
    status, doc, err = evaluate(str(SPEC), "--users", "4", "--days", "1", "--workers", "2",
                                "--out", str(tmp_path / "o"), "--quiet", report=False)
    assert status == 0 and doc["workers"] == 2 and pools == [2]
    assert "--workers" not in err
