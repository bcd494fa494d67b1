"""The result store: one SQLite database per evaluation, in its output folder.

WAL mode. Replications are stored in batches, one transaction for every chunk of users a
worker returns, committed as soon as the chunk is back (one transaction per replication
rewrote the same index pages for every user: 878 MB written for a 28 MB store of 1,000 users
x 30 days). The records of a chunk arrive together, so killing the run at any moment still
loses at most the replications in flight, and ``--resume`` runs only what is missing or
failed. A batch the disk has no room for is stored one replication per transaction up to the
one that does not fit, so a full disk keeps every replication there was room for. The index
of sample values by metric is built once the replications are stored (:meth:`ResultStore.index`,
called at the end of every run), not kept up to date during the run. The schema (a contract with the report code and with
anyone who opens ``results.sqlite`` in another tool):

- ``run(key, value)``: JSON values — ``plan`` (the EvaluationPlan, what ``--resume``
  re-runs), ``metrics`` (the metrics design A declares; ``metrics_B`` those of B), and for other readers the same parameters as
  separate keys: ``spec``, ``spec_sha256``, ``designs``, ``users``, ``days``, ``seed``,
  ``user_model``, ``user_model_sha256``, ``opspec_version``, ``started``;
- ``replication(design, user, status, error, metrics, wall_s)``: one row per user and design,
  ``metrics`` the user's declared metrics as JSON (the ``opspec run --json`` shape);
  ``status`` ``failed`` when the replication could not run or had a run-time fault or a
  deadlock (``error`` then starts ``fault:`` / ``deadlock:`` and names the first one's
  file:line; :mod:`opspec.evaluation.failures`); the tables below hold complete
  (``done``) replications only;
- ``sample(design, user, metric, value, time)``: every duration observation, ``time`` the
  simulated time it ended;
- ``outcome(design, user, metric, day, hour, n)``: count-metric events by day (0-based) and
  hour of day;
- ``activity(design, user, activity, offered, completed, omitted, wrong)``: the user lane's
  manual activities;
- ``monitor(design, user, monitor, violations, first_time, first_message)``: one row per
  monitor the spec declares (``opspec:Monitor``) and user, also when there were none.
- ``person(design, user, subgroup)`` and ``person_parameter(design, user, parameter,
  value)``: who each user is when the user model is a population (docs/user-models.md):
  their subgroup (NULL without subgroups) and each parameter drawn for them (dotted path);
  no rows for a model without variation.
"""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Callable, Iterator, Sequence
from itertools import chain, groupby
from pathlib import Path
from typing import Any, Self

import numpy as np

from opspec.errors import EvaluationError
from opspec.evaluation.columns import (
    Columns,
    columns_of_outcomes,
    columns_of_samples,
)
from opspec.evaluation.replication import ReplicationRecord
from opspec.evaluation.sample_index import IndexBeside, reads_samples

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
CREATE TABLE IF NOT EXISTS outcome (
    design TEXT NOT NULL, user INTEGER NOT NULL, metric TEXT NOT NULL, day INTEGER NOT NULL,
    hour INTEGER NOT NULL, n INTEGER NOT NULL);
CREATE TABLE IF NOT EXISTS activity (
    design TEXT NOT NULL, user INTEGER NOT NULL, activity TEXT NOT NULL, offered INTEGER,
    completed INTEGER, omitted INTEGER, wrong INTEGER);
CREATE INDEX IF NOT EXISTS activity_by_user ON activity (design, user);
CREATE TABLE IF NOT EXISTS monitor (
    design TEXT NOT NULL, user INTEGER NOT NULL, monitor TEXT NOT NULL,
    violations INTEGER NOT NULL, first_time REAL, first_message TEXT);
CREATE INDEX IF NOT EXISTS monitor_by_user ON monitor (design, user);
CREATE TABLE IF NOT EXISTS person (
    design TEXT NOT NULL, user INTEGER NOT NULL, subgroup TEXT);
