"""`opspec evaluate`: many users, results independent of workers, stored as they finish,
summaries that match the reference scenario's closed form, reports, exports, bad inputs."""

from __future__ import annotations

import json
import os
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import SPEC, USERS_TOML

from opspec.cli import main


def metrics_of(doc: dict) -> dict:
    return {k: {f: v for f, v in m.items() if f != "users"} for k, m in doc["metrics"].items()}


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


def test_interrupted_run_resumes_to_the_same_results(tmp_path, evaluate):
    out = tmp_path / "killed"
    cmd = [sys.executable, "-m", "opspec.cli", "evaluate", str(SPEC), "--users", "40",
           "--days", "6", "--seed", "9", "--workers", "2", "--out", str(out), "--quiet"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            env={**os.environ, "PYTHONPATH": str(SPEC.parents[1])})
    db = out / "results.sqlite"
    deadline = time.monotonic() + 120
    stored = 0
    while time.monotonic() < deadline and proc.poll() is None:
        if db.exists():
            try:
                with sqlite3.connect(db, timeout=5) as conn:
                    stored = conn.execute("SELECT COUNT(*) FROM replication").fetchone()[0]
            except sqlite3.Error:
                stored = 0
            if stored >= 5:
                break
        time.sleep(0.05)
    workers = _children(proc.pid)
    proc.kill()
    proc.wait()
    assert 5 <= stored < 40, "the run should have been killed part-way"
    # the pool's workers do not outlive the killed run
    assert workers, "the run should have started its worker pool"
    deadline = time.monotonic() + 30
    while any(Path(f"/proc/{w}").exists() for w in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not [w for w in workers if Path(f"/proc/{w}").exists()], "orphaned workers"
    status, resumed, err = evaluate("--resume", "--out", str(out), "--workers", "2")
    assert status == 0, err
    _, whole, _ = evaluate(str(SPEC), "--users", "40", "--days", "6", "--seed", "9",
                           "--workers", "2", "--out", str(tmp_path / "whole"))
    assert metrics_of(resumed) == metrics_of(whole)


def _children(pid: int) -> list[int]:
    """Process ids whose parent is ``pid`` (Linux /proc; empty elsewhere)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


def test_failed_replications_are_recorded_and_resume_completes_them(tmp_path, monkeypatch):
    from opspec.evaluation import replication
    from opspec.evaluation.plan import Design, EvaluationPlan, file_digest
    from opspec.evaluation.runner import run_evaluation
    from opspec.evaluation.store import ResultStore

    plan = EvaluationPlan(designs=(Design("A", str(SPEC), file_digest(SPEC)),), users=6,
                          days=1, seed=0, user_model=str(USERS_TOML))
    real = replication.run_user

    def flaky(context, design, user, **kw):
        if user in (2, 4):
            raise RuntimeError("simulated crash")
        return real(context, design, user, **kw)

    with ResultStore(tmp_path, create=True) as store:
        store.put("plan", plan.to_json())
        monkeypatch.setattr(replication, "run_user", flaky)
        outcome = run_evaluation(plan, store, workers=1)
        monkeypatch.undo()
        # the crashing chunks are failed replications with the reason; the others are kept
        assert outcome.failed == 2 and outcome.done == 4
        assert store.finished("A") == {0, 1, 3, 5}
        assert [(u, "simulated crash" in e) for _, u, e in store.failures()] == [(2, True),
                                                                                 (4, True)]
        outcome = run_evaluation(plan, store, workers=1)
        assert outcome.skipped == 4 and outcome.done == 2
        assert store.finished("A") == set(range(6)) and store.failures() == []


def test_a_dead_worker_becomes_failed_replications_with_the_reason(tmp_path, monkeypatch):
    from opspec.evaluation import runner
    from opspec.evaluation.plan import Design, EvaluationPlan, file_digest
    from opspec.evaluation.store import ResultStore

    plan = EvaluationPlan(designs=(Design("A", str(SPEC), file_digest(SPEC)),), users=4,
                          days=1, seed=0, user_model=str(USERS_TOML))
    monkeypatch.setattr(runner, "run_users", _exit_in_worker)
    with ResultStore(tmp_path, create=True) as store:
        outcome = runner.run_evaluation(plan, store, workers=2)
        assert outcome.failed == 4 and outcome.done == 0
        assert all("worker failed" in error for _, _, error in store.failures())


def _exit_in_worker(plan, design, users):
    os._exit(3)


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


@pytest.mark.parametrize("content, message", [
    ('[activities.hear_alarm]\nduration = { kind = "zipf", a = 2 }\n', "zipf"),
    ('[activities.hear_alarm]\nduration = { kind = "lognormal", median = -60, sigma = 0.6 }\n',
     "median"),
    ('[activities.hear_alarm]\nduration = 0\nomission = { probability = 1.5 }\n',
     "probability"),
], ids=["unknown-distribution", "negative-scale", "probability-above-1"])
def test_bad_user_model_stops_before_any_simulation(content, message, evaluate, tmp_path):
    model = tmp_path / "bad.users.toml"
    model.write_text(content, encoding="utf-8")
    out = tmp_path / "never"
    status, doc, err = evaluate(str(SPEC), "--user-model", str(model), "--out", str(out))
    assert status == 2 and doc is None
    assert str(model) in err and message in err
    assert not out.exists()


def test_model_not_covering_a_manual_activity_names_it(evaluate, tmp_path):
    text = USERS_TOML.read_text(encoding="utf-8")
    start = text.index("[activities.take_pill]")
    end = text.find("\n[", start + 1)
    model = tmp_path / "partial.users.toml"
    model.write_text(text[:start] + (text[end:] if end != -1 else ""), encoding="utf-8")
    status, _, err = evaluate(str(SPEC), "--user-model", str(model), "--out",
                              str(tmp_path / "x"))
    assert status == 2
    assert "take_pill" in err and str(model) in err


def test_unwritable_output_folder_is_a_clear_error(evaluate, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder", encoding="utf-8")
    status, _, err = evaluate(str(SPEC), "--users", "2", "--days", "1", "--out",
                              str(blocker / "out"))
    assert status == 2
    assert "cannot create the output folder" in err and "Traceback" not in err


def test_existing_results_need_resume_and_resume_refuses_other_options(evaluate, tmp_path):
    out = str(tmp_path / "run")
    assert evaluate(str(SPEC), "--users", "2", "--days", "1", "--out", out)[0] == 0
    status, _, err = evaluate(str(SPEC), "--users", "2", "--days", "1", "--out", out)
    assert status == 2 and "already holds an evaluation" in err
    status, _, err = evaluate(str(SPEC), "--users", "3", "--days", "1", "--out", out,
                              "--resume")
    assert status == 2 and "users" in err
    status, doc, _ = evaluate("--resume", "--out", out)
    assert status == 0 and doc["users"] == 2


def test_unknown_export_format_and_resume_without_out(evaluate, tmp_path):
    status, _, err = evaluate(str(SPEC), "--export", "csv", "--out", str(tmp_path / "e"))
    assert status == 2 and "xes, jsonl" in err
    status, _, err = evaluate("--resume")
    assert status == 2 and "--resume needs --out" in err


def test_summary_table_on_a_terminal_run(tmp_path, capsys):
    status = main(["evaluate", str(SPEC), "--users", "3", "--days", "1", "--workers", "1",
                   "--out", str(tmp_path / "t")])
    out = capsys.readouterr().out
    assert status == 0
    assert "95 % CI" in out and "taken_rate" in out and "%" in out
    assert f"report: {tmp_path / 't' / 'report.html'}" in out


def _plan(users: int, days: float = 1):
    from opspec.evaluation.plan import Design, EvaluationPlan, file_digest

    return EvaluationPlan(designs=(Design("A", str(SPEC), file_digest(SPEC)),), users=users,
                          days=days, seed=0, user_model=str(USERS_TOML))


def _die_once_per_user(plan, design, users):
    """A worker process that dies (as if killed) the first time it meets user 1."""
    from opspec.evaluation.replication import run_users

    marker = Path(os.environ["OPSPEC_TEST_MARKER"])
    if 1 in users and not marker.exists():
        marker.write_text("died", encoding="utf-8")
        os._exit(9)
    return run_users(plan, design, users)


def test_chunks_lost_with_a_killed_worker_run_again_in_a_fresh_pool(tmp_path, monkeypatch):
    from opspec.evaluation import runner
    from opspec.evaluation.store import ResultStore

    monkeypatch.setenv("OPSPEC_TEST_MARKER", str(tmp_path / "marker"))
    monkeypatch.setattr(runner, "run_users", _die_once_per_user)
    with ResultStore(tmp_path / "run", create=True) as store:
        outcome = runner.run_evaluation(_plan(8), store, workers=2)
        assert (tmp_path / "marker").exists(), "the worker should have died once"
        assert outcome.failed == 0 and outcome.done == 8
        assert store.finished("A") == set(range(8)) and store.failures() == []


def test_a_full_disk_is_a_clear_error_and_leaves_a_sound_database(tmp_path):
    from opspec.errors import EvaluationError
    from opspec.evaluation.runner import run_evaluation
    from opspec.evaluation.store import ResultStore

    plan = _plan(30, days=3)
    with ResultStore(tmp_path, create=True) as store:
        store.put("plan", plan.to_json())
        pages = store.query("PRAGMA page_count")[0][0]
        # a disk with room for a few pages more than the empty database
        store.query(f"PRAGMA max_page_count = {pages + 6}")
        with pytest.raises(EvaluationError, match=r"cannot store replication A/\d+: "
                           r"database or disk is full.*writable"):
            run_evaluation(plan, store, workers=1)
        kept = store.finished("A")
        assert 0 < len(kept) < 30
    with sqlite3.connect(tmp_path / "results.sqlite") as conn:
        assert conn.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
        # every stored replication is whole: its samples are all there
        for user, metrics in conn.execute("SELECT user, metrics FROM replication"):
            n = json.loads(metrics)["report_latency_s"]["n"]
            stored = conn.execute("SELECT COUNT(*) FROM sample WHERE user = ?",
                                  (user,)).fetchone()[0]
            assert stored == n
    with ResultStore(tmp_path, create=False) as store:     # room again: resume finishes
        outcome = run_evaluation(plan, store, workers=1)
        assert outcome.skipped == len(kept) and store.finished("A") == set(range(30))


@pytest.mark.parametrize("args, message", [
    (["--users", "-3"], "--users must be a whole number >= 1"),
    (["--users", "0"], "--users must be a whole number >= 1"),
    (["--days", "-1"], "--days must be a positive number"),
    (["--days", "nan"], "--days must be a positive number"),
    (["--workers", "0"], "--workers must be >= 1"),
], ids=["negative-users", "no-users", "negative-days", "nan-days", "no-workers"])
def test_impossible_run_sizes_are_refused_before_anything_runs(args, message, evaluate,
                                                              tmp_path):
    out = tmp_path / "never"
    status, doc, err = evaluate(str(SPEC), *args, "--out", str(out))
    assert status == 2 and doc is None
    assert message in err
    assert not out.exists()


def test_broken_spec_stops_with_its_location_before_anything_runs(evaluate, tmp_path):
    broken = tmp_path / "broken.xpdl"
    broken.write_text(SPEC.read_text(encoding="utf-8").replace("</Activities>", "", 1),
                      encoding="utf-8")
    out = tmp_path / "never"
    status, doc, err = evaluate(str(broken), "--user-model", str(USERS_TOML), "--out",
                                str(out))
    assert status == 1 and doc is None
    assert f"{broken}:" in err and "Traceback" not in err
    assert not out.exists()


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


def test_resume_refuses_a_spec_changed_since_the_run_started(evaluate, tmp_path):
    spec = tmp_path / "dispenser.xpdl"
    spec.write_text(SPEC.read_text(encoding="utf-8"), encoding="utf-8")
    out = str(tmp_path / "run")
    assert evaluate(str(spec), "--users", "2", "--days", "1", "--user-model",
                    str(USERS_TOML), "--out", out)[0] == 0
    spec.write_text(SPEC.read_text(encoding="utf-8").replace("PT300S", "PT600S"),
                    encoding="utf-8")
    status, _, err = evaluate("--resume", "--out", out)
    assert status == 2 and f"{spec} changed since the run started" in err


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


def test_unreachable_scheduler_is_a_clear_error_before_anything_is_written(evaluate, tmp_path,
                                                                          monkeypatch):
    pytest.importorskip("distributed")
    import socket

    from opspec.evaluation import runner

    monkeypatch.setattr(runner, "SCHEDULER_TIMEOUT", 1)
    with socket.socket() as sock:            # a port nobody listens on
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    out = tmp_path / "never"
    status, doc, err = evaluate(str(SPEC), "--users", "2", "--days", "1", "--scheduler",
                                f"tcp://127.0.0.1:{port}", "--out", str(out))
    assert status == 2 and doc is None
    assert f"cannot reach the Dask scheduler at tcp://127.0.0.1:{port}" in err
    assert not out.exists()


def test_failed_replications_are_listed_exit_1_and_resume_completes_them(evaluate, tmp_path,
                                                                         monkeypatch):
    from opspec.errors import ExecutionError
    from opspec.evaluation import replication

    real = replication._world_performers

    def broken_for_user_1(compiled, seed, user):
        if user == 1:
            raise ExecutionError("the simulated device fell over")
        return real(compiled, seed, user)

    out = str(tmp_path / "run")
    monkeypatch.setattr(replication, "_world_performers", broken_for_user_1)
    status, doc, _ = evaluate(str(SPEC), "--users", "3", "--days", "1", "--workers", "1",
                              "--out", out)
    assert status == 1
    assert doc["failed"] == [{"design": "A", "user": 1,
                              "error": "the simulated device fell over"}]
    assert doc["metrics"]["doses_due"]["users"] == 2
    html = Path(doc["report"]).read_text(encoding="utf-8")
    assert "Failed replications" in html and "the simulated device fell over" in html
    monkeypatch.undo()
    status, doc, _ = evaluate("--resume", "--out", out)
    assert status == 0 and doc["failed"] == []
    assert doc["metrics"]["doses_due"]["users"] == 3
