"""The dedicated processor's counts (opspec/engine/dedicated.py): compiled, its bursts under
way are a line (sorted, the latest first) while few and a heap past ``LINE_MAX``; the counts
must be those of a plain list of end times, whatever the way they are kept."""

from __future__ import annotations

import random

import pytest

from opspec.engine.dedicated import DedicatedProcessor
from opspec.engine.timers import LINE_MAX, LINE_MIN


@pytest.mark.parametrize("seed", range(4))
def test_busy_counts_as_a_list_of_end_times(seed: int) -> None:
    rng = random.Random(seed)
    dedicated = DedicatedProcessor()
    ends: list[float] = []
    now = 0.0
    busiest = 0
    seen: set[int] = set()
    for n in range(4000):
        # waves: many bursts at once (past LINE_MAX), then a lull (below LINE_MIN)
        wave = (n // 500) % 2 == 0
        now += rng.choice([0.0, 0.0, 0.01]) if wave else rng.choice([0.0, 0.5, 1.0])
        cost = rng.choice([0.0, 0.25, 0.5, 1.0, 2.0]) if wave else rng.choice([0.0, 0.1, 0.25])
        dedicated.burst(now, cost)
        ends = [end for end in ends if end > now]
        ends.append(now + cost)
        busiest = max(busiest, len(ends))
        seen.add(len(ends))
        assert dedicated.max_busy == busiest
    assert dedicated.bursts == 4000
    assert max(seen) > LINE_MAX and min(seen) < LINE_MIN
    assert dedicated.summary()["max_busy"] == busiest
