"""A run's event times come in time order (the clock never goes back), and the outcome rows
are then counted without a sort (``opspec.evaluation.columns.outcome_columns``): the same
``(metric, day, hour, n)`` rows, in the order first seen, as Python's own ``t // 86400``
and ``(t % 86400) // 3600`` counted by a ``Counter`` — on hour and day edges too, where a
time a hair before midnight must not land in the next day's first hour."""

from __future__ import annotations

from collections import Counter

from hypothesis import given, settings
from hypothesis import strategies as st

from opspec.evaluation.columns import DAY, outcome_columns


def _counted(count_times: dict[str, list[float]]) -> list[tuple[str, int, int, int]]:
    rows: dict[tuple[str, int, int], int] = {}
    for name, times in count_times.items():
        rows.update(Counter([(name, int(t // DAY), int((t % DAY) // 3600)) for t in times]))
    return [(m, d, h, n) for (m, d, h), n in rows.items()]


_edges = st.builds(lambda k, nudge: max(0.0, k * 3600.0 + nudge), st.integers(0, 24 * 40),
                   st.sampled_from([0.0, -1e-9, 1e-9, -1e-6, -5e-12, 0.5]))
_sorted_times = st.lists(st.one_of(st.floats(0.0, 40 * DAY), _edges), max_size=80).map(sorted)


@settings(max_examples=200, deadline=None)
@given(st.dictionaries(st.sampled_from(["alarms", "doses_taken", "missed", "due"]),
                       _sorted_times, max_size=4))
def test_times_in_order_give_the_counters_rows(count_times) -> None:
    assert outcome_columns(count_times).rows() == _counted(count_times)


def test_a_later_metric_may_start_before_the_last_time_of_the_one_before() -> None:
    """Each metric's times are in order, not the metrics one after another: the rows stay
    the metrics' own, each in its order."""
    times = {"b": [5 * 3600.0, DAY + 1.0, DAY + 2.0], "a": [0.0, 10.0, 3 * DAY]}
    assert outcome_columns(times).rows() == [("b", 0, 5, 1), ("b", 1, 0, 2), ("a", 0, 0, 2),
                                             ("a", 3, 0, 1)]


def test_times_out_of_order_are_counted_in_the_order_first_seen() -> None:
    times = {"a": [2 * 3600.0, 10.0, 2 * 3600.0 + 5, 20.0]}
    assert outcome_columns(times).rows() == [("a", 0, 2, 2), ("a", 0, 0, 2)]
