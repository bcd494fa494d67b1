"""Each finished user's values of a design's metrics, as the summaries read them: one
``(y, n)`` pair per user and metric (a count ``(total, 1)``, a duration ``(sum, number)``, a
ratio ``(numerator, denominator)``), read in one streamed pass over the users' stored
metrics and held in arrays of doubles (:class:`Pairs`, 16 bytes per user and metric), or
for more than :data:`HELD_USERS` users written to disk and read back at each pass
(:mod:`.spilled`).
"""

from __future__ import annotations

import weakref
from array import array
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from opspec.evaluation.store import ResultStore

__all__ = ["HELD_USERS", "Pairs", "UserValues", "held_in_memory", "pair_reader",
           "per_user_values", "user_pairs", "user_pairs_by_metric", "user_values"]


def _scalar_pair(metric: Mapping[str, Any] | None) -> tuple[float, float]:
    """(y, n) of one user's value of a count or duration metric."""
    if not metric:
        return 0.0, 0.0
    if metric.get("kind") == "count":
        return float(metric.get("total") or 0), 1.0
    if metric.get("kind") == "duration":
        n = float(metric.get("n") or 0)
        mean = metric.get("mean")
        return (float(mean) * n if mean is not None else 0.0), n
    value = metric.get("value")
    return (float(value), 1.0) if value is not None else (0.0, 0.0)



class Pairs(Sequence[tuple[float, float]]):
    """The ``(y, n)`` pairs of one metric over users, held as two arrays of doubles (16 bytes
    per user, where a list of tuples takes about 120): a sequence of pairs to the statistics,
    which only iterate over it and take its length."""

    __slots__ = ("n", "y")

    def __init__(self, y: array[float] | None = None, n: array[float] | None = None) -> None:
        self.y = y if y is not None else array("d")
        self.n = n if n is not None else array("d")

    def __len__(self) -> int:
        return len(self.y)

    def __iter__(self) -> Iterator[tuple[float, float]]:
        return zip(self.y, self.n)

    def __getitem__(self, index: Any) -> Any:
        if isinstance(index, slice):
            return Pairs(self.y[index], self.n[index])
        return self.y[index], self.n[index]


@dataclass(frozen=True, slots=True)
class UserValues:
    """Each finished user's ``(y, n)`` pair of every metric read (:func:`user_values`):
    ``users`` in user order, and per metric name its :class:`Pairs` in the same order."""

    users: array[int]
    pairs: Mapping[str, Pairs]

    def of(self, name: str) -> list[tuple[int, tuple[float, float]]]:
        """``(user, (y, n))`` of metric ``name`` as a list (what :func:`user_pairs` gives)."""
        return list(zip(self.users, self.pairs[name], strict=True))


def user_values(store: ResultStore, design: str, definitions: Sequence[Mapping[str, Any]],
                users: set[int] | None = None) -> UserValues:
    """Per finished user of ``design`` (of ``users`` only, when given), the (y, n) pair of
    every metric in ``definitions``, from one streamed reading of the users' stored metrics
    (each user's one JSON object, parsed once for all metrics): the memory is the arrays', 16
    bytes per user and metric, never the stored rows'."""
    ids = array("q")
    out = {d["name"]: Pairs() for d in definitions}
    columns = [out[d["name"]] for d in definitions]
    read = pair_reader(definitions)
    for user, metrics in store.user_metrics(design):
        if users is not None and user not in users:
            continue
        ids.append(user)
        for column, (y, n) in zip(columns, read(metrics), strict=True):
            column.y.append(y)
            column.n.append(n)
    return UserValues(ids, out)


def pair_reader(definitions: Sequence[Mapping[str, Any]]
                ) -> Callable[[Mapping[str, Any]], list[tuple[float, float]]]:
    """A function from one user's stored metrics (their JSON object) to the ``(y, n)`` pair
    of every metric in ``definitions``, in their order: a count ``(total, 1)``, a duration
    ``(sum, number)``, a ratio ``(numerator, denominator)``."""
    plan = [(True, d.get("numerator") or "", d.get("denominator") or "")
            if d["kind"] == "ratio" else (False, d["name"], "") for d in definitions]

    def read(metrics: Mapping[str, Any]) -> list[tuple[float, float]]:
        out = []
        for ratio, first, second in plan:
            if ratio:
                num, _ = _scalar_pair(metrics.get(first))
                den, _ = _scalar_pair(metrics.get(second))
                out.append((num, den))
            else:
                out.append(_scalar_pair(metrics.get(first)))
        return out

    return read


