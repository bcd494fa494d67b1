"""The result store: one SQLite database per evaluation, in its output folder.

WAL mode, one transaction per replication, committed as soon as the replication finishes:
killing the run at any moment loses at most the replications in flight, and ``--resume``
runs only what is missing or failed. The schema (a contract with the report code and with
anyone who opens ``results.sqlite`` in another tool):

- ``run(key, value)``: JSON values — ``plan`` (the EvaluationPlan, what ``--resume``
  re-runs), ``metrics`` (the metrics design A declares; ``metrics_B`` those of B), and for other readers the same parameters as
  separate keys: ``spec``, ``spec_sha256``, ``designs``, ``users``, ``days``, ``seed``,
  ``user_model``, ``user_model_sha256``, ``opspec_version``, ``started``;
- ``replication(design, user, status, error, metrics, wall_s)``: one row per user and design,
  ``metrics`` the user's declared metrics as JSON (the ``opspec run --json`` shape);
- ``sample(design, user, metric, value, time)``: every duration observation, ``time`` the
  simulated time it ended;
- ``outcome(design, user, metric, day, hour, n)``: count-metric events by day (0-based) and
  hour of day;
- ``activity(design, user, activity, offered, completed, omitted, wrong)``: the user lane's
  manual activities;
- ``monitor(design, user, monitor, violations, first_time, first_message)``: one row per
  monitor the spec declares (``opspec:Monitor``) and user, also when there were none.
"""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Iterator
from pathlib import Path
from typing import Any, Self

from opspec.errors import EvaluationError
from opspec.evaluation.replication import ReplicationRecord

__all__ = ["SCHEMA_VERSION", "ResultStore"]

SCHEMA_VERSION = 1

_SCHEMA = """
CREATE TABLE IF NOT EXISTS run (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS replication (
    design TEXT NOT NULL, user INTEGER NOT NULL, status TEXT NOT NULL, error TEXT,
    metrics TEXT, wall_s REAL, PRIMARY KEY (design, user));
CREATE TABLE IF NOT EXISTS sample (
    design TEXT NOT NULL, user INTEGER NOT NULL, metric TEXT NOT NULL, value REAL NOT NULL,
    time REAL NOT NULL);
CREATE INDEX IF NOT EXISTS sample_by_metric ON sample (design, metric, value);
CREATE INDEX IF NOT EXISTS sample_by_user ON sample (design, user);
CREATE TABLE IF NOT EXISTS outcome (
    design TEXT NOT NULL, user INTEGER NOT NULL, metric TEXT NOT NULL, day INTEGER NOT NULL,
    hour INTEGER NOT NULL, n INTEGER NOT NULL);
CREATE INDEX IF NOT EXISTS outcome_by_user ON outcome (design, user);
CREATE TABLE IF NOT EXISTS activity (
    design TEXT NOT NULL, user INTEGER NOT NULL, activity TEXT NOT NULL, offered INTEGER,
    completed INTEGER, omitted INTEGER, wrong INTEGER);
CREATE INDEX IF NOT EXISTS activity_by_user ON activity (design, user);
CREATE TABLE IF NOT EXISTS monitor (
    design TEXT NOT NULL, user INTEGER NOT NULL, monitor TEXT NOT NULL,
    violations INTEGER NOT NULL, first_time REAL, first_message TEXT);
CREATE INDEX IF NOT EXISTS monitor_by_user ON monitor (design, user);
"""

FILENAME = "results.sqlite"


def _fail(path: Path, doing: str, error: BaseException) -> EvaluationError:
    reason = getattr(error, "strerror", None) or str(error)
    if isinstance(error, sqlite3.DatabaseError) and "not a database" in reason:
        hint = ("the file is damaged or is not an opspec result store; start the run again "
                "with another --out (the damaged file is left as it is)")
    elif isinstance(error, sqlite3.OperationalError) and "full" in reason:
        hint = ("free some space, then `opspec evaluate --resume --out "
                f"{path.parent}`: every replication stored so far is kept")
    else:
        hint = ("check that the output folder is writable and the disk has room; once it "
                "is, --resume continues a started run (--out DIR chooses another folder)")
    return EvaluationError(f"{path}: cannot {doing}: {reason}", hint=hint)


