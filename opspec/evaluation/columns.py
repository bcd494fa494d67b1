"""A replication's sample and outcome rows column by column (numpy arrays), as a worker
makes them, sends them and the store writes them.

A user-month of the dispenser is about 120 ``sample`` rows and 360 ``outcome`` rows. Made,
pickled, unpickled, summed and stored as a Python tuple per row, they cost the evaluate
process about 0.6 CPU-s per 1,000 user-months beside SQLite's own work (a ``Counter`` of
``(metric, day, hour)`` keys, the pickles, a tuple per row, the running sums a dictionary
update per row). As columns, the same rows are a few arrays per replication: counted,
converted to SQLite's parameters and summed by numpy's loops.

The rows are the same as before, in the same order, with the same Python types: an
``outcome`` row's day and hour are ``int(t // DAY)`` and ``int((t % DAY) // 3600)`` of the
event's time ``t`` (numpy's ``floor_divide`` and ``remainder`` follow Python's float
``//`` and ``%``), in the order each ``(day, hour)`` of a metric was first seen (that of the
``Counter`` they replace), metrics in the order the run counted them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from itertools import chain
from typing import Any

import numpy as np

__all__ = [
    "DAY",
    "Columns",
    "columns_of_outcomes",
    "columns_of_samples",
    "object_rows",
    "outcome_columns",
    "sample_columns",
]

DAY = 86_400.0


@dataclass(frozen=True, slots=True)
class Columns:
    """Rows of one table for one replication: row ``i`` is ``(metrics[which[i]],
    *data[i])``; ``data`` holds int64 (outcome: day, hour, n) or float64 (sample: value,
    time) columns. Plain data: crosses process boundaries as a few arrays."""

    metrics: tuple[str, ...]
    which: np.ndarray       # int64, one per row: the metric's index in ``metrics``
    data: np.ndarray        # (rows, columns)

    def __len__(self) -> int:
        return int(self.which.shape[0])

    def rows(self) -> list[tuple[Any, ...]]:
        """The rows as tuples of Python values (``(metric, *columns)``)."""
        names = self.metrics
        return [(names[m], *values) for m, values in zip(self.which.tolist(),
                                                          self.data.tolist(), strict=True)]


def _flat(groups: Iterable[Sequence[float]], total: int) -> np.ndarray:
    return np.fromiter(chain.from_iterable(groups), dtype=np.float64, count=total)


def outcome_columns(count_times: Mapping[str, Sequence[float]]) -> Columns:
    """The ``outcome`` rows of a run's count-metric event times: per metric (in the
    mapping's order) each ``(day, hour)`` its events fell in, with their number, in the
    order first seen."""
    names = tuple(count_times)
    lengths = [len(times) for times in count_times.values()]
    total = sum(lengths)
    if not total:
        return Columns(names, np.zeros(0, dtype=np.int64), np.zeros((0, 3), dtype=np.int64))
    t = _flat(count_times.values(), total)
    which = np.repeat(np.arange(len(names), dtype=np.int64), lengths)
    day = np.floor_divide(t, DAY).astype(np.int64)
    hour = np.floor_divide(np.remainder(t, DAY), 3600.0).astype(np.int64)
    # one key per (metric, day, hour); counted, then put back in the order first seen
    days = int(day.max()) + 1
    key = (which * days + day) * 24 + hour
    step = key[1:] != key[:-1]
    if not (key[1:] < key[:-1]).any():
        # keys in order (a run's times are: the clock never goes back): each key's events
        # are one stretch, first seen where it starts, so no sort is needed
        first = np.flatnonzero(np.concatenate(([True], step)))
        counts = np.diff(np.append(first, len(key)))
        data = np.column_stack((day[first], hour[first], counts.astype(np.int64)))
        return Columns(names, which[first], data)
    unique, first, counts = np.unique(key, return_index=True, return_counts=True)
    order = np.argsort(first, kind="stable")
    unique, first, counts = unique[order], first[order], counts[order]
    data = np.column_stack((day[first], hour[first], counts.astype(np.int64)))
    return Columns(names, which[first], data)


def sample_columns(samples: Mapping[str, Sequence[float]],
                   times: Mapping[str, Sequence[float]]) -> Columns:
    """The ``sample`` rows of a run's duration observations: per metric (in the mapping's
    order) each value with the time it ended. A metric's values and times must pair up."""
    names = tuple(samples)
    ends = [times.get(name, ()) for name in names]
    lengths = [len(values) for values in samples.values()]
    for name, values, at in zip(names, samples.values(), ends, strict=True):
        if len(values) != len(at):
            raise ValueError(f"metric {name!r}: {len(values)} observations, {len(at)} times")
    total = sum(lengths)
    which = np.repeat(np.arange(len(names), dtype=np.int64), lengths)
    data = np.column_stack((_flat(samples.values(), total), _flat(ends, total)))
    return Columns(names, which, data.reshape(total, 2))


def _columns(rows: Sequence[tuple[Any, ...]], width: int, dtype: Any) -> Columns:
    """Rows ``(metric, *values)`` given as tuples (a record built by hand) as columns."""
    index: dict[str, int] = {}
    which = np.fromiter((index.setdefault(r[0], len(index)) for r in rows), dtype=np.int64,
                        count=len(rows))
    data = np.array([r[1:] for r in rows], dtype=dtype).reshape(len(rows), width)
    return Columns(tuple(index), which, data)


def columns_of_outcomes(outcomes: Mapping[tuple[str, int, int], int]) -> Columns:
    """``{(metric, day, hour): n}`` as columns (the rows in the mapping's order)."""
    return _columns([(m, d, h, n) for (m, d, h), n in outcomes.items()], 3, np.int64)


def columns_of_samples(samples: Sequence[tuple[str, float, float]]) -> Columns:
    """``[(metric, value, time)]`` as columns (the rows in their order)."""
    return _columns(samples, 2, np.float64)


def object_rows(design: str, users: Sequence[int], tables: Sequence[Columns], columns: int
                ) -> list[Any]:
    """The rows ``(design, user, metric, *columns)`` of ``tables`` (``tables[i]`` the rows
    of user ``users[i]``, ``columns`` values each beside the metric), flattened into one
    list of Python values (ints, floats, str), row after row: what SQLite binds. numpy's
    casts make the Python values (an int64 is an ``int``, a float64 the same ``float``), so
    no tuple is made per row."""
    sizes = [len(table) for table in tables]
    total = sum(sizes)
    if not total:
        return []
    out = np.empty((total, 3 + columns), dtype=object)
    out[:, 0] = design
    out[:, 1] = np.repeat(np.asarray(users, dtype=np.int64), sizes).astype(object)
    out[:, 2] = np.concatenate([np.asarray(table.metrics, dtype=object)[table.which]
                                for table in tables if len(table)])
    out[:, 3:] = np.concatenate([table.data for table in tables if len(table)]).astype(object)
    return out.ravel().tolist()
