"""Chunks of users are stored in the order they were sent, whichever worker finishes first:
the store's rows, the trace exports and the figures drawn from the rows (the latency
figure's even sample is taken by row) are then those of one worker, whatever ``--workers``
says."""

from __future__ import annotations

import concurrent.futures as cf
from typing import Any

from opspec.evaluation import runner
from opspec.evaluation.replication import ReplicationRecord


class _Backwards(cf.Executor):
    """Runs nothing until it holds ``hold`` tasks, then finishes them last sent first (a
    worker that got a later chunk done before an earlier one); one task can be made to fail
    or to be lost with its process."""

    def __init__(self, hold: int, broken: int | None = None, failing: int | None = None
                 ) -> None:
        self.hold, self.broken, self.failing = hold, broken, failing
        self.waiting: list[tuple[cf.Future[Any], Any, tuple[Any, ...]]] = []
        self.sent = 0

    def submit(self, fn: Any, /, *args: Any, **kwargs: Any) -> cf.Future[Any]:
        future: cf.Future[Any] = cf.Future()
        self.waiting.append((future, fn, args))
        self.sent += 1
        if len(self.waiting) >= self.hold or self.sent >= 7:
            for done, task, given in reversed(self.waiting):
                number = given[2][0]
                if number == self.broken:
                    done.set_exception(cf.BrokenExecutor("a worker process died"))
                elif number == self.failing:
                    done.set_exception(RuntimeError("boom"))
                else:
                    done.set_result(task(*given))
            self.waiting.clear()
        return future


def _users(doc: Any, label: str, users: list[int]) -> list[ReplicationRecord]:
    return [ReplicationRecord(label, u, "done") for u in users]


def _drain(executor: cf.Executor, slots: int) -> tuple[list[list[int]], list[Any]]:
    kept: list[list[int]] = []
    chunks = [("A", [2 * i, 2 * i + 1]) for i in range(7)]      # users 0..13, 7 chunks
    lost = runner._drain(executor, {}, chunks, slots,
                         lambda records: kept.append([r.user for r in records]))
    return kept, lost


def test_chunks_back_out_of_order_are_stored_in_the_order_sent(monkeypatch) -> None:
    monkeypatch.setattr(runner, "run_users", _users)
    monkeypatch.setattr(runner, "_while_workers_start", lambda meanwhile=None: None)
    kept, lost = _drain(_Backwards(hold=3), slots=4)
    assert kept == [[2 * i, 2 * i + 1] for i in range(7)] and lost == []


def test_a_failed_chunk_keeps_its_place_and_a_lost_one_holds_back_nothing(
        monkeypatch) -> None:
    monkeypatch.setattr(runner, "run_users", _users)
    monkeypatch.setattr(runner, "_while_workers_start", lambda meanwhile=None: None)
    kept, lost = _drain(_Backwards(hold=3, broken=4, failing=8), slots=4)
    # chunk [4, 5] was lost with its worker (run again by the caller), chunk [8, 9] failed:
    # its users are stored as failed replications, in their place
    assert kept == [[0, 1], [2, 3], [6, 7], [8, 9], [10, 11], [12, 13]]
    assert [(label, users) for label, users, _ in lost] == [("A", [4, 5])]


def test_what_the_caller_needs_later_is_loaded_before_any_chunk_is_stored(
        monkeypatch) -> None:
    # ``meanwhile`` (evaluate: the report's modules and template) runs once the workers have
    # their first chunks, not after the last one, when their cores would stand idle
    monkeypatch.setattr(runner, "run_users", _users)
    events: list[str] = []
    chunks = [("A", [2 * i, 2 * i + 1]) for i in range(7)]
    runner._drain(_Backwards(hold=3), {}, chunks, 4,
                  lambda records: events.append(f"kept {records[0].user}"),
                  meanwhile=lambda: events.append("meanwhile"))
    assert events[0] == "meanwhile" and events.count("meanwhile") == 1
    assert len(events) == 8


def test_a_failing_meanwhile_loses_no_replication(monkeypatch) -> None:
    monkeypatch.setattr(runner, "run_users", _users)
    kept: list[int] = []

    def fails() -> None:
        raise OSError("the template's disk is gone")

    lost = runner._drain(_Backwards(hold=2), {}, [("A", [0, 1]), ("A", [2, 3])], 4,
                         lambda records: kept.extend(r.user for r in records),
                         meanwhile=fails)
    assert kept == [0, 1, 2, 3] and lost == []
