"""A replication's sample and outcome rows as columns (opspec.evaluation.columns): the same
rows, in the same order and with the same SQLite types, as the tuples they replace; the
store keeps the same tables and the same running sums from them."""

from __future__ import annotations

import math
import sqlite3
from collections import Counter

import numpy as np
from evaluation_inputs import SPEC, USERS_TOML
from hypothesis import given, settings
from hypothesis import strategies as st

from opspec.evaluation.columns import (
    DAY,
    columns_of_outcomes,
    columns_of_samples,
    object_rows,
    outcome_columns,
    sample_columns,
)
from opspec.evaluation.plan import file_digest
from opspec.evaluation.replication import ReplicationRecord, prepare, run_user
from opspec.evaluation.store import ResultStore
from opspec.runs import build


def _counted(count_times: dict[str, list[float]]) -> list[tuple[str, int, int, int]]:
    """The rows as the evaluation counted them before: Python's float ``//`` and ``%``, a
    ``Counter`` per metric, keys in the order first seen."""
    rows: dict[tuple[str, int, int], int] = {}
    for name, times in count_times.items():
        rows.update(Counter([(name, int(t // DAY), int((t % DAY) // 3600)) for t in times]))
    return [(m, d, h, n) for (m, d, h), n in rows.items()]


# times on the edges too: midnight, the hour, a hair before either (floor division's cases)
_edges = st.builds(lambda k, nudge: max(0.0, k * 3600.0 + nudge), st.integers(0, 24 * 40),
                   st.sampled_from([0.0, -1e-9, 1e-9, -1e-6, 0.5]))
_times = st.lists(st.one_of(st.floats(0.0, 40 * DAY), _edges), max_size=60)


@settings(max_examples=150, deadline=None)
@given(st.dictionaries(st.sampled_from(["alarms", "doses_taken", "missed"]), _times,
                       max_size=3))
def test_outcome_columns_are_the_counters_rows(count_times) -> None:
    """Any event times, in time order or not, on hour and day edges: the same
    ``(metric, day, hour, n)`` rows as Python's own ``t // 86400`` and ``(t % 86400) //
    3600`` counted by a Counter, in the same order."""
    assert outcome_columns(count_times).rows() == _counted(count_times)


def test_sample_columns_pair_each_value_with_its_time() -> None:
    columns = sample_columns({"latency": [1.5, 2.25], "other": [], "wait": [0.1]},
                             {"latency": [10.0, 20.0], "wait": [30.0]})
    assert columns.rows() == [("latency", 1.5, 10.0), ("latency", 2.25, 20.0),
                              ("wait", 0.1, 30.0)]
    try:
        sample_columns({"latency": [1.0, 2.0]}, {"latency": [1.0]})
    except ValueError as error:
        assert "latency" in str(error)
    else:
        raise AssertionError("values without their times were accepted")


def test_object_rows_are_python_values_row_after_row() -> None:
    a = columns_of_outcomes({("alarms", 0, 8): 2, ("taken", 1, 9): 1})
    b = columns_of_outcomes({("taken", 3, 23): 4})
    flat = object_rows("A", [7, 8, 9], [a, columns_of_outcomes({}), b], 3)
    assert flat == ["A", 7, "alarms", 0, 8, 2, "A", 7, "taken", 1, 9, 1,
                    "A", 9, "taken", 3, 23, 4]
    assert {type(v) for v in flat} == {str, int}      # no numpy scalars reach SQLite
    samples = object_rows("B", [1], [columns_of_samples([("x", 0.1, 1e-300)])], 2)
    assert samples == ["B", 1, "x", 0.1, 1e-300] and type(samples[3]) is float


def _table(folder, sql: str) -> list[tuple]:
    with sqlite3.connect(folder / "results.sqlite") as conn:
        return list(conn.execute(sql))


def test_records_with_columns_store_what_records_with_tuples_store(tmp_path) -> None:
    """The same replications given as tuples (a record built by hand) and as columns (as
    run_user makes them), designs interleaved in one batch: the same rows in the same order,
    with SQLite's integer and real types, and the same running sums as the table's."""
    times = {"alarms": [0.0, 3599.9, 3600.0, DAY + 5.0], "taken": [7200.0]}
    samples = {"latency": [12.5, 0.25]}
    ends = {"latency": [100.0, DAY]}
    plain, packed = [], []
    for design, user in (("A", 0), ("B", 0), ("A", 1)):
        outcomes = dict(((m, d, h), n) for m, d, h, n in _counted(times))
        rows = [(m, v, t) for m in samples for v, t in zip(samples[m], ends[m], strict=True)]
        plain.append(ReplicationRecord(design, user, "done", outcomes=outcomes, samples=rows))
        packed.append(ReplicationRecord(design, user, "done",
                                        sample_columns=sample_columns(samples, ends),
                                        outcome_columns=outcome_columns(times)))
    folders = [tmp_path / "plain", tmp_path / "packed"]
    sums = []
    for folder, records in zip(folders, (plain, packed), strict=True):
        with ResultStore(folder, create=True) as store:
            store.add_many(records)
            sums.append((sorted(store.outcome_sums("A")), sorted(store.outcome_day_squares("A"))))
    tables = [[_table(f, "SELECT *, typeof(value), typeof(time) FROM sample ORDER BY rowid"),
               _table(f, "SELECT *, typeof(day), typeof(n) FROM outcome ORDER BY rowid")]
              for f in folders]
    assert tables[0] == tables[1]
    assert tables[1][1][0] == ("A", 0, "alarms", 0, 0, 2, "integer", "integer")
    assert [r[0] for r in tables[1][1]] == ["A"] * 4 + ["B"] * 4 + ["A"] * 4
    assert sums[0] == sums[1]
    assert sums[1][0] == sorted(_table(folders[1], "SELECT metric, day, hour, SUM(n) FROM "
                                       "outcome WHERE design = 'A' GROUP BY 1, 2, 3"))
    # two users, each with 3 alarms on day 0 and 1 on day 1, 1 taken on day 0
    assert sums[1][1] == [("alarms", 0, 18), ("alarms", 1, 2), ("taken", 0, 2)]


def test_a_record_with_tuples_and_columns_stores_the_tuples_first(tmp_path) -> None:
    record = ReplicationRecord("A", 3, "done", outcomes={("x", 0, 1): 1},
                               outcome_columns=outcome_columns({"y": [0.0], "x": [DAY]}))
    with ResultStore(tmp_path, create=True) as store:
        store.add(record)
        assert sorted(store.outcome_sums("A")) == [("x", 0, 1, 1), ("x", 1, 0, 1),
                                                   ("y", 0, 0, 1)]
    assert _table(tmp_path, "SELECT metric, day, hour, n FROM outcome ORDER BY rowid") == [
        ("x", 0, 1, 1), ("y", 0, 0, 1), ("x", 1, 0, 1)]


def test_the_dispensers_records_hold_the_rows_counted_from_their_runs() -> None:
    """run_user's columns against the run's own event times, counted as above, for users of
    the dispenser (the run built as run_user builds it: the same seed and user)."""
    context = prepare(str(SPEC), file_digest(SPEC), str(USERS_TOML),
                      {})
    for user in (0, 1):
        record = run_user(context, "A", user, seed=5, horizon=2 * DAY, keep_trace=False)
        outcome = build(context.spec, seed=5, user=context.user, user_index=user,
                        until=2 * DAY, config=context.config, keep_times=True).execute()
        assert record.outcome_columns is not None and record.sample_columns is not None
        assert record.outcome_columns.rows() == _counted(outcome.count_times)
        assert record.sample_columns.rows() == [
            (m, v, t) for m, values in outcome.samples.items()
            for v, t in zip(values, outcome.sample_times[m], strict=True)]
        assert len(record.outcome_columns) > 10
        assert all(math.isfinite(v) for _, v, _ in record.sample_columns.rows())
        assert record.outcomes == {} and record.samples == []
        assert np.issubdtype(record.outcome_columns.data.dtype, np.integer)
