"""How evaluate splits its users into chunks for the workers (``runner.chunks``): every user
once, in user order, and with several workers the last chunks small, so that no worker is
left running a full chunk while the others have nothing to do."""

from __future__ import annotations

import pytest

from opspec.evaluation.runner import chunks


@pytest.mark.parametrize(("users", "workers"), [(1000, 2), (10_000, 2), (300, 4), (7, 2),
                                                (1, 3), (1000, 1)])
def test_every_user_once_in_order(users: int, workers: int) -> None:
    parts = chunks(list(range(users)), workers)
    assert [u for part in parts for u in part] == list(range(users))
    assert all(1 <= len(part) <= 50 for part in parts)


def test_one_worker_gets_equal_chunks() -> None:
    assert [len(p) for p in chunks(list(range(1000)), 1)] == [50] * 20


def test_several_workers_finish_on_small_chunks() -> None:
    sizes = [len(p) for p in chunks(list(range(1000)), 2)]
    assert sizes[0] == 50
    assert sizes == sorted(sizes, reverse=True)         # never a big chunk after a small
    # the work left once the last full chunk is handed out is spread in small pieces: the
    # last chunk each worker takes is at most an eighth of a full one
    assert max(sizes[-2:]) <= 50 // 8
