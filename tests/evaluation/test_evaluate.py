"""`opspec evaluate`: many users, results independent of workers and backend, summaries that
match the reference scenario's closed form, paired comparisons, reports, exports, worlds.
Faults are in test_faults.py, bad input in test_bad_input.py."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import pytest
from conftest import SPEC, USERS_TOML, metrics_of

from opspec.cli import main


def test_same_seed_gives_the_same_results_with_one_or_two_workers(evaluate, tmp_path):
    args = [str(SPEC), "--users", "12", "--days", "3", "--seed", "5"]
    s1, one, _ = evaluate(*args, "--workers", "1", "--out", str(tmp_path / "w1"))
    s2, two, _ = evaluate(*args, "--workers", "2", "--out", str(tmp_path / "w2"))
    assert s1 == s2 == 0
    assert one["workers"] == 1 and two["workers"] == 2
    assert metrics_of(one) == metrics_of(two)
    _, other, _ = evaluate(str(SPEC), "--users", "12", "--days", "3", "--seed", "6",
                           "--workers", "1", "--out", str(tmp_path / "s6"))
    assert metrics_of(other) != metrics_of(one)


def test_dask_cluster_gives_the_same_results_as_local_workers(evaluate, tmp_path):
    distributed = pytest.importorskip("distributed")
    args = [str(SPEC), "--users", "6", "--days", "2", "--seed", "3"]
    _, local, _ = evaluate(*args, "--workers", "1", "--out", str(tmp_path / "local"))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        status, remote, _ = evaluate(*args, "--scheduler", cluster.scheduler_address,
                                     "--out", str(tmp_path / "dask"))
    assert status == 0
    assert metrics_of(remote) == metrics_of(local)


def test_reference_users_match_the_closed_form_of_the_scenario(evaluate, tmp_path):
    """SCENARIO.md: P(missed) = 0.15^3 + sum_k 0.85 0.15^(k-1) P(W > 900 - a_k), W the walk
    (lognormal median 60 s, sigma 0.6) plus 10 s with probability 0.05."""
    from scipy import stats

    walk = stats.lognorm(s=0.6, scale=60.0)

    def p_walk_over(x: float) -> float:
        return 0.95 * walk.sf(x) + 0.05 * walk.sf(x - 10.0)

    p_miss = 0.15 ** 3 + sum(0.85 * 0.15 ** k * p_walk_over(900 - 300 * k) for k in range(3))
    assert p_miss == pytest.approx(0.003456, abs=2e-5)

    def p_report_after(t: float) -> float:
        return 1 - sum(0.85 * 0.15 ** k * (1 - p_walk_over(t - 300 * k))
                       for k in range(3) if t > 300 * k)

    alarms_per_dose = 1 + p_report_after(300) + p_report_after(600)

    status, doc, _ = evaluate(str(SPEC), "--users", "200", "--days", "30", "--seed", "1",
                              "--out", str(tmp_path / "ref"))
    assert status == 0
    missed = doc["metrics"]["missed_rate"]
    assert missed["ci95"][0] <= p_miss <= missed["ci95"][1]
    ratio = doc["metrics"]["alarms_per_dose"]
    assert ratio["ci95"][0] <= alarms_per_dose <= ratio["ci95"][1]
    latency = doc["metrics"]["report_latency_s"]
    assert latency["ci95"][0] <= 122.2 <= latency["ci95"][1]
    assert latency["p95"] == pytest.approx(393, rel=0.03)
    assert doc["metrics"]["doses_due"]["total"] == 200 * 30 * 4


def test_json_document_has_the_documented_shape(evaluate, tmp_path):
    status, doc, _ = evaluate(str(SPEC), "--users", "4", "--days", "2", "--out",
                              str(tmp_path / "o"), "--workers", "1")
    assert status == 0
    assert {"spec", "users", "days", "seed", "workers", "out", "report", "metrics",
            "failed"} <= set(doc)
    count = doc["metrics"]["doses_taken"]
    assert {"total", "mean", "sd", "ci95", "median", "p95"} <= set(count)
    assert len(count["ci95"]) == 2
    duration = doc["metrics"]["report_latency_s"]
    assert {"mean", "median", "p95", "ci95", "n"} <= set(duration)
    per_user = duration["per_user"]
    assert {"users", "mean", "sd", "ci95", "median", "p95"} <= set(per_user)
    assert per_user["users"] == 4 and per_user["ci95"][0] <= per_user["mean"]
    assert {"value", "ci95", "per_user"} <= set(doc["metrics"]["taken_rate"])
    assert doc["failed"] == []
    report = Path(doc["report"])
    html = report.read_text(encoding="utf-8")
    assert report.name == "report.html" and "data:image/png;base64," in html
    assert "report_latency_s" in html and "How users differ" in html
    assert (report.parent / "report.md").is_file()


def test_identical_designs_compared_on_the_same_users_differ_by_exactly_zero(evaluate,
                                                                              tmp_path):
    status, doc, _ = evaluate(str(SPEC), "--compare", str(SPEC), "--users", "8", "--days",
                              "2", "--workers", "1", "--out", str(tmp_path / "same"))
    assert status == 0
    for name, diff in doc["compare"]["difference"].items():
        if diff["difference"] is not None:
            assert diff["difference"] == pytest.approx(0.0, abs=1e-12), name
            assert not diff["significant"]


def test_a_longer_deadline_misses_fewer_doses_on_the_same_users(evaluate, tmp_path):
    longer = tmp_path / "dispenser_600s.xpdl"
    longer.write_text(SPEC.read_text(encoding="utf-8").replace("PT300S", "PT600S"),
                      encoding="utf-8")
    status, doc, _ = evaluate(str(SPEC), "--compare", str(longer), "--users", "40",
                              "--days", "10", "--seed", "2", "--out", str(tmp_path / "cmp"))
    assert status == 0
    alarms = doc["compare"]["difference"]["alarms_per_dose"]
    assert alarms["difference"] < 0 and alarms["significant"]
    assert alarms["ci95"][1] < 0


def test_exports_write_one_case_per_user(evaluate, tmp_path):
    from opspec.engine.trace_sinks import read_trace

    out = tmp_path / "exp"
    status, _doc, _ = evaluate(str(SPEC), "--users", "3", "--days", "1", "--workers", "2",
                              "--export", "xes,jsonl", "--out", str(out))
    assert status == 0
    cases = {e.data.get("case") for e in read_trace(out / "traces.jsonl")
             if e.kind != "case.started"} | {
        json.loads(line).get("case") for line in
        (out / "traces.jsonl").read_text(encoding="utf-8").splitlines()[1:]}
    assert {"A/0", "A/1", "A/2"} <= cases
    xes = (out / "traces.xes").read_text(encoding="utf-8")
    assert xes.count("<trace>") == 3


def test_summary_table_on_a_terminal_run(tmp_path, capsys):
    status = main(["evaluate", str(SPEC), "--users", "3", "--days", "1", "--workers", "1",
                   "--out", str(tmp_path / "t")])
    out = capsys.readouterr().out
    assert status == 0
    assert "95 % CI" in out and "taken_rate" in out and "%" in out
    assert f"report: {tmp_path / 't' / 'report.html'}" in out


def test_run_parameters_are_stored_for_other_readers(evaluate, tmp_path):
    out = tmp_path / "run"
    assert evaluate(str(SPEC), "--users", "2", "--days", "1", "--seed", "4", "--out",
                    str(out))[0] == 0
    with sqlite3.connect(out / "results.sqlite") as conn:
        run = {k: json.loads(v) for k, v in conn.execute("SELECT key, value FROM run")}
    assert run["spec"] == str(SPEC) and len(run["spec_sha256"]) == 64
    assert (run["users"], run["days"], run["seed"]) == (2, 1.0, 4)
    assert run["user_model"] == str(USERS_TOML)
    assert [d["label"] for d in run["designs"]] == ["A"]
    assert {"opspec_version", "started", "plan", "metrics"} <= set(run)


def test_specs_with_a_simulated_world_give_each_user_their_own_world(evaluate, tmp_path):
    """The vacuum cleaner's room comes from bindings.worlds, one per user from (seed, u):
    users differ, and the results do not depend on the number of workers."""
    spec = SPEC.parent / "vacuum_cleaner.xpdl"
    args = [str(spec), "--users", "3", "--days", "0.003", "--seed", "2"]
    status, one, err = evaluate(*args, "--workers", "1", "--out", str(tmp_path / "w1"))
    assert status == 0, err
    _, two, _ = evaluate(*args, "--workers", "2", "--out", str(tmp_path / "w2"))
    assert metrics_of(one) == metrics_of(two)
    covered = one["metrics"]["cells_covered"]
    assert covered["total"] > 0 and covered["sd"] > 0
