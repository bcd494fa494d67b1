"""A fault reaches the estimate through every front door (issue 33): ``simulate()`` - and so
the pytest fixture and ``*.scenario.toml`` files - fails the replications a run-time fault
cut short, as ``opspec evaluate`` does (the same users: user ``u`` of seed ``S`` is the same
run through every door), names each with the fault's file:line, and refuses to compute any
statistic over them: a statistical assertion or a scenario line over such a result fails
naming the fault instead of passing on truncated runs.

The spec is the dispenser whose condition divides by zero on the second re-alarm, its
rarest branch, so some users reach the fault and others do not."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

import opspec
from opspec.cli import main
from opspec.testing import assert_mean, assert_rate, simulate
from opspec.testing.scenario import load_scenarios, run_scenario
from opspec.testing.simulation import FailedReplications

SPEC = Path(__file__).resolve().parents[2] / "specs" / "medication_dispenser.xpdl"
USERS, DAYS, SEED = 6, 3, 2            # some of these users reach the second re-alarm


def test_simulate_fails_the_same_replications_as_evaluate_and_names_the_fault(
        broken_spec: Path, fault_site: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str], no_report) -> None:
    # evaluate's failures in its report: test_evaluate_faults.py; here its --json
    # (tests/evaluate_without_report.py)
    result = simulate(broken_spec, users=USERS, days=DAYS, seed=SEED)   # the companion users
    where = fault_site
    assert 1 <= len(result.failed) < USERS and result.complete == USERS - len(result.failed)
    for failed in result.failed:
        assert failed.problem.startswith(f"fault: {where}: activity 'R'")
        assert "division by zero" in failed.problem
    assert f"{len(result.failed)} failed" in repr(result)

    status = main(["evaluate", str(broken_spec), "--users", str(USERS), "--days", str(DAYS),
                   "--seed", str(SEED), "--workers", "1", "--out", str(tmp_path / "e"),
                   "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert status == 1
    assert sorted(f["user"] for f in doc["failed"]) == [f.replication for f in result.failed]
    assert [f["error"] for f in sorted(doc["failed"], key=lambda f: f["user"])] == [
        f.problem for f in result.failed]

    # one user's run through opspec.run says the same
    first = result.failed[0].replication
    assert opspec.run(broken_spec, seed=SEED, days=DAYS, user_index=first).problem == (
        result.failed[0].problem)


def test_no_statistic_is_computed_over_runs_a_fault_cut_short(broken_spec: Path,
                                                              fault_site: str) -> None:
    result = simulate(broken_spec, users=USERS, days=DAYS, seed=SEED)
    where = re.escape(fault_site)
    said = rf"(?s)\d of {USERS} replication\(s\) failed.*replication \d+: fault: {where}: "
    for statistic in (lambda: result.value("doses_missed"),
                      lambda: result.samples("doses_taken"),
                      lambda: result.counts("doses_missed", "doses_due"),
                      lambda: result.observations("report_latency_s"),
                      lambda: assert_rate(result, "missed_rate", at_most=0.5),
                      lambda: assert_mean(result, "doses_taken", at_least=0)):
        with pytest.raises(FailedReplications, match=said) as caught:
            statistic()
        assert isinstance(caught.value, AssertionError)      # the test fails, not errors
        assert "fix the spec at the file:line named" in str(caught.value)
    # what happened stays readable: the traces, and each failed run's own metrics
    assert len(result.traces) == USERS
    assert result.per_replication[result.failed[0].replication]["doses_due"]["total"] > 0


def test_a_scenario_over_runs_with_a_fault_fails_naming_it(broken_spec: Path, fault_site: str,
                                                          tmp_path: Path) -> None:
    scenario_file = tmp_path / "missed.scenario.toml"
    scenario_file.write_text(
        f'spec = "{broken_spec.as_posix()}"\n[[scenario]]\nname = "few doses missed"\n'
        f'given = {{ users = {USERS}, days = {DAYS}, seed = {SEED} }}\n'
        'then = ["rate doses_missed/doses_due <= 0.5 with 95% confidence"]\n', encoding="utf-8")
    (scenario,) = load_scenarios(scenario_file).scenarios
    failures = run_scenario(scenario, broken_spec)
    assert failures, "a scenario over runs cut short by a fault must not pass"
    assert re.search(rf"\d of {USERS} replication\(s\) failed", failures[0])
    assert f"fault: {fault_site}: activity 'R'" in failures[0]


def test_a_sound_spec_has_no_failed_replications(tmp_path: Path) -> None:
    result = simulate(SPEC, users=2, days=1, seed=SEED)
    assert result.failed == () and result.complete == 2
    assert result.value("doses_due") == 8
