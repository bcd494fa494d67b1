"""Each finished user's value of every metric, kept on disk rather than in memory, and read
back a batch at a time for each pass of the summaries and the report (for many users; up to
:data:`opspec.evaluation.values_per_user.HELD_USERS` they are held in memory, where spilling saves
nothing: ``values_per_user.per_user_values`` and :func:`held_activities`).

The summaries need every user's ``(y, n)`` pair of every metric (sums over users, the
cluster-robust variance, the users with any) and percentiles of the users' own values. Held
in arrays they took 16 bytes per user and metric in the evaluate process, the per-activity
rates 24 per user and activity, and each pass made sorted copies: memory that grew with the
number of users (about 10 MiB from 10,000 to 100,000 users of the dispenser). Here they are
written once, in one streamed reading of the stored results, to temporary tables of the
result store's connection (SQLite keeps them in a temporary file behind a page cache of
fixed size, and drops them with the connection), and every pass reads them again in
batches: the memory is a batch's, whatever the number of users.

The numbers are those of the arrays bit for bit: the same doubles (SQLite stores a REAL as
the 8-byte IEEE value) read in the same order (user order; sorted values in ascending
order, as ``sorted`` gave them), and the statistics only iterate over them
(``math.fsum`` is exactly rounded, ``statistics.stdev`` exact, plain sums run in the same
order as before). A percentile reads its two order statistics through an index on the
value. A NaN, which SQLite cannot store as a number, is left to the in-memory arrays
(:func:`opspec.evaluation.values_per_user.user_values`), whose results it already was.
"""

from __future__ import annotations

import itertools
import weakref
from array import array
from collections.abc import Iterator, Mapping, Sequence
from typing import Any

from opspec.evaluation.store import ResultStore

__all__ = ["Column", "SpilledPairs", "SpilledUsers", "spill_activities", "spill_user_values"]

#: Rows read per batch (a few hundred kB of row tuples at most).
BATCH = 4096
#: Users whose values are written at once (their row tuples: about 0.4 MB).
FLUSH = 512


class Column(Sequence[Any]):
    """The rows of one fixed read of a temporary table (one value per row, or a tuple of
    several), read again at each pass; ``len`` is known beforehand. Indexing reads the
    ``index``-th row (through the table's order: its rowid, or an index on the sorted
    value)."""

    __slots__ = ("_length", "_select", "_single", "_store")

    def __init__(self, store: ResultStore, select: str, length: int, *,
                 single: bool = True) -> None:
        self._store, self._select, self._length, self._single = store, select, length, single

    def __len__(self) -> int:
        return self._length

    def __iter__(self) -> Iterator[Any]:
        # a batch's values made at once, then handed out by chain (C): no Python step per
        # row between SQLite and the statistic's own loop (a 100,000-user summary reads
        # about 18 million rows so)
        batches = self._store.batches(self._select, batch=BATCH)
        if self._single:
            return itertools.chain.from_iterable([row[0] for row in rows] for rows in batches)
        return itertools.chain.from_iterable(batches)

    def __getitem__(self, index: Any) -> Any:
        if isinstance(index, slice):
            return list(itertools.islice(iter(self), *index.indices(self._length)))
        if index < 0:
            index += self._length
        if not 0 <= index < self._length:
            raise IndexError(index)
        row = self._store.query(f"{self._select} LIMIT 1 OFFSET ?", (index,))[0]
        return row[0] if self._single else tuple(row)


class SpilledPairs(Column):
    """``(y, n)`` pairs over users (a read of two columns), in the stored order."""

    def __init__(self, store: ResultStore, select: str, length: int) -> None:
        super().__init__(store, select, length, single=False)


class _Tables:
    """Names of this store's temporary tables, made one after another."""

    counter = itertools.count(1)

    @classmethod
    def new(cls, store: ResultStore, columns: str) -> str:
        name = f"opspec_spill_{next(cls.counter)}"
        store.scratch(f"CREATE TEMP TABLE {name} ({columns})")
        return name


class SpilledUsers:
    """Per finished user of a design, the ``(y, n)`` pair of each metric read, in
    temporary tables (:func:`spill_user_values`)."""

    def __init__(self, store: ResultStore, tables: Mapping[str, str], users: int) -> None:
        self.store = store
        self.tables = dict(tables)
        #: how many users (rows per metric)
        self.users = users
        self._sorted: dict[tuple[str, str], Column] = {}

    def pairs(self, name: str) -> SpilledPairs:
        """``(y, n)`` of metric ``name`` per user, in user order."""
        return SpilledPairs(self.store, f"SELECT y, n FROM {self.tables[name]} ORDER BY rowid",
                            self.users)

    def where_denominator(self, name: str) -> Column:
        """``y`` of the users whose ``n`` is above 0, in user order."""
        table = self.tables[name]
        count = int(self.store.query(f"SELECT COUNT(*) FROM {table} WHERE n > 0")[0][0])
        return Column(self.store, f"SELECT y FROM {table} WHERE n > 0 ORDER BY rowid", count)

    def in_user_order(self, name: str) -> array[float]:
        """``y / n`` of metric ``name`` of the users whose ``n`` is above 0, in user order,
        as an array (one metric's values held at a time: what a figure of them needs)."""
        values = array("d")
        for rows in self.store.batches(
                f"SELECT v FROM {self.tables[name]} WHERE v IS NOT NULL ORDER BY rowid",
                batch=BATCH):
            values.extend([row[0] for row in rows])
        return values

    def sorted(self, name: str, column: str) -> Column:
        """Metric ``name``'s ``y`` (every user's: a count's totals) or ``v`` (``y / n`` of
        the users whose ``n`` is above 0: their mean duration, their ratio), ascending."""
        if column not in ("y", "v"):
            raise ValueError(column)
        found = self._sorted.get((name, column))
        if found is not None:
            return found
        table = self.tables[name]
        self.store.scratch(f"CREATE INDEX IF NOT EXISTS {table}_{column} ON {table} ({column})")
        where = " WHERE v IS NOT NULL" if column == "v" else ""
        count = int(self.store.query(f"SELECT COUNT(*) FROM {table}{where}")[0][0])
        found = self._sorted[(name, column)] = Column(
            self.store, f"SELECT {column} FROM {table}{where} ORDER BY {column}", count)
        return found