CREATE INDEX IF NOT EXISTS person_by_user ON person (design, user);
CREATE TABLE IF NOT EXISTS person_parameter (
    design TEXT NOT NULL, user INTEGER NOT NULL, parameter TEXT NOT NULL, value REAL NOT NULL);
CREATE INDEX IF NOT EXISTS person_parameter_by_user ON person_parameter (design, user);
"""

# Built once the replications are stored (:meth:`ResultStore.index`): kept up to date during
# the run, this index of values in random order rewrote most of its pages in every batch (143
# MB written instead of 62 MB for 1,000 users x 30 days).
_SAMPLE_INDEX = "CREATE INDEX IF NOT EXISTS sample_by_metric ON sample (design, metric, value)"

# The two largest tables' rows by user (a user-month of the dispenser is 120 samples and 360
# outcome rows), for --resume, which replaces failed users' rows through them: never built by
# a fresh run (no user of it has earlier rows to replace; kept during the run they cost a
# third of the store's time, built at its end a quarter), built when a store with
# replications is opened again, whether the run before it finished or was killed.
_USER_INDEXES = """
CREATE INDEX IF NOT EXISTS sample_by_user ON sample (design, user);
CREATE INDEX IF NOT EXISTS outcome_by_user ON outcome (design, user);
"""

FILENAME = "results.sqlite"

# Rows per INSERT statement: a statement's step and reset are paid once per hundred rows
# rather than per row (the outcome table's 0.36 million rows of 1,000 users x 30 days went in
# 40 % faster); 100 rows of at most 7 columns stay under the 999 parameters of old SQLites.
_ROWS_PER_INSERT = 100


def _insert(db: sqlite3.Connection, table: str, rows: Sequence[tuple[Any, ...]]) -> None:
    """Append ``rows`` (all of one width) to ``table`` in their order (so in rowid order)."""
    if not rows:
        return
    one = "(" + ", ".join("?" * len(rows[0])) + ")"
    full = len(rows) - len(rows) % _ROWS_PER_INSERT
    if full:
        db.executemany(f"INSERT INTO {table} VALUES " + ", ".join([one] * _ROWS_PER_INSERT),
                       (list(chain.from_iterable(rows[i:i + _ROWS_PER_INSERT]))
                        for i in range(0, full, _ROWS_PER_INSERT)))
    if full < len(rows):
        db.executemany(f"INSERT INTO {table} VALUES {one}", rows[full:])


#: the statements of :func:`_insert_runs`, by (table, values per row, rows)
_RUN_SQL: dict[tuple[str, int, int], str] = {}


def _run_sql(table: str, width: int, rows: int) -> str:
    """``INSERT INTO table VALUES (?1, ?2, ?3, ?4, …), (?1, ?2, ?3, …), …``: ``rows`` rows
    sharing their first three values (bound once), ``width`` of their own each."""
    key = (table, width, rows)
    sql = _RUN_SQL.get(key)
    if sql is None:
        own = iter(range(4, 4 + width * rows))
        sql = _RUN_SQL[key] = f"INSERT INTO {table} VALUES " + ", ".join(
            "(?1, ?2, ?3, " + ", ".join(f"?{next(own)}" for _ in range(width)) + ")"
            for _ in range(rows))
    return sql


def _insert_runs(db: sqlite3.Connection, table: str, design: str, users: Sequence[int],
                 tables: Sequence[Columns], width: int) -> None:
    """Append the rows ``(design, users[i], metric, *values)`` of ``tables`` to ``table``
    in their order, each run of rows of one user and metric (a replication's rows come
    metric after metric) in statements that bind the design, the user and the metric once
    (numbered parameters): binding a text costs SQLite a copy, and these two texts were
    two of a row's five or six values, about 0.8 M instructions per user-month of the
    dispenser. The same rows, values and SQLite types as one statement per row."""
    for user, rows in zip(users, tables, strict=True):
        if not len(rows):
            continue
        which = rows.which
        cuts = (np.flatnonzero(which[1:] != which[:-1]) + 1).tolist()
        data = rows.data
        names = rows.metrics
        for start, end in zip([0, *cuts], [*cuts, len(which)], strict=True):
            shared = [design, user, names[int(which[start])]]
            while start < end:
                stop = min(end, start + _ROWS_PER_INSERT)
                db.execute(_run_sql(table, width, stop - start),
                           shared + data[start:stop].ravel().tolist())
                start = stop


def _sample_columns(record: ReplicationRecord) -> Columns:
    """A record's sample rows as columns: those given as tuples, then its columns."""
    return _joined(columns_of_samples(record.samples) if record.samples else None,
                   record.sample_columns)


