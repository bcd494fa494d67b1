"""Confidence intervals over simulated users: the count case is the t interval of the
per-user mean, the ratio (cluster) interval covers the truth about 95 % of the time, and a
paired difference is tighter than an unpaired one when users are correlated across designs."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from opspec.statistics import paired_difference, ratio_estimate


def test_count_interval_is_the_t_interval_of_the_per_user_mean():
    rng = np.random.default_rng(7)
    totals = rng.poisson(4.0, size=25).astype(float)
    estimate = ratio_estimate([(float(y), 1.0) for y in totals])
    low, high = stats.t.interval(0.95, len(totals) - 1, loc=totals.mean(),
                                 scale=stats.sem(totals))
    assert estimate.value == pytest.approx(totals.mean())
    assert (estimate.low, estimate.high) == (pytest.approx(low), pytest.approx(high))


def test_ratio_interval_covers_the_true_ratio_about_95_percent_of_the_time():
    """Clustered data: each user has their own success probability (beta) and a varying
    number of trials; the true pooled ratio is E[n p] / E[n] = E[p] (n independent of p)."""
    rng = np.random.default_rng(11)
    truth = 2.0 / (2.0 + 8.0)
    repetitions, users = 600, 40
    covered = 0
    for _ in range(repetitions):
        n = rng.integers(20, 200, size=users)
        p = rng.beta(2.0, 8.0, size=users)
        y = rng.binomial(n, p)
        est = ratio_estimate(list(zip(y.astype(float), n.astype(float), strict=True)))
        covered += est.low <= truth <= est.high
    # 95 % nominal; the binomial sampling error of 600 repetitions is about 0.9 %
    assert 0.92 <= covered / repetitions <= 0.975


def test_a_count_interval_never_goes_below_zero():
    # four robots, collisions 0, 0, 1, 12: the t interval's lower end would be about -5
    estimate = ratio_estimate([(0.0, 1.0), (0.0, 1.0), (1.0, 1.0), (12.0, 1.0)])
    assert estimate.low == 0.0
    assert estimate.high == pytest.approx(
        stats.t.interval(0.95, 3, loc=3.25, scale=stats.sem([0, 0, 1, 12]))[1])


def test_no_observations_gives_no_estimate_and_one_user_no_interval():
    assert ratio_estimate([]).value is None
    assert ratio_estimate([(0.0, 0.0), (0.0, 0.0)]).value is None
    one = ratio_estimate([(3.0, 2.0)])
    assert one.value == 1.5 and one.ci == [None, None]


def test_pairing_by_user_removes_the_between_user_spread():
    rng = np.random.default_rng(3)
    users = 60
    ability = rng.normal(100.0, 30.0, size=users)            # shared by both designs
    a = [(float(x + rng.normal(0, 2)), 1.0) for x in ability]
    b = [(float(x - 5.0 + rng.normal(0, 2)), 1.0) for x in ability]
    paired = paired_difference(a, b)
    assert paired.value == pytest.approx(np.mean([y for y, _ in b]) - np.mean([y for y, _ in a]))
    assert paired.low < -5.0 < paired.high
    unpaired_half = 1.96 * math.sqrt(np.var([y for y, _ in a], ddof=1) / users
                                     + np.var([y for y, _ in b], ddof=1) / users)
    assert (paired.high - paired.low) / 2 < unpaired_half / 5


def test_paired_designs_need_the_same_users():
    with pytest.raises(ValueError, match="same users"):
        paired_difference([(1.0, 1.0)], [(1.0, 1.0), (2.0, 1.0)])
