"""`opspec evaluate`: many users, results independent of workers and backend, summaries that
match the reference scenario's closed form, paired comparisons, reports, exports, worlds.
Faults are in test_faults.py, bad input in test_bad_input.py."""

from __future__ import annotations

import json
import re
import sqlite3
from pathlib import Path

import pytest
from evaluation_inputs import SPEC, USERS_TOML, metrics_of

from opspec.cli import main


def test_same_seed_gives_the_same_results_with_one_or_two_workers(evaluate, monkeypatch,
                                                                    tmp_path):
    import opspec.commands.evaluate as command

    # two worker processes even on a machine of one core (the command runs at most as many
    # as the cores it may run on)
    monkeypatch.setattr(command, "_local_cores", lambda: 2)
    args = [str(SPEC), "--users", "12", "--days", "3", "--seed", "5"]
    s1, one, _ = evaluate(*args, "--workers", "1", "--out", str(tmp_path / "w1"))
    s2, two, _ = evaluate(*args, "--workers", "2", "--out", str(tmp_path / "w2"), report=False)
    assert s1 == s2 == 0
    assert one["workers"] == 1 and two["workers"] == 2
    assert metrics_of(one) == metrics_of(two)
    _, other, _ = evaluate(str(SPEC), "--users", "12", "--days", "3", "--seed", "6",
                           "--workers", "1", "--out", str(tmp_path / "s6"), report=False)
    assert metrics_of(other) != metrics_of(one)


@pytest.mark.parametrize("processes, workers", [
    (False, 1),
    pytest.param(True, 2, marks=pytest.mark.slow),     # ~10-20 s: starts two interpreters
], ids=["in-process-worker", "two-worker-processes"])
def test_dask_cluster_gives_the_same_results_as_local_workers(processes, workers, evaluate,
                                                              tmp_path):
    distributed = pytest.importorskip("distributed")
    args = [str(SPEC), "--users", "6", "--days", "2", "--seed", "3"]
    _, local, _ = evaluate(*args, "--workers", "1", "--out", str(tmp_path / "local"),
                           report=False)
    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1,
                                  processes=processes, dashboard_address=None) as cluster:
        status, remote, _ = evaluate(*args, "--scheduler", cluster.scheduler_address,
                                     "--out", str(tmp_path / "dask"))
    assert status == 0
    assert metrics_of(remote) == metrics_of(local)


def test_reference_users_match_the_closed_form_of_the_scenario(evaluate, tmp_path):
    """SCENARIO.md, with the user's parameters read from the model file: alarms at
    a_k = 0, 300, 600 s, the device gives up at 900 s; each alarm is heard with probability
    h; a heard alarm starts a walk W (lognormal) plus the wrong-button cost c with
    probability e, and later alarms are ignored on the way. So

        P(missed) = (1-h)^3 + sum_k h (1-h)^k P(W' > 900 - a_k),
        latency | taken  has density  sum_k h (1-h)^k f_W'(t - a_k) 1{t <= 900} / P(taken).
    """
    import tomllib

    from scipy import integrate, optimize, stats

    model = tomllib.loads(USERS_TOML.read_text(encoding="utf-8"))["activities"]
    h = 1 - model["hear_alarm"]["omission"]["probability"]
    walk_spec = model["walk_to_dispenser"]["duration"]
    walk = stats.lognorm(s=walk_spec["sigma"], scale=walk_spec["median"])
    e = model["choose_button"]["commission"]["probability"]
    c = model["press_wrong_button"]["duration"]
    alarms, interval = 3, 300.0                         # the spec: 3 alarms, PT300S apart
    starts = [k * interval for k in range(alarms)]
    give_up = alarms * interval
    first_heard = [h * (1 - h) ** k for k in range(alarms)]

    def walk_cdf(x: float) -> float:                    # W' = W, or W + c (wrong button)
        return (1 - e) * walk.cdf(x) + e * walk.cdf(x - c)

    def walk_pdf(x: float) -> float:
        return (1 - e) * walk.pdf(x) + e * walk.pdf(x - c)

    p_taken = sum(p * walk_cdf(give_up - a) for p, a in zip(first_heard, starts, strict=True))
    p_miss = 1 - p_taken
    assert p_miss == pytest.approx(0.003456, abs=2e-5)   # SCENARIO.md's 0.3456 %

    def latency_cdf(t: float) -> float:
        return sum(p * walk_cdf(min(t, give_up) - a) for p, a in
                   zip(first_heard, starts, strict=True) if t > a) / p_taken

    def latency_pdf(t: float) -> float:
        return sum(p * walk_pdf(t - a) for p, a in zip(first_heard, starts, strict=True)
                   if t > a) / p_taken

    latency_mean = sum(integrate.quad(lambda t: t * latency_pdf(t), a, b, limit=200)[0]
                       for a, b in zip(starts, [*starts[1:], give_up], strict=True))
    latency_p95 = optimize.brentq(lambda t: latency_cdf(t) - 0.95, 1.0, give_up)
    # an alarm after a_k sounds when no report came before it
    alarms_per_dose = 1 + sum(1 - latency_cdf(a) * p_taken for a in starts[1:])
    assert latency_mean == pytest.approx(122.2, abs=0.1)  # SCENARIO.md's values
    assert latency_p95 == pytest.approx(393, abs=1)

    users, days = 200, 30
    # the numbers are the point: no report (a plain evaluation's report is drawn and read in
    # tests/evaluation_output/, test_report_content.py and test_figure_numbers.py)
    status, doc, _ = evaluate(str(SPEC), "--users", str(users), "--days", str(days),
                              "--seed", "1", "--out", str(tmp_path / "ref"), report=False)
    assert status == 0
    metrics = doc["metrics"]
    assert metrics["doses_due"]["total"] == users * days * 4
    missed = metrics["missed_rate"]
    assert missed["ci95"][0] <= p_miss <= missed["ci95"][1]
    ratio = metrics["alarms_per_dose"]
    assert ratio["ci95"][0] <= alarms_per_dose <= ratio["ci95"][1]
    latency = metrics["report_latency_s"]
    assert latency["ci95"][0] <= latency_mean <= latency["ci95"][1]
    # the sample p95's standard error: sqrt(q (1-q) / n) / f(p95) (doses are independent)
    se_p95 = (0.95 * 0.05 / latency["n"]) ** 0.5 / latency_pdf(latency_p95)
    assert abs(latency["p95"] - latency_p95) <= 3.5 * se_p95


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
    assert report.name == "report.html" and "<svg" in html
    assert "report_latency_s" in html and "How users differ" in html
    assert (report.parent / "report.md").is_file()


