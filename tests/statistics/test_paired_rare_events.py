"""Paired differences of rare events (issue 19): with a handful of discordant events the
per-user differences are mostly zero and the t interval is too narrow (it covered the closed
form of the reference scenario's fourth-alarm design in 88-90 % of 1,000 repetitions at 10
users, benchmarks/interval_coverage.py) or [0, 0]. Then the interval also covers the exact
Poisson (Garwood 1936) bounds of the events one design adds and removes.

Garwood's two-sided 95 % limits used below are the published ones: 0 events [0, 3.689],
3 events [0.619, 8.767] (Garwood, F. (1936). Fiducial limits for the Poisson distribution.
Biometrika, 28, 437-442; the chi-square form of its tables)."""

from __future__ import annotations

import numpy as np
import pytest

from opspec.statistics import RARE_DISCORDANT, paired_difference, ratio_estimate


def test_no_discordant_event_is_not_a_zero_width_interval() -> None:
    # 10 users, 120 doses each, nobody misses in either design
    a = [(0.0, 120.0)] * 10
    diff = paired_difference(a, a)
    assert diff.value == 0.0
    assert diff.low == pytest.approx(-3.689 / 1200, abs=1e-6)
    assert diff.high == pytest.approx(3.689 / 1200, abs=1e-6)


def test_three_events_added_get_garwoods_bounds() -> None:
    a = [(0.0, 120.0)] * 10
    b = [(1.0, 120.0)] * 3 + [(0.0, 120.0)] * 7
    diff = paired_difference(a, b)
    assert diff.value == pytest.approx(3 / 1200)
    assert diff.high == pytest.approx(8.767 / 1200, abs=1e-6)
    # widened downward by the bound of the events B might remove (none seen: 3.689)
    assert diff.low == pytest.approx((0.619 - 3.689) / 1200, abs=1e-6)


def test_common_events_and_durations_keep_the_t_interval() -> None:
    rng = np.random.default_rng(5)
    a = [(float(rng.poisson(30)), 120.0) for _ in range(20)]
    b = [(y + float(rng.poisson(3)), n) for y, n in a]
    est_a, est_b = ratio_estimate(a), ratio_estimate(b)
    diff = paired_difference(a, b)
    assert sum(yb - ya for (ya, _), (yb, _) in zip(a, b, strict=True)) >= RARE_DISCORDANT
    z = [(yb - est_b.value * nb) / 120.0 - (ya - est_a.value * na) / 120.0
         for (ya, na), (yb, nb) in zip(a, b, strict=True)]
    from scipy import stats

    half = stats.t.ppf(0.975, 19) * np.std(z, ddof=1) / np.sqrt(20)
    assert (diff.low, diff.high) == (pytest.approx(diff.value - half),
                                     pytest.approx(diff.value + half))
    # durations (sums of seconds over counts that differ between designs) are not counts
    durations_a = [(130.5, 2.0), (99.0, 1.0), (0.0, 0.0)]
    durations_b = [(140.0, 2.0), (99.0, 1.0), (310.2, 1.0)]
    assert paired_difference(durations_a, durations_b).value is not None


def test_rare_paired_counts_cover_the_truth_at_least_nominally() -> None:
    """A second design adds events at a rate of 0.0035 per dose to users with 120 doses;
    10 users (about 4 events in all): the widened interval covers the true difference in at
    least 95 % of 2,000 repetitions (the t interval alone: about 90 %)."""
    rng = np.random.default_rng(9)
    truth = 0.0035
    covered = covered_t = 0
    reps = 2000
    for _ in range(reps):
        base = rng.poisson(0.4, 10).astype(float)
        extra = rng.binomial(120, truth, 10).astype(float)
        a = [(y, 120.0) for y in base]
        b = [(y + e, 120.0) for y, e in zip(base, extra, strict=True)]
        diff = paired_difference(a, b)
        covered += diff.low <= truth <= diff.high
        z = extra / 120.0
        sd = z.std(ddof=1)
        half = 2.262 * sd / np.sqrt(10)
        covered_t += (z.mean() - half <= truth <= z.mean() + half)
    assert covered / reps >= 0.95
    assert covered_t / reps < 0.93


def test_durations_differing_in_few_users_get_few_degrees_of_freedom_or_none() -> None:
    """On common random numbers most users' latencies are identical in both designs; the
    variance of the difference rests on the users where they differ."""
    same = [(600.0, 5.0)] * 8
    one = paired_difference([*same, (700.0, 5.0), (650.0, 5.0)],
                            [*same, (700.0, 5.0), (1750.0, 6.0)])
    assert one.value is not None and one.value > 0
    assert one.low is None and one.high is None           # 1 user differs: cannot tell
    a = [*same, (700.0, 5.0), (650.0, 5.0)]
    b = [*same, (1720.0, 6.0), (1750.0, 6.0)]
    two = paired_difference(a, b)
    from scipy import stats

    wide = two.high - two.low
    # 2 users differ: t on 1 degree of freedom (12.71), not 9 (2.262)
    narrow = wide * stats.t.ppf(0.975, 9) / stats.t.ppf(0.975, 1)
    est_a, est_b = ratio_estimate(a), ratio_estimate(b)
    z = [(yb - est_b.value * nb) / (sum(n for _, n in b) / 10)
         - (ya - est_a.value * na) / (sum(n for _, n in a) / 10)
         for (ya, na), (yb, nb) in zip(a, b, strict=True)]
    assert narrow == pytest.approx(2 * stats.t.ppf(0.975, 9) * np.std(z, ddof=1) / np.sqrt(10))