#: The spills of each open store, by (design, metric names, users filter): the summaries'
#: spill is read again by the report's per-user figure, not made twice.
_SPILLS: weakref.WeakKeyDictionary[ResultStore, dict[Any, SpilledUsers | None]] = (
    weakref.WeakKeyDictionary())


def spill_user_values(store: ResultStore, design: str,
                      definitions: Sequence[Mapping[str, Any]],
                      users: set[int] | None = None) -> SpilledUsers | None:
    """Per finished user of ``design`` (of ``users`` only, when given), the ``(y, n)`` pair
    of every metric in ``definitions`` (as :func:`opspec.evaluation.values_per_user.user_values`
    reads them), written to temporary tables in one streamed reading of the users' stored
    metrics. None when a value is NaN (the caller then holds them in arrays)."""
    from opspec.evaluation.summary import pair_reader

    # the store's writes are counted: a spill is of the results as they were
    key = (store.writes, design, tuple(d["name"] for d in definitions),
           None if users is None else frozenset(users))
    cache = _SPILLS.setdefault(store, {})
    if key in cache:
        return cache[key]
    tables = {d["name"]: _Tables.new(store, "y REAL NOT NULL, n REAL NOT NULL, v REAL")
              for d in definitions}
    read = pair_reader(definitions)
    order = [tables[d["name"]] for d in definitions]
    pending: list[list[tuple[float, float, float | None]]] = [[] for _ in order]
    count = 0
    nan = False

    def flush() -> None:
        for table, rows in zip(order, pending, strict=True):
            store.scratch_rows(f"INSERT INTO {table} VALUES (?, ?, ?)", rows)
            rows.clear()

    for user, metrics in store.user_metrics(design):
        if users is not None and user not in users:
            continue
        count += 1
        for rows, (y, n) in zip(pending, read(metrics), strict=True):
            v = y / n if n > 0 else None
            if y != y or n != n or v != v:
                nan = True
            rows.append((y, n, v))
        if count % FLUSH == 0:
            flush()
        if nan:
            break
    spilled: SpilledUsers | None = None
    if not nan:
        flush()
        spilled = SpilledUsers(store, tables, count)
    for rows in pending:
        rows.clear()
    if spilled is None:
        for table in order:
            store.scratch(f"DROP TABLE {table}")
    cache[key] = spilled
    return spilled


def spill_activities(store: ResultStore, design: str
                     ) -> list[tuple[str, int, SpilledPairs, SpilledPairs]]:
    """Per manual activity of ``design`` (in the order first stored) with offers:
    ``(activity, offered, (omitted, offered) per user, (wrong, offered) per user)``, the
    pairs in the stored order, from temporary tables written in one streamed reading of
    the activity table."""
    tables: dict[str, str] = {}
    pending: dict[str, list[tuple[int, int, int]]] = {}
    counts: dict[str, int] = {}

    def flush(activity: str) -> None:
        store.scratch_rows(f"INSERT INTO {tables[activity]} VALUES (?, ?, ?)",
                           pending[activity])
        pending[activity].clear()

    for activity, offered, omitted, wrong in store.rows(
            "SELECT activity, offered, omitted, wrong FROM activity WHERE design = ? "
            "ORDER BY rowid", (design,), batch=BATCH):
        name = str(activity)
        rows = pending.get(name)
        if rows is None:
            tables[name] = _Tables.new(store, "offered REAL, omitted REAL, wrong REAL")
            rows = pending[name] = []
            counts[name] = 0
        rows.append((int(offered or 0), int(omitted or 0), int(wrong or 0)))
        counts[name] += 1
        if len(rows) == BATCH:
            flush(name)
    out = []
    for name, table in tables.items():
        flush(name)
        offered = int(store.query(f"SELECT TOTAL(offered) FROM {table}")[0][0])
        if not offered:
            continue
        out.append((name, offered,
                    SpilledPairs(store, f"SELECT omitted, offered FROM {table} ORDER BY rowid",
                                 counts[name]),
                    SpilledPairs(store, f"SELECT wrong, offered FROM {table} ORDER BY rowid",
                                 counts[name])))
    return out


def held_activities(store: ResultStore, design: str
                    ) -> list[tuple[str, int, list[tuple[float, float]],
                                    list[tuple[float, float]]]]:
    """What :func:`spill_activities` gives, held in lists (for few users, where spilling
    saves no memory): per activity (in the order first stored) with offers, ``(activity,
    offered, (omitted, offered) per user, (wrong, offered) per user)``, each count the
    float its REAL column gives back."""
    rows: dict[str, list[tuple[int, int, int]]] = {}
    for activity, offered, omitted, wrong in store.rows(
            "SELECT activity, offered, omitted, wrong FROM activity WHERE design = ? "
            "ORDER BY rowid", (design,)):
        rows.setdefault(str(activity), []).append(
            (int(offered or 0), int(omitted or 0), int(wrong or 0)))
    out = []
    for name, counts in rows.items():
        offered = sum(given for given, _, _ in counts)   # whole numbers: exact in any order
        if offered:
            out.append((name, offered,
                        [(float(omitted), float(given)) for given, omitted, _ in counts],
                        [(float(wrong), float(given)) for given, _, wrong in counts]))
    return out