def test_identical_designs_compared_on_the_same_users_differ_by_exactly_zero(evaluate,
                                                                              tmp_path):
    # no report: test_comparison_table_gives_units_and_rate_differences_in_points draws one
    status, doc, _ = evaluate(str(SPEC), "--compare", str(SPEC), "--users", "8", "--days",
                              "2", "--workers", "1", "--out", str(tmp_path / "same"),
                              report=False)
    assert status == 0
    for name, diff in doc["compare"]["difference"].items():
        if diff["difference"] is not None:
            assert diff["difference"] == pytest.approx(0.0, abs=1e-12), name
            assert not diff["significant"]


def test_a_shorter_re_alert_interval_sounds_more_alarms_for_the_same_users(evaluate, tmp_path):
    # Re-alerting after 150 s instead of 300 s re-alarms every dose whose report takes between
    # the two (about one dose in twenty here: +0.055 alarms per dose, 88 more alarms), so on the
    # same users the paired difference is clearly positive. (A longer interval than the shipped
    # 300 s changes only the handful of doses reported after 300 s: too few discordant events
    # at this size for the exact interval to call the difference significant.)
    shorter = tmp_path / "dispenser_150s.xpdl"
    shorter.write_text(SPEC.read_text(encoding="utf-8").replace("PT300S", "PT150S"),
                       encoding="utf-8")
    status, doc, _ = evaluate(str(SPEC), "--compare", str(shorter), "--users", "40",
                              "--days", "10", "--seed", "2", "--out", str(tmp_path / "cmp"),
                              report=False)
    assert status == 0
    alarms = doc["compare"]["difference"]["alarms_per_dose"]
    assert alarms["difference"] > 0 and alarms["significant"]
    assert alarms["ci95"][0] > 0


def test_exports_write_one_case_per_user_when_asked(evaluate, tmp_path):
    from opspec.engine.trace_sinks import read_trace

    out = tmp_path / "exp"
    status, _doc, _ = evaluate(str(SPEC), "--users", "3", "--days", "1", "--workers", "2",
                              "--export", "xes,jsonl", "--case", "user", "--out", str(out),
                              report=False)
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
    captured = capsys.readouterr()
    out = captured.out
    assert status == 0
    # not a terminal: plain progress lines on stderr, ending with the total
    assert "opspec evaluate: 3/3 users (" in captured.err and "done)" in captured.err
    assert "95 % CI" in out and "taken_rate" in out and "%" in out
    assert f"report: {tmp_path / 't' / 'report.html'}" in out


def test_run_parameters_are_stored_for_other_readers(evaluate, tmp_path):
    out = tmp_path / "run"
    assert evaluate(str(SPEC), "--users", "2", "--days", "1", "--seed", "4", "--out",
                    str(out), report=False)[0] == 0
    with sqlite3.connect(out / "results.sqlite") as conn:
        run = {k: json.loads(v) for k, v in conn.execute("SELECT key, value FROM run")}
    assert run["spec"] == str(SPEC) and len(run["spec_sha256"]) == 64
    assert (run["users"], run["days"], run["seed"]) == (2, 1.0, 4)
    assert run["user_model"] == str(USERS_TOML)
    assert [d["label"] for d in run["designs"]] == ["A"]
    assert {"opspec_version", "started", "plan", "metrics"} <= set(run)