def _outcome_columns(record: ReplicationRecord) -> Columns:
    """A record's outcome rows as columns: those given as a mapping, then its columns."""
    return _joined(columns_of_outcomes(record.outcomes) if record.outcomes else None,
                   record.outcome_columns)


def _joined(given: Columns | None, made: Columns | None) -> Columns:
    if given is None or made is None:
        found = given if given is not None else made
        return found if found is not None else _EMPTY
    names = given.metrics + made.metrics
    return Columns(names, np.concatenate((given.which, made.which + len(given.metrics))),
                   np.concatenate((given.data, made.data)))


_EMPTY = Columns((), np.zeros(0, dtype=np.int64), np.zeros((0, 0)))


class _RunningSums:
    """One design's outcome rows summed over users by (metric, day, hour), and Σ over users
    of (the user's count on a day)² by (metric, day), kept as each chunk is stored: numpy
    arrays indexed by metric (in the order first stored), day and hour, grown as needed."""

    def __init__(self) -> None:
        self.metrics: dict[str, int] = {}
        self.counts = np.zeros((0, 0, 24), dtype=np.int64)
        self.squares = np.zeros((0, 0), dtype=np.int64)

    def add(self, tables: Sequence[Columns]) -> None:
        """Add the outcome rows of users stored together (``tables[i]``: user i's)."""
        tables = [t for t in tables if len(t)]
        if not tables:
            return
        metric = np.concatenate([np.asarray([self.metrics.setdefault(m, len(self.metrics))
                                             for m in t.metrics], dtype=np.int64)[t.which]
                                 for t in tables])
        user = np.repeat(np.arange(len(tables)), [len(t) for t in tables])
        data = np.concatenate([t.data for t in tables])
        day, hour, n = data[:, 0], data[:, 1], data[:, 2]
        self._grow(len(self.metrics), int(day.max()) + 1)
        np.add.at(self.counts, (metric, day, hour), n)
        # each user's count of a metric on a day, squared
        days = self.counts.shape[1]
        key = (user * len(self.metrics) + metric) * days + day
        unique, inverse = np.unique(key, return_inverse=True)
        totals = np.bincount(inverse.ravel(), weights=n).astype(np.int64)
        at = unique % (len(self.metrics) * days)
        np.add.at(self.squares, (at // days, at % days), totals * totals)

    def _grow(self, metrics: int, days: int) -> None:
        have_m, have_d = self.squares.shape
        if metrics <= have_m and days <= have_d:
            return
        m, d = max(metrics, have_m), max(days, have_d)
        counts = np.zeros((m, d, 24), dtype=np.int64)
        counts[:have_m, :have_d] = self.counts
        squares = np.zeros((m, d), dtype=np.int64)
        squares[:have_m, :have_d] = self.squares
        self.counts, self.squares = counts, squares

    def sums(self) -> list[tuple[str, int, int, int]]:
        names = list(self.metrics)
        return [(names[m], d, h, int(self.counts[m, d, h]))
                for m, d, h in zip(*(i.tolist() for i in np.nonzero(self.counts)),
                                   strict=True)]

    def day_squares(self) -> list[tuple[str, int, int]]:
        names = list(self.metrics)
        return [(names[m], d, int(self.squares[m, d]))
                for m, d in zip(*(i.tolist() for i in np.nonzero(self.squares)), strict=True)]


def _in_transaction(db: sqlite3.Connection, sql: str, rows: Sequence[tuple[Any, ...]]
                    ) -> None:
    db.execute("BEGIN")
    try:
        db.executemany(sql, rows)
        db.execute("COMMIT")
    except BaseException:
        if db.in_transaction:
            db.execute("ROLLBACK")
        raise


def _full(error: BaseException) -> bool:
    """Whether ``error`` says the disk (or the database's size limit) is full."""
    return isinstance(error, sqlite3.OperationalError) and "full" in str(error)


def _fail(path: Path, doing: str, error: BaseException, *,
          started: bool = True) -> EvaluationError:
    """The error of a store that cannot be written (``started``: a run may already be in it,
    which ``--resume`` continues; not so when its folder cannot even be made)."""
    reason = getattr(error, "strerror", None) or str(error)
    if not started:
        hint = ("check that the folder's parent exists and is writable, or choose another "
                "folder with --out DIR")
    elif isinstance(error, sqlite3.DatabaseError) and "not a database" in reason:
        hint = ("the file is damaged or is not an opspec result store; start the run again "
                "with another --out (the damaged file is left as it is)")
    elif _full(error):
        hint = ("free some space, then `opspec evaluate --resume --out "
                f"{path.parent}`: every replication stored so far is kept")
    else:
        hint = ("check that the output folder is writable and the disk has room; once it "
                "is, --resume continues a started run (--out DIR chooses another folder)")
    return EvaluationError(f"{path}: cannot {doing}: {reason}", hint=hint)


def _claim(path: Path) -> None:
    """Create ``path`` empty (an empty file is an empty SQLite database), failing if it
    exists: the one step that decides which of two runs started together gets the folder."""
    import os

    try:
        os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
    except FileExistsError:
        raise EvaluationError(f"{path.parent} already holds an evaluation",
                              hint="add --resume to finish it, or choose another --out"
                              ) from None
    except OSError as error:
        raise _fail(path, "create the result store", error, started=False) from None


class ResultStore:
    """An open result store. Use as a context manager; every write commits at once."""

    def __init__(self, folder: str | Path, *, create: bool, new: bool = False) -> None:
        """``create``: make the folder and the database when missing; ``new`` too: the
        database must not exist yet, decided in one step (two runs started into one folder
        at the same moment: one of them is refused, never both let in)."""
        self.folder = Path(folder)
        self.path = self.folder / FILENAME
        if create:
            try:
                self.folder.mkdir(parents=True, exist_ok=True)
            except OSError as error:
                raise _fail(self.folder, "create the output folder", error,
                            started=False) from None
            if new:
                _claim(self.path)
        elif not self.path.is_file():
            raise EvaluationError(f"{self.path}: no stored evaluation to resume",
                                  hint="run without --resume first, or give the --out folder "
                                  "of the run to finish")
        #: replications stored through this object so far (readers that keep what they
        #: read, :mod:`opspec.evaluation.spilled`, know when it is out of date)
        self.writes = 0
        #: the sample index being built beside (:meth:`index`), until it is waited for
        self._indexing: IndexBeside | None = None
        try:
            # (room for _insert_runs's statements, one per table and length of a run,
            # beside the others: a statement prepared again costs more than its rows)
            self._db = sqlite3.connect(self.path, timeout=30.0, isolation_level=None,
                                       cached_statements=512)
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=NORMAL")
            self._db.executescript(_SCHEMA)
            #: a store with results already (a resumed run): any stored user's rows may be
            #: replaced, so every stored user is deleted first, through the user indexes
            self._had_results = any(
                self._db.execute(f"SELECT 1 FROM {table} LIMIT 1").fetchone() is not None
                for table in ("replication", "sample", "outcome"))
            if self._had_results:
                self._db.executescript(_USER_INDEXES)
            #: per design, the outcome rows summed over users by (metric, day, hour), kept
            #: while a fresh store stores: what the report's counts-over-time figures read,
            #: without a pass over the largest table. None once any user's earlier rows
            #: were replaced (or the store had results when opened): then read from the table.
            #: With them, Σ over users of (the user's count on a day)², by (metric, day):
            #: the day-by-day figures' intervals, without that pass either.
            self._outcome_sums: dict[str, _RunningSums] | None = (
                None if self._had_results else {})
        except sqlite3.Error as error:
            raise _fail(self.path, "open the result database", error) from None

    # ------------------------------------------------------------------ run parameters

    def put(self, key: str, value: Any) -> None:
        self._write(lambda db: db.execute(
            "INSERT OR REPLACE INTO run (key, value) VALUES (?, ?)", (key, json.dumps(value))),
            "store the run parameters")

    def get(self, key: str) -> Any:
        rows = self.query("SELECT value FROM run WHERE key = ?", (key,))
        return None if not rows else json.loads(rows[0][0])

    # ------------------------------------------------------------------ replications

    def finished(self, design: str) -> set[int]:
        """Users of ``design`` whose replication is stored as done."""
        # done with an error: a run-time fault stored as done before faults failed a
        # replication; --resume runs it again rather than accept it
        rows = self.query("SELECT user FROM replication WHERE design = ? AND status = 'done' "
                          "AND error IS NULL", (design,))
        return {int(r[0]) for r in rows}

    def add(self, record: ReplicationRecord) -> None:
        """Store one replication (replacing an earlier failed attempt) in one transaction."""
        self.add_many([record])

    def add_many(self, records: Sequence[ReplicationRecord]) -> None:
        """Store replications (each replacing an earlier failed attempt) in one transaction;
        when the disk is full, one per transaction up to the first that does not fit, then
        the error (an EvaluationError with the resume hint)."""
        queue = list(records)
        if not queue:
            return
        self._index_built()
        try:
            self._transaction(queue)
            return
        except sqlite3.Error as error:
            if not _full(error) or len(queue) == 1:
                first = queue[0]
                raise _fail(self.path, f"store replication {first.design}/{first.user}"
                            + (f" and {len(queue) - 1} more" if len(queue) > 1 else ""),
                            error) from None
        for record in queue:            # full: keep every replication there is room for
            try:
                self._transaction([record])
            except sqlite3.Error as error:
                raise _fail(self.path, f"store replication {record.design}/{record.user}",
                            error) from None

    def _transaction(self, records: Sequence[ReplicationRecord]) -> None:
        db = self._db
        keys = [(r.design, r.user) for r in records]
        self.writes += 1
        db.execute("BEGIN IMMEDIATE")
        try:
            # an earlier attempt's rows (a failed replication) are replaced whole. In a store
            # that was empty when opened, only a user stored earlier in this run can have rows
            # (found by the replication's primary key); in one opened with results, any can.
            again = keys if self._had_results else [key for key in keys if db.execute(
                "SELECT 1 FROM replication WHERE design = ? AND user = ?", key).fetchone()]
            for table in ("sample", "outcome", "activity", "monitor", "person",
                          "person_parameter") if again else ():
                db.executemany(f"DELETE FROM {table} WHERE design = ? AND user = ?", again)
            db.executemany("INSERT OR REPLACE INTO replication VALUES (?, ?, ?, ?, ?, ?)",
                           [(r.design, r.user, r.status, r.error,
                             json.dumps(r.metrics, allow_nan=True), r.wall_s)
                            for r in records])
            # a failed replication keeps its metrics (its replication row) and nothing
            # else: every reader of the other tables reads complete replications only
            complete = [r for r in records if r.status == "done"]
            # runs of records of one design (a chunk is one design), in their order: the
            # rows as columns, flattened by numpy (opspec.evaluation.columns)
            groups = [(design, list(group))
                      for design, group in groupby(complete, key=lambda r: r.design)]
            counted = [[_outcome_columns(r) for r in group] for _, group in groups]
            for (design, group), outcomes in zip(groups, counted, strict=True):
                users = [r.user for r in group]
                _insert_runs(db, "sample", design, users, [_sample_columns(r) for r in group],
                             2)
                _insert_runs(db, "outcome", design, users, outcomes, 3)
            _insert(db, "activity", [(r.design, r.user, a, *c) for r in complete
                                     for a, c in r.activities.items()])
            _insert(db, "monitor", [(r.design, r.user, m, *v) for r in complete
                                    for m, v in r.monitors.items()])
            people = [r for r in complete if r.person is not None]    # a population's users
            _insert(db, "person", [(r.design, r.user, r.person[0]) for r in people
                                   if r.person])
            _insert(db, "person_parameter", [(r.design, r.user, n, v) for r in people
                                             if r.person for n, v in r.person[1].items()])
            db.execute("COMMIT")
        except BaseException:
            # SQLite may already have rolled back (disk full); keep the original error
            if db.in_transaction:
                db.execute("ROLLBACK")
            raise
        if again:
            self._outcome_sums = None
        elif self._outcome_sums is not None:
            for (design, _group), outcomes in zip(groups, counted, strict=True):
                self._outcome_sums.setdefault(design, _RunningSums()).add(outcomes)

    def index(self, *, beside: bool = False) -> None:
        """Build the index readers need that is not kept during the run (the sample values
        by metric: quantiles, histograms); nothing to do when it exists.

        ``beside`` (``opspec evaluate --workers W``, W > 1): build it on a thread of its own
        and return at once. Every later read of the sample table, and every write, waits
        for it first, and the error that stopped it (a full disk) is raised there, as this
        method raises it otherwise; so whatever reads the samples reads them indexed, as
        with one worker, and the results are the same."""
        self._index_built()
        if beside:
            try:
                self._indexing = IndexBeside(self.path, _SAMPLE_INDEX)
                return
            except sqlite3.Error as error:
                raise _fail(self.path, "index the stored results", error) from None
            except RuntimeError:
                pass                        # no thread to be had: built here, as with one
        self._write(lambda db: db.execute(_SAMPLE_INDEX), "index the stored results")

    def _index_built(self) -> None:
        """Wait for the index being built beside, if any; its failure as an EvaluationError."""
        indexing = self._indexing
        if indexing is None:
            return
        error = indexing.wait()         # a Ctrl-C meanwhile leaves it to __exit__ to stop
        self._indexing = None
        if error is not None:
            raise _fail(self.path, "index the stored results", error) from None

    def outcome_sums(self, design: str) -> list[tuple[str, int, int, int]]:
        """``(metric, day, hour, n)``: the outcome rows of ``design`` summed over users, from
        the running sums of this store's writes when they are all there is, else from the
        table."""
        if self._outcome_sums is not None:
            sums = self._outcome_sums.get(design)
            return sums.sums() if sums is not None else []
        return [(str(m), int(d), int(h), int(n)) for m, d, h, n in self.query(
            "SELECT metric, day, hour, SUM(n) FROM outcome WHERE design = ? "
            "GROUP BY metric, day, hour", (design,))]

    def outcome_day_squares(self, design: str) -> list[tuple[str, int, int]]:
        """``(metric, day, Σ_u n_u²)``: each user's count of a metric on a day, squared and
        summed over users (with :meth:`outcome_sums`, the day's mean and its variance over
        users), kept while storing like the sums, else from the table."""
        if self._outcome_sums is not None:
            sums = self._outcome_sums.get(design)
            return sums.day_squares() if sums is not None else []
        return [(str(m), int(d), int(q)) for m, d, q in self.query(
            "SELECT metric, day, SUM(t * t) FROM (SELECT metric, day, user, SUM(n) AS t "
            "FROM outcome WHERE design = ? GROUP BY metric, day, user) GROUP BY metric, day",
            (design,))]

    def failures(self) -> list[tuple[str, int, str]]:
        """``(design, user, error)`` of every failed replication (also one stored as done
        with an error by an older opspec: a run-time fault), by design and user."""
        rows = self.query("SELECT design, user, error FROM replication "
                          "WHERE status != 'done' OR error IS NOT NULL ORDER BY design, user")
        return [(str(d), int(u), str(e)) for d, u, e in rows]

    def user_metrics(self, design: str) -> Iterator[tuple[int, dict[str, dict[str, Any]]]]:
        """(user, metrics) of every complete replication of ``design``, by user."""
        for user, metrics in self.rows("SELECT user, metrics FROM replication WHERE design = ? "
                                       "AND status = 'done' AND error IS NULL ORDER BY user",
                                       (design,)):
            yield int(user), json.loads(metrics)

    def query(self, sql: str, params: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        """Rows of a read. A failure, such as a disk too full for SQLite's temporary files, is
        an EvaluationError with the resume hint."""
        if self._indexing is not None and reads_samples(sql):
            self._index_built()
        try:
            return list(self._db.execute(sql, params))
        except sqlite3.Error as error:
            raise _fail(self.path, "read the stored results", error) from None

    def rows(self, sql: str, params: tuple[Any, ...] = (), batch: int = 1000
             ) -> Iterator[tuple[Any, ...]]:
        """Rows of a read, streamed a batch at a time (the memory of one batch, whatever the
        number of users); a failure is an EvaluationError as with :meth:`query`."""
        return chain.from_iterable(self.batches(sql, params, batch))

    def batches(self, sql: str, params: tuple[Any, ...] = (), batch: int = 1000
                ) -> Iterator[list[tuple[Any, ...]]]:
        """The rows of a read in lists of ``batch`` rows (the last one shorter), as
        :meth:`rows` streams them: a pass over many users' values (the summaries read each
        metric several times) steps through Python once per batch, not once per row."""
        if self._indexing is not None and reads_samples(sql):
            self._index_built()
        try:
            cursor = self._db.execute(sql, params)
            while chunk := cursor.fetchmany(batch):
                yield chunk
        except sqlite3.Error as error:
            raise _fail(self.path, "read the stored results", error) from None

    # ------------------------------------------------------------------ scratch tables

    def scratch(self, sql: str) -> None:
        """Run one statement on this connection's temporary tables (``CREATE TEMP TABLE``,
        an index, ``DROP``): scratch space of the readers (:mod:`opspec.evaluation.spilled`),
        in a temporary file SQLite deletes with the connection; the store is not changed."""
        self._write(lambda db: db.execute(sql), "write a temporary table", temporary=True)

    def scratch_rows(self, sql: str, rows: Sequence[tuple[Any, ...]]) -> None:
        """Insert ``rows`` into a temporary table with ``sql`` (one transaction)."""
        if rows:
            self._write(lambda db: _in_transaction(db, sql, rows), "write a temporary table",
                        temporary=True)

    # ------------------------------------------------------------------ plumbing

    def _write(self, action: Callable[[sqlite3.Connection], Any], doing: str, *,
               temporary: bool = False) -> None:
        """``action`` on the database; ``temporary``: on this connection's temporary
        tables alone, which lock nothing another connection writes (the index being built
        beside is not waited for)."""
        if not temporary:
            self._index_built()
        try:
            action(self._db)
        except sqlite3.Error as error:
            raise _fail(self.path, doing, error) from None

    def close(self) -> None:
        """Close the database, once the index being built beside is there (its failure
        raised, as at any write)."""
        try:
            self._index_built()
        finally:
            try:
                self._db.close()
            except sqlite3.Error:
                pass

    def __enter__(self) -> Self:
        return self

    def __exit__(self, kind: type[BaseException] | None, *exc: object) -> None:
        if kind is not None and self._indexing is not None:
            # the run is stopping (Ctrl-C, an error): not the time to finish an index
            indexing, self._indexing = self._indexing, None
            indexing.stop()
        self.close()
