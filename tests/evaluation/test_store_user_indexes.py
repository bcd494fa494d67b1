"""The result store's indexes: a fresh run leaves the sample values indexed by metric (what its
readers' quantiles need) and no index of rows by user (only --resume needs one: building it
cost a quarter of the store's time); a store with results opened again gets them, and a
resumed failed user's earlier rows are replaced, not doubled. (The store is the point: no
report is drawn, tests/evaluate_without_report.py.)"""

from __future__ import annotations

import sqlite3

from evaluation_inputs import SPEC, metrics_of

USER_INDEXES = {"sample_by_user", "outcome_by_user", "sample_by_metric"}
BY_USER = {"sample_by_user", "outcome_by_user"}


def _indexes(path) -> set[str]:
    with sqlite3.connect(path) as conn:
        return {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type='index'")}


def test_a_finished_run_has_its_readers_index_and_no_resume_index(tmp_path, evaluate):
    status, _, _ = evaluate(str(SPEC), "--users", "3", "--days", "1", "--workers", "1",
                            "--out", str(tmp_path / "run"), report=False)
    assert status == 0
    indexes = _indexes(tmp_path / "run" / "results.sqlite")
    assert "sample_by_metric" in indexes
    assert not BY_USER & indexes


def test_a_resumed_user_replaces_its_rows(tmp_path, evaluate):
    args = [str(SPEC), "--users", "4", "--days", "1", "--seed", "5", "--workers", "1"]
    status, whole, _ = evaluate(*args, "--out", str(tmp_path / "whole"), report=False)
    assert status == 0
    # user 2 stored as failed, its samples and outcomes left behind; the indexes gone, as
    # after a run killed before it ended
    run = tmp_path / "cut"
    evaluate(*args, "--out", str(run), report=False)
    db = run / "results.sqlite"
    with sqlite3.connect(db) as conn:
        conn.execute("UPDATE replication SET status = 'failed' WHERE user = 2")
        for name in USER_INDEXES:
            conn.execute(f"DROP INDEX IF EXISTS {name}")
        rows = conn.execute("SELECT COUNT(*) FROM outcome").fetchone()[0]
    status, resumed, err = evaluate("--resume", "--out", str(run), "--workers", "1",
                                    report=False)
    assert status == 0, err
    assert USER_INDEXES <= _indexes(db)
    with sqlite3.connect(db) as conn:
        assert conn.execute("SELECT COUNT(*) FROM outcome").fetchone()[0] == rows
    assert metrics_of(resumed) == metrics_of(whole)
