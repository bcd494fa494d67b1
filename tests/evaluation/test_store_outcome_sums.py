"""The outcome sums the report's counts-over-time figures read: kept by the store while a
fresh run stores, read from the table otherwise. Either way they are the table's own sums,
and a report re-drawn from a reopened store shows the same pictures."""

from __future__ import annotations

import sqlite3

from evaluation_inputs import SPEC

from opspec.evaluation.replication import ReplicationRecord
from opspec.evaluation.store import ResultStore


def _record(user: int, outcomes: dict[tuple[str, int, int], int], status: str = "done"
            ) -> ReplicationRecord:
    return ReplicationRecord(design="A", user=user, status=status, outcomes=outcomes)


def _table_sums(folder) -> list[tuple[str, int, int, int]]:
    with sqlite3.connect(folder / "results.sqlite") as conn:
        return sorted(conn.execute("SELECT metric, day, hour, SUM(n) FROM outcome "
                                   "WHERE design = 'A' GROUP BY metric, day, hour"))


def test_sums_are_the_tables_also_when_a_user_is_stored_again(tmp_path) -> None:
    with ResultStore(tmp_path, create=True) as store:
        store.add_many([_record(0, {("alarms", 0, 8): 2, ("doses_taken", 0, 8): 1}),
                        _record(1, {("alarms", 0, 8): 1, ("alarms", 1, 20): 3})])
        assert sorted(store.outcome_sums("A")) == _table_sums(tmp_path) == [
            ("alarms", 0, 8, 3), ("alarms", 1, 20, 3), ("doses_taken", 0, 8, 1)]
        # user 1 failed and is run again in the same run: its earlier rows are replaced
        store.add_many([_record(1, {("alarms", 0, 8): 5})])
        assert sorted(store.outcome_sums("A")) == _table_sums(tmp_path) == [
            ("alarms", 0, 8, 7), ("doses_taken", 0, 8, 1)]
        assert store.outcome_sums("B") == []
    with ResultStore(tmp_path, create=False) as store:          # reopened: from the table
        store.add_many([_record(2, {("doses_taken", 2, 8): 1})])
        assert sorted(store.outcome_sums("A")) == _table_sums(tmp_path)
        assert ("doses_taken", 2, 8, 1) in store.outcome_sums("A")


def test_a_report_redrawn_from_the_reopened_store_has_the_same_count_figures(
        tmp_path, evaluate) -> None:
    out = tmp_path / "run"
    status, _, err = evaluate(str(SPEC), "--users", "6", "--days", "3", "--seed", "11",
                              "--workers", "1", "--out", str(out))
    assert status == 0, err
    figures = {name: (out / "figures" / name).read_bytes()
               for name in ("A-days.svg", "A-hours.svg")}
    status, _, err = evaluate("--resume", "--out", str(out), "--workers", "1")
    assert status == 0, err
    for name, before in figures.items():
        assert (out / "figures" / name).read_bytes() == before, name