class ResultStore:
    """An open result store. Use as a context manager; every write commits at once."""

    def __init__(self, folder: str | Path, *, create: bool) -> None:
        self.folder = Path(folder)
        self.path = self.folder / FILENAME
        if create:
            try:
                self.folder.mkdir(parents=True, exist_ok=True)
            except OSError as error:
                raise _fail(self.folder, "create the output folder", error) from None
        elif not self.path.is_file():
            raise EvaluationError(f"{self.path}: no stored evaluation to resume",
                                  hint="run without --resume first, or give the --out folder "
                                  "of the run to finish")
        try:
            self._db = sqlite3.connect(self.path, timeout=30.0, isolation_level=None)
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=NORMAL")
            self._db.executescript(_SCHEMA)
        except sqlite3.Error as error:
            raise _fail(self.path, "open the result database", error) from None

    # ------------------------------------------------------------------ run parameters

    def put(self, key: str, value: Any) -> None:
        self._write(lambda db: db.execute(
            "INSERT OR REPLACE INTO run (key, value) VALUES (?, ?)", (key, json.dumps(value))),
            "store the run parameters")

    def get(self, key: str) -> Any:
        row = self._db.execute("SELECT value FROM run WHERE key = ?", (key,)).fetchone()
        return None if row is None else json.loads(row[0])

    # ------------------------------------------------------------------ replications

    def finished(self, design: str) -> set[int]:
        """Users of ``design`` whose replication is stored as done."""
        rows = self._db.execute(
            "SELECT user FROM replication WHERE design = ? AND status = 'done'", (design,))
        return {int(r[0]) for r in rows}

    def add(self, record: ReplicationRecord) -> None:
        """Store one replication (replacing an earlier failed attempt) in one transaction."""
        def write(db: sqlite3.Connection) -> None:
            key = (record.design, record.user)
            db.execute("BEGIN IMMEDIATE")
            try:
                for table in ("sample", "outcome", "activity", "monitor"):
                    db.execute(f"DELETE FROM {table} WHERE design = ? AND user = ?", key)
                db.execute("INSERT OR REPLACE INTO replication VALUES (?, ?, ?, ?, ?, ?)",
                           (*key, record.status, record.error,
                            json.dumps(record.metrics, allow_nan=True), record.wall_s))
                db.executemany("INSERT INTO sample VALUES (?, ?, ?, ?, ?)",
                               [(*key, m, v, t) for m, v, t in record.samples])
                db.executemany("INSERT INTO outcome VALUES (?, ?, ?, ?, ?, ?)",
                               [(*key, m, d, h, n) for (m, d, h), n in record.outcomes.items()])
                db.executemany("INSERT INTO activity VALUES (?, ?, ?, ?, ?, ?, ?)",
                               [(*key, a, *c) for a, c in record.activities.items()])
                db.executemany("INSERT INTO monitor VALUES (?, ?, ?, ?, ?, ?)",
                               [(*key, m, *v) for m, v in record.monitors.items()])
                db.execute("COMMIT")
            except BaseException:
                # SQLite may already have rolled back (disk full); keep the original error
                if db.in_transaction:
                    db.execute("ROLLBACK")
                raise

        self._write(write, f"store replication {record.design}/{record.user}")

    def failures(self) -> list[tuple[str, int, str]]:
        rows = self._db.execute("SELECT design, user, error FROM replication "
                                "WHERE status != 'done' ORDER BY design, user")
        return [(str(d), int(u), str(e)) for d, u, e in rows]

    def user_metrics(self, design: str) -> Iterator[tuple[int, dict[str, dict[str, Any]]]]:
        """(user, metrics) of every finished replication of ``design``, by user."""
        rows = self._db.execute("SELECT user, metrics FROM replication WHERE design = ? AND "
                                "status = 'done' ORDER BY user", (design,))
        for user, metrics in rows:
            yield int(user), json.loads(metrics)

    def query(self, sql: str, params: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        return list(self._db.execute(sql, params))

    # ------------------------------------------------------------------ plumbing

    def _write(self, action: Any, doing: str) -> None:
        try:
            action(self._db)
        except sqlite3.Error as error:
            raise _fail(self.path, doing, error) from None

    def close(self) -> None:
        try:
            self._db.close()
        except sqlite3.Error:
            pass

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
