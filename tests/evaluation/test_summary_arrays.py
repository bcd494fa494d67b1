"""The summaries hold each user's values in arrays (16 bytes per user and metric) rather than
lists of tuples: the estimates and intervals must be exactly those of the same pairs in a list."""

from __future__ import annotations

import random

from opspec.evaluation.summary import Pairs
from opspec.statistics import (
    count_estimate,
    paired_difference,
    proportion_interval,
    ratio_estimate,
)
from opspec.statistics.ratios import ratio_interval


def _pairs(seed: int, users: int) -> list[tuple[float, float]]:
    rng = random.Random(seed)
    out = []
    for _ in range(users):
        n = float(rng.randint(0, 40))
        out.append((float(rng.randint(0, int(n))), n))
    return out


def test_array_pairs_give_exactly_the_estimates_of_a_list_of_pairs():
    for seed, users in ((1, 2), (2, 37), (3, 1000)):
        listed = _pairs(seed, users)
        arrays = Pairs()
        for y, n in listed:
            arrays.y.append(y)
            arrays.n.append(n)
        assert len(arrays) == users and list(arrays) == listed
        assert arrays[users - 1] == listed[-1]
        assert list(arrays[1:]) == listed[1:]
        assert ratio_estimate(arrays) == ratio_estimate(listed)
        assert proportion_interval(arrays) == proportion_interval(listed)
        for proportion in (True, False):
            assert ratio_interval(arrays, proportion=proportion, of_counts=True) == \
                ratio_interval(listed, proportion=proportion, of_counts=True)
        assert count_estimate([y for y, _ in arrays]) == count_estimate([y for y, _ in listed])
        other = _pairs(seed + 10, users)
        assert paired_difference(arrays, other) == paired_difference(listed, other)
