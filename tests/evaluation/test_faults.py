"""`opspec evaluate` under faults: killed runs, crashing replications, dead workers and a
full disk lose no finished result, and `--resume` completes the rest."""

from __future__ import annotations

import json
import os
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest
from evaluation_inputs import SPEC, USERS_TOML, metrics_of


def test_interrupted_run_resumes_to_the_same_results(tmp_path, evaluate):
    out = tmp_path / "killed"
    # 200 users x 20 days: long enough that the run is still going when 5 users are stored, on a
    # fast idle machine too (40 users x 6 days, compiled, ended within 1.5 s, once between two
    # looks at the store, since the store now writes a chunk per transaction)
    cmd = [sys.executable, "-m", "opspec.cli", "evaluate", str(SPEC), "--users", "200",
           "--days", "20", "--seed", "9", "--workers", "2", "--out", str(out), "--quiet"]
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
    assert 5 <= stored < 200, f"the run should have been killed part-way ({stored} stored)"
    # the pool's workers do not outlive the killed run
    assert workers, "the run should have started its worker pool"
    deadline = time.monotonic() + 30
    while any(Path(f"/proc/{w}").exists() for w in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not [w for w in workers if Path(f"/proc/{w}").exists()], "orphaned workers"
    status, resumed, err = evaluate("--resume", "--out", str(out), "--workers", "2")
    assert status == 0, err
    _, whole, _ = evaluate(str(SPEC), "--users", "200", "--days", "20", "--seed", "9",
                           "--workers", "2", "--out", str(tmp_path / "whole"), report=False)
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
                           r"database or disk is full.*free some space, then `opspec "
                           r"evaluate --resume"):
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


def test_failed_replications_are_listed_exit_1_and_resume_completes_them(evaluate, tmp_path,
                                                                         monkeypatch):
    from opspec import runs
    from opspec.errors import ExecutionError

    real = runs._world

    def broken_for_user_1(compiled, seed, user):
        if user == 1:
            raise ExecutionError("the simulated device fell over")
        return real(compiled, seed, user)

    out = str(tmp_path / "run")
    monkeypatch.setattr(runs, "_world", broken_for_user_1)
    status, doc, _ = evaluate(str(SPEC), "--users", "3", "--days", "1", "--workers", "1",
                              "--out", out)
    assert status == 1
    assert doc["failed"] == [{"design": "A", "user": 1, "kind": "error",
                              "error": "the simulated device fell over"}]
    assert doc["metrics"]["doses_due"]["users"] == 2
    html = Path(doc["report"]).read_text(encoding="utf-8")
    assert "Failed replications" in html and "the simulated device fell over" in html
    monkeypatch.undo()
    status, doc, _ = evaluate("--resume", "--out", out)
    assert status == 0 and doc["failed"] == []
    assert doc["metrics"]["doses_due"]["users"] == 3


def test_a_report_that_cannot_be_written_keeps_the_results_and_resume_writes_it(
        evaluate, tmp_path, monkeypatch):
    import errno

    from opspec.evaluation import report

    def disk_full(store, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    out = tmp_path / "run"
    monkeypatch.setattr(report, "write_report", disk_full)
    status, doc, err = evaluate(str(SPEC), "--users", "3", "--days", "1", "--workers", "1",
                                "--out", str(out))
    assert status == 2 and doc is None
    assert "cannot write the report: No space left on device" in err
    assert f"--resume --out {out}" in err and "Traceback" not in err
    monkeypatch.undo()
    status, doc, _ = evaluate("--resume", "--out", str(out))
    assert status == 0 and Path(doc["report"]).is_file()
    assert doc["metrics"]["doses_due"]["total"] == 3 * 4


def test_resumed_export_has_every_users_trace_in_one_file(tmp_path, evaluate):
    """An export interrupted part-way (users 0-2 stored, their cases in traces.jsonl.partial)
    and resumed gives one complete traces.jsonl, equal to an uninterrupted run's."""
    args = [str(SPEC), "--users", "6", "--days", "1", "--seed", "3", "--workers", "1",
            "--export", "jsonl"]
    # no report but the resumed run's: the exports and results are what is compared
    status, _, _ = evaluate(*args, "--out", str(tmp_path / "whole"), report=False)
    assert status == 0
    whole = (tmp_path / "whole" / "traces.jsonl").read_text(encoding="utf-8")
    # the interrupted run: the same, with users 3-5 not stored and the trace file cut short
    cut = tmp_path / "cut"
    evaluate(*args, "--out", str(cut), report=False)
    with sqlite3.connect(cut / "results.sqlite") as conn:
        conn.execute("DELETE FROM replication WHERE user >= 3")
    lines = (cut / "traces.jsonl").read_text(encoding="utf-8").splitlines(keepends=True)
    (cut / "traces.jsonl").unlink()
    (cut / "traces.jsonl.partial").write_text("".join(lines[:len(lines) // 2]),
                                              encoding="utf-8")
    status, doc, err = evaluate("--resume", "--out", str(cut), "--workers", "1")
    assert status == 0, err
    assert (cut / "traces.jsonl").read_text(encoding="utf-8") == whole
    assert not (cut / "traces.jsonl.partial").exists()
    # and the resumed results are those of an uninterrupted run (re-traced users not doubled)
    _, again, _ = evaluate(str(SPEC), "--users", "6", "--days", "1", "--seed", "3",
                           "--workers", "1", "--out", str(tmp_path / "again"), report=False)
    assert metrics_of(doc) == metrics_of(again)
