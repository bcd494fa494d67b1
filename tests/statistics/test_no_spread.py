"""An interval of no width because every user gave the same value is described as such
(opspec.statistics.no_spread): how many users were alike, the exact bound of the share of
users who could still give another value, and whether they are too few to show that at most
1 in 100 would. Checked against scipy's beta quantile and the estimates that collapse."""

from __future__ import annotations

import pytest
import scipy.stats

from opspec.statistics import count_estimate, paired_difference, rate_interval, ratio_estimate
from opspec.statistics.clustered import ValuesAsPairs
from opspec.statistics.no_spread import ALIKE_SHARE, no_spread, unlike_share_high


@pytest.mark.parametrize("users", [2, 3, 10, 59, 367, 368, 1000, 100_000])
def test_the_share_bound_is_clopper_pearsons_of_0_of_n(users):
    expected = scipy.stats.beta.ppf(0.975, 1, users)
    assert unlike_share_high(users) == pytest.approx(expected, rel=1e-10)
    assert unlike_share_high(users) == pytest.approx(
        rate_interval(0, users, method="clopper-pearson").hi, rel=1e-10)


def test_368_users_all_alike_are_the_fewest_that_bound_the_share_below_1_in_100():
    assert ALIKE_SHARE == 0.01
    assert no_spread([4.0, 4.0], 367)["too_few_users"] is True
    assert no_spread([4.0, 4.0], 368)["too_few_users"] is False
    # the bundled dispenser's 1,000 users of the README, all due 120 doses: not marked
    assert no_spread([120.0, 120.0], 1000) == {
        "users": 1000, "share_unlike_ci95_high": pytest.approx(0.003682, abs=1e-6),
        "too_few_users": False}


def test_three_users_alike_could_hide_that_most_users_differ():
    got = no_spread([4.0, 4.0], 3)
    assert got == {"users": 3, "share_unlike_ci95_high": pytest.approx(0.70760, abs=1e-5),
                   "too_few_users": True}


@pytest.mark.parametrize("ci, users", [([1.0, 2.0], 3), ([None, None], 3), (None, 3),
                                       ([4.0, 4.0], 1), ([0.0, 1e-9], 5)])
def test_an_interval_with_a_width_or_none_is_not_described(ci, users):
    assert no_spread(ci, users) is None


def test_the_estimates_that_collapse_are_recognised():
    # a count: 3 users with 4 doses taken each, 12 events (no Garwood widening)
    count = count_estimate([4.0, 4.0, 4.0])
    assert count.ci == [4.0, 4.0] and no_spread(count.ci, 3)["too_few_users"]
    # a ratio: one alarm per dose in every user's run
    ratio = ratio_estimate([(4.0, 4.0), (5.0, 5.0), (4.0, 4.0)])
    assert ratio.ci == [1.0, 1.0] and no_spread(ratio.ci, 3)["too_few_users"]
    # a mean of the users' own values, every one 0.25
    mean = ratio_estimate(ValuesAsPairs([0.25] * 4))
    assert no_spread(mean.ci, 4)["users"] == 4
    # a paired difference of durations: every user 10 s slower in B
    a = [(30.0, 1.0), (45.0, 1.0), (60.0, 1.0)]
    diff = paired_difference(a, [(y + 10.0, n) for y, n in a])
    assert diff.ci == [10.0, 10.0] and no_spread(diff.ci, 3)["too_few_users"]
    # floating point: 0.1 s per observation over users with different numbers of them
    pairs = [(0.1 * k, float(k)) for k in (3, 7, 11)]
    assert no_spread(ratio_estimate(pairs).ci, 3) is not None
    # but users who differ leave a width, and a count with few events gets Garwood's
    assert no_spread(count_estimate([4.0, 5.0, 4.0]).ci, 3) is None
    assert no_spread(count_estimate([1.0, 1.0, 1.0]).ci, 3) is None
