"""The dedicated processor's counts are those of the bursts' end times, however it keeps them
(compiled: the two earliest as native floats, the rest on a line or a heap; from source a
heap): checked against a plain list of the bursts under way."""

from __future__ import annotations

import random

import pytest

from opspec.engine.dedicated import DedicatedProcessor


def _reference(bursts: list[tuple[float, float]]) -> dict[str, float | int]:
    ends: list[float] = []
    max_busy = 0
    busy_time = 0.0
    for now, cost in bursts:
        ends = [end for end in ends if end > now]
        ends.append(now + cost)
        max_busy = max(max_busy, len(ends))
        busy_time += cost
    return {"bursts": len(bursts), "busy_time": busy_time, "max_busy": max_busy}


@pytest.mark.parametrize("seed", range(12))
def test_the_counts_are_those_of_the_bursts_under_way(seed: int) -> None:
    rng = random.Random(seed)
    # from one or two at once (a robot spec) to past the line's length (a heap, then a line)
    spread = [0.2, 1.0, 5.0, 40.0, 150.0][seed % 5]
    now = 0.0
    bursts = []
    for _ in range(3000):
        now += rng.choice([0.0, rng.random() * 0.5])    # bursts at the same instant too
        cost = rng.choice([0.0, 0.1, rng.random() * spread])   # ends tied, at once
        bursts.append((now, cost))
    dedicated = DedicatedProcessor()
    for at, cost in bursts:
        dedicated.burst(at, cost)
    assert dedicated.summary() == _reference(bursts)
