"""``DedicatedProcessor.burst``'s counts against the bursts counted one by one: ``max_busy``
is the most bursts under way at one burst's start (those ending later than it starts, and
itself), whichever way the end times are kept (compiled a line, the last ended one taken
off after the new one is in; from source a heap)."""

from __future__ import annotations

import random

from opspec.engine.dedicated import DedicatedProcessor


def test_counts_as_counted_one_by_one() -> None:
    draw = random.Random(17)
    for _ in range(300):
        model = DedicatedProcessor()
        ends: list[float] = []
        most = 0
        now = 0.0
        count = draw.randint(1, 120)
        for _ in range(count):
            now += draw.choice((0.0, 0.001, 0.002, draw.uniform(0.0, 0.01)))
            cost = draw.choice((0.001, 0.002, 0.003, draw.uniform(0.0001, 0.05)))
            model.burst(now, cost)
            ends = [e for e in ends if e > now] + [now + cost]
            most = max(most, len(ends))
            assert model.max_busy == most
        assert model.bursts == count


def test_many_at_once_and_back() -> None:
    model = DedicatedProcessor()
    for k in range(100):                 # past the line's length: a heap, then a line again
        model.burst(0.0, 1.0 + k)
    assert model.max_busy == 100
    model.burst(500.0, 1.0)
    model.burst(500.5, 0.1)
    assert model.max_busy == 100
    assert model.bursts == 102
