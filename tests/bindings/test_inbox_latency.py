"""The inbox bridging device threads to the engine thread, and latency statistics."""

from __future__ import annotations

import threading

import pytest

from opspec.bindings import Inbox, summarise


def test_callbacks_run_on_the_draining_thread_in_posting_order() -> None:
    inbox = Inbox()
    ran: list[tuple[int, str]] = []
    poster = threading.Thread(target=lambda: [
        inbox.post(lambda i=i: ran.append((i, threading.current_thread().name)))
        for i in range(100)])
    poster.start()
    poster.join()
    assert inbox.pending == 100
    assert inbox.drain() == 100
    assert [i for i, _ in ran] == list(range(100))
    assert {name for _, name in ran} == {threading.current_thread().name}
    assert inbox.drain() == 0


def test_wake_is_called_for_each_post_so_a_sleeping_loop_can_drain_early() -> None:
    woken = threading.Event()
    inbox = Inbox(wake=woken.set)
    threading.Thread(target=inbox.post, args=(lambda: None,)).start()
    assert woken.wait(10)
    assert inbox.wait(10)
    assert inbox.drain() == 1


def test_wait_times_out_when_nothing_arrives() -> None:
    assert Inbox().wait(0.01) is False


def test_latency_summary_uses_nearest_rank_percentiles() -> None:
    summary = summarise([i / 1000 for i in range(1, 101)])  # 1..100 ms
    assert summary.count == 100
    assert summary.mean == pytest.approx(0.0505)
    assert (summary.p50, summary.p99, summary.max) == (0.05, 0.099, 0.1)
    assert "p99 99.000 ms" in summary.describe()
    assert summarise([]).describe() == "no commands"