def test_specs_with_a_simulated_world_give_each_user_their_own_world(evaluate, tmp_path):
    """The vacuum cleaner's room comes from opspec.worlds, one per user from (seed, u):
    users differ, and the results do not depend on the number of workers."""
    spec = SPEC.parent / "vacuum_cleaner.xpdl"
    args = [str(spec), "--users", "3", "--days", "0.003", "--seed", "2"]
    status, one, err = evaluate(*args, "--workers", "1", "--out", str(tmp_path / "w1"))
    assert status == 0, err
    _, two, _ = evaluate(*args, "--workers", "2", "--out", str(tmp_path / "w2"),
                         report=False)
    assert metrics_of(one) == metrics_of(two)
    covered = one["metrics"]["cells_covered"]
    assert covered["total"] > 0 and covered["sd"] > 0


def test_a_spec_with_a_run_length_is_evaluated_over_that_length(evaluate, tmp_path, capsys):
    """The cart declares opspec:RunLength PT10M: one run is ten minutes, not 30 days."""
    spec = SPEC.parent / "medication_cart_guidance.xpdl"
    status, doc, err = evaluate(str(spec), "--users", "2", "--workers", "1",
                                "--out", str(tmp_path / "cart"), report=False)
    assert status == 0, err
    assert doc["days"] == pytest.approx(600 / 86400)
    assert doc["metrics"]["patients_found"]["total"] == 2
    status = main(["evaluate", str(spec), "--users", "2", "--workers", "1",
                   "--out", str(tmp_path / "cart2")])
    assert status == 0
    assert "2 users x 10 min" in capsys.readouterr().out


def test_designs_with_different_metrics_compare_only_what_both_declare(evaluate, tmp_path):
    other = tmp_path / "dispenser_b.xpdl"
    text = SPEC.read_text(encoding="utf-8").replace(
        '<opspec:Count Name="caregiver_notified"', '<opspec:Count Name="caregiver_calls"')
    other.write_text(text, encoding="utf-8")
    status, doc, _ = evaluate(str(SPEC), "--compare", str(other), "--users", "3", "--days",
                              "1", "--workers", "1", "--user-model", str(USERS_TOML),
                              "--out", str(tmp_path / "cmp"))
    assert status == 0
    assert "caregiver_notified" in doc["metrics"]
    assert "caregiver_calls" in doc["compare"]["metrics"]
    assert "caregiver_notified" not in doc["compare"]["metrics"]
    difference = doc["compare"]["difference"]
    assert "caregiver_notified" not in difference and "caregiver_calls" not in difference
    assert difference["doses_due"]["difference"] == 0


def test_comparison_table_gives_units_and_rate_differences_in_points(tmp_path, capsys):
    # B waits 240 s instead of 300 s for the report: latency drops, in seconds
    spec_b = tmp_path / "shorter_wait.xpdl"
    spec_b.write_text(SPEC.read_text(encoding="utf-8").replace("PT300S", "PT240S"),
                      encoding="utf-8")
    (tmp_path / "shorter_wait.users.toml").write_text(USERS_TOML.read_text(encoding="utf-8"),
                                                      encoding="utf-8")
    status = main(["evaluate", str(SPEC), "--compare", str(spec_b), "--users", "40", "--days",
                   "2", "--workers", "1", "--out", str(tmp_path / "out"), "--quiet"])
    printed = capsys.readouterr().out.split("compared with B")[1]
    assert status == 0
    rows = {line.split()[0]: line for line in printed.splitlines()[3:] if line.strip()}
    latency = rows["report_latency_s"]
    assert latency.count(" s") >= 4 and "differs" in latency   # A, B, B − A and the CI
    # the column of 'differs' has a name, and the line above the table says what it means
    assert printed.splitlines()[1].split()[-1] == "verdict"
    assert "'differs': the 95 % interval excludes 0" in printed.splitlines()[0]
    assert " pp" in rows["taken_rate"] and "%" in rows["taken_rate"]
    assert (tmp_path / "out" / "figures" / "comparison.svg").stat().st_size > 10_000


def test_exports_cut_cases_by_chain_by_default_named_after_the_specs_workflow(
        evaluate, tmp_path):
    """The default case is one a process-discovery algorithm learns from: one run of the
    device's root workflow with everything it set in motion, named after that workflow of
    the spec (the dispenser's timer_workflow: one case per due dose)."""
    out = tmp_path / "exp"
    status, doc, _ = evaluate(str(SPEC), "--users", "2", "--days", "1", "--workers", "1",
                              "--export", "xes", "--out", str(out), report=False)
    assert status == 0
    xes = (out / "traces.xes").read_text(encoding="utf-8")
    assert xes.count("<trace>") == doc["metrics"]["doses_due"]["total"] == 8
    names = re.findall(r'<trace>\s*<string key="concept:name" value="([^"]+)"', xes)
    assert len(names) == 8 and all(re.fullmatch(r"A/[01]/timer_workflow#\d+", n)
                                   for n in names), names[:3]
