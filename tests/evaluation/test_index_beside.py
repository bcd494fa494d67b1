"""`opspec evaluate --workers W` (W > 1) builds the store's sample index on a thread of its
own while it asks for the report's first figures and computes the summaries
(``ResultStore.index(beside=True)``). What reads the samples must read them indexed, as with
one worker; what reads other tables, and the summaries' temporary tables, must not wait for
it; a failure of the index (a full disk) must be the usual error with the command that
finishes the run."""

from __future__ import annotations

import sqlite3
import threading
from pathlib import Path
from typing import Any

import pytest
from evaluation_inputs import SPEC

from opspec.evaluation import sample_index
from opspec.evaluation.store import ResultStore


def _indexes(path: Path) -> set[str]:
    with sqlite3.connect(path) as db:
        return {name for (name,) in db.execute(
            "SELECT name FROM sqlite_master WHERE type = 'index'")}


@pytest.fixture
def stored(evaluate: Any, tmp_path: Path) -> Path:
    """A finished run's folder, its sample index dropped again."""
    out = tmp_path / "run"
    status, _, err = evaluate(str(SPEC), "--users", "4", "--days", "1", "--seed", "3",
                              "--workers", "1", "--out", str(out), report=False)
    assert status == 0, err
    with sqlite3.connect(out / "results.sqlite") as db:
        db.execute("DROP INDEX sample_by_metric")
    return out


def test_sample_reads_wait_for_the_index_other_reads_and_temporary_tables_do_not(
        stored: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    release = threading.Event()
    building = sample_index.IndexBeside._build

    def held(indexing: Any) -> None:    # the index begins only once the test says so
        release.wait(30)
        building(indexing)

    monkeypatch.setattr(sample_index.IndexBeside, "_build", held)
    with ResultStore(stored, create=False) as store:
        store.index(beside=True)
        # another table, and this connection's temporary tables while another connection
        # holds the write lock (as the index's does while it sorts): no waiting
        assert store.get("plan")["users"] == 4
        other = sqlite3.connect(stored / "results.sqlite", isolation_level=None)
        other.execute("BEGIN IMMEDIATE")
        store.scratch("CREATE TEMP TABLE scratch_values (v REAL)")
        store.scratch_rows("INSERT INTO scratch_values VALUES (?)", [(1.0,), (2.0,)])
        assert store.query("SELECT COUNT(*) FROM scratch_values") == [(2,)]
        other.execute("ROLLBACK")
        other.close()
        assert not release.is_set() and "sample_by_metric" not in _indexes(
            stored / "results.sqlite")
        release.set()
        # a read of the samples: once the index is there
        rows = store.query("SELECT value FROM sample WHERE design = 'A' LIMIT 1")
        assert rows and "sample_by_metric" in _indexes(stored / "results.sqlite")
    assert not [t for t in threading.enumerate() if t.name == "opspec-sample-index"]


def test_a_write_waits_for_the_index(stored: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    with ResultStore(stored, create=False) as store:
        store.index(beside=True)
        store.put("note", "after the index")
        assert "sample_by_metric" in _indexes(stored / "results.sqlite")
        assert store.get("note") == "after the index"


def _disk_full(indexing: Any) -> None:
    indexing.error = sqlite3.OperationalError("database or disk is full")


def test_a_full_disk_as_the_index_is_built_beside_is_exit_2_and_resume_finishes(
        evaluate: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "run"
    with monkeypatch.context() as patch:
        patch.setattr(sample_index.IndexBeside, "_build", _disk_full)
        status, _, err = evaluate(str(SPEC), "--users", "4", "--days", "1", "--seed", "3",
                                  "--workers", "2", "--out", str(out), report=False)
    assert status == 2, err
    assert "internal error" not in err and "Traceback" not in err
    assert "cannot index the stored results: database or disk is full" in err, err
    assert f"opspec evaluate --resume --out {out}" in err, err
    status, doc, err = evaluate("--resume", "--out", str(out), "--workers", "2",
                                report=False)
    assert status == 0, err
    assert doc is not None and doc["metrics"]["doses_due"]["users"] == 4
    assert "sample_by_metric" in _indexes(out / "results.sqlite")


def test_without_a_thread_the_index_is_built_in_place(
        stored: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def no_thread(_thread: Any) -> None:
        raise RuntimeError("can't start new thread")

    monkeypatch.setattr(sample_index.threading.Thread, "start", no_thread)
    with ResultStore(stored, create=False) as store:
        store.index(beside=True)
        assert "sample_by_metric" in _indexes(stored / "results.sqlite")