def user_pairs(store: ResultStore, design: str, definition: Mapping[str, Any],
               users: set[int] | None = None) -> list[tuple[int, tuple[float, float]]]:
    """Per finished user of ``design`` (of ``users`` only, when given): the (y, n) pair of
    ``definition``'s metric."""
    return user_values(store, design, [definition], users).of(definition["name"])


def user_pairs_by_metric(store: ResultStore, design: str,
                         definitions: Sequence[Mapping[str, Any]], users: set[int] | None = None
                         ) -> dict[str, list[tuple[int, tuple[float, float]]]]:
    """:func:`user_pairs` of every metric in ``definitions``, by name, from one reading of
    the users' stored metrics (:func:`user_values`, as lists)."""
    values = user_values(store, design, definitions, users)
    return {d["name"]: values.of(d["name"]) for d in definitions}


class _Held:
    """Each finished user's ``(y, n)`` of every metric in arrays (:func:`user_values`):
    what :class:`opspec.evaluation.spilled.SpilledUsers` reads from disk, for a value
    SQLite cannot store (NaN)."""

    def __init__(self, values: UserValues) -> None:
        self.values = values

    def pairs(self, name: str) -> Pairs:
        return self.values.pairs[name]

    def where_denominator(self, name: str) -> list[float]:
        return [y for y, k in self.values.pairs[name] if k > 0]

    def in_user_order(self, name: str) -> array[float]:
        return array("d", (y / k for y, k in self.values.pairs[name] if k > 0))

    def sorted(self, name: str, column: str) -> list[float]:
        pairs = self.values.pairs[name]
        if column == "y":
            return sorted(pairs.y)
        return sorted(y / k for y, k in pairs if k > 0)


def per_user_values(store: ResultStore, design: str,
                    definitions: Sequence[Mapping[str, Any]], users: set[int] | None = None
                    ) -> Any:
    """Each finished user's values of ``definitions`` (of ``users`` only, when given) as
    the summaries read them: ``pairs(name)`` in user order, ``sorted(name, "y")`` (a
    count's totals) and ``sorted(name, "v")`` (``y / n`` where ``n > 0``) ascending,
    ``where_denominator(name)``; in arrays for at most :data:`HELD_USERS` users or when a
    value is NaN, else on disk (:mod:`opspec.evaluation.spilled`). Either is made once per
    state of the store and read again by the report's per-user figure."""
    from opspec.evaluation.spilled import spill_user_values

    key = (store.writes, design, tuple(d["name"] for d in definitions),
           None if users is None else frozenset(users))
    held = _HELD.setdefault(store, {})
    if key in held:
        return held[key]
    if not held_in_memory(_finished_users(store, design, users)):
        spilled = spill_user_values(store, design, definitions, users)
        if spilled is not None:
            return spilled
    # the same doubles in the same order as the spill's (tests/evaluation/
    # test_spilled_values.py): the numbers do not depend on where they are kept
    found = held[key] = _Held(user_values(store, design, definitions, users))
    return found


#: Users whose values are held in arrays rather than written to disk: a pass over spilled
#: values reads a batch of this many rows at once (:data:`.spilled.BATCH`), so below it
#: spilling saves no memory, and its 150-odd reads of SQLite cost 0.09 CPU-s at 1,000
#: users (seventh pass, docs/engine-performance.md). At most 16 bytes per user and metric.
HELD_USERS = 4096

#: The values held in arrays, by store and (its writes, design, metrics, users filter).
_HELD: weakref.WeakKeyDictionary[ResultStore, dict[Any, _Held]] = weakref.WeakKeyDictionary()


def _finished_users(store: ResultStore, design: str, users: set[int] | None) -> int:
    """How many users :func:`user_values` reads (at most ``len(users)``, when given)."""
    count = int(store.query("SELECT COUNT(*) FROM replication WHERE design = ? AND status "
                            "= 'done' AND error IS NULL", (design,))[0][0])
    return count if users is None else min(count, len(users))


def held_in_memory(users: int) -> bool:
    """Whether the values of ``users`` users are held in memory (at most
    :data:`HELD_USERS`) rather than spilled to disk."""
    return users <= HELD_USERS
