"""A spec that declares no metrics (a modeller's diagram with simulation parameters) is
measured per process by ``opspec evaluate``: its completed instances and their cycle time,
said to be opspec's defaults on the command's output and in the report (docs/evaluation.md,
Default metrics). A spec that declares metrics is measured by those alone."""

from __future__ import annotations

from pathlib import Path

import pytest

import opspec
from opspec.request import RunRequest, prepare

ROOT = Path(__file__).resolve().parents[2]
LOAN = ROOT / "tests" / "bpmn" / "data" / "simulation" / "qbp_loan.bpmn"    # QBP arrivals
DISPENSER = ROOT / "specs" / "medication_dispenser.xpdl"
DAYS = "0.1"


def test_each_process_is_measured_and_the_numbers_are_the_trace_s(evaluate, tmp_path) -> None:
    """One user, seed 5: evaluate's count and mean cycle time are those of the trace of
    ``opspec.run`` with the same seed (user 0 of the evaluation), counted here from the
    process.started and process.completed events."""
    status, doc, err = evaluate(str(LOAN), "--users", "1", "--days", DAYS, "--seed", "5",
                                "--out", str(tmp_path / "out"))
    assert status == 0
    assert set(doc["metrics"]) == {"loan_process_completed", "loan_process_cycle_time_s"}
    assert "declares no metrics (opspec:Metrics), so each process is measured by default: " \
           "loan_process_completed, loan_process_cycle_time_s" in " ".join(err.split())
    trace = opspec.run(LOAN, seed=5, days=float(DAYS)).trace
    started = {e.instance: e.time for e in trace
               if e.kind == "process.started" and e.process == "loan_process"}
    cycle = [e.time - started[e.instance] for e in trace
             if e.kind == "process.completed" and e.process == "loan_process"]
    assert len(cycle) > 5
    assert doc["metrics"]["loan_process_completed"]["mean"] == len(cycle)
    assert doc["metrics"]["loan_process_cycle_time_s"]["mean"] == pytest.approx(
        sum(cycle) / len(cycle), rel=1e-12)
    report = (tmp_path / "out" / "report.md").read_text(encoding="utf-8")
    assert "opspec measured each process by default" in report
    assert "Metrics the spec declares" not in report


def test_a_spec_that_declares_metrics_keeps_only_its_own() -> None:
    declared = prepare(RunRequest(DISPENSER, no_user=True)).package.metrics
    assert declared
    asked = prepare(RunRequest(DISPENSER, no_user=True, default_metrics=True)).package.metrics
    assert asked == declared


def test_other_doors_measure_nothing_they_were_not_asked_to() -> None:
    """``opspec run`` (and the API) of such a spec show no metrics: only evaluate asks."""
    assert opspec.run(LOAN, seed=5, days=0.01).metrics == {}
