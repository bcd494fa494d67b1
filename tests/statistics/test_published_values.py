"""opspec.statistics against published values: its intervals are the textbook ones.

Sources:
* Newcombe RG (1998), "Two-sided confidence intervals for the single proportion: comparison of
  seven methods", Statistics in Medicine 17:857-872, Table II: method 3 (Wilson score, no
  continuity correction) and method 5 (Clopper-Pearson "exact") at 95 % for 81/263, 15/148,
  0/20 and 1/29, to four decimals.
* scipy.stats.binomtest's documented example: k=7, n=50, the exact 95 % interval
  (0.05819170033997342, 0.26739600249700846).
* The exact Poisson (Garwood 1936) 95 % limits of a count, as tabulated e.g. by Ulm (1990),
  Am J Epidemiol 131:373-375: 0 -> (0, 3.689), 1 -> (0.0253, 5.572), 5 -> (1.623, 11.668),
  10 -> (4.795, 18.390).
* The distribution-free interval of the median (e.g. Conover, Practical Nonparametric
  Statistics, table of order statistics): n=10 -> (X(2), X(9)), n=20 -> (X(6), X(15)) at
  95 % or more.
* Student t: t(0.975; 10) = 2.2281, t(0.975; 30) = 2.0423 (any t table).
"""

from __future__ import annotations

import pytest

from opspec.statistics import (
    mean_interval,
    normal_quantile,
    one_sided,
    poisson_interval,
    quantile_interval,
    rate_interval,
    t_quantile,
)

NEWCOMBE = [  # successes, trials, Wilson (lo, hi), Clopper-Pearson (lo, hi)
    (81, 263, (0.2553, 0.3662), (0.2527, 0.3676)),
    (15, 148, (0.0624, 0.1605), (0.0578, 0.1617)),
    (0, 20, (0.0, 0.1611), (0.0, 0.1684)),
    (1, 29, (0.0061, 0.1718), (0.0009, 0.1776)),
]


@pytest.mark.parametrize(("k", "n", "wilson", "exact"), NEWCOMBE,
                         ids=[f"{k}-of-{n}" for k, n, *_ in NEWCOMBE])
def test_rate_intervals_are_newcombes(k: int, n: int, wilson: tuple[float, float],
                                      exact: tuple[float, float]) -> None:
    estimate, lo, hi = rate_interval(k, n, 0.95)
    assert estimate == k / n
    assert (lo, hi) == (pytest.approx(wilson[0], abs=5e-5), pytest.approx(wilson[1], abs=5e-5))
    _, lo, hi = rate_interval(k, n, 0.95, method="clopper-pearson")
    assert (lo, hi) == (pytest.approx(exact[0], abs=5e-5), pytest.approx(exact[1], abs=5e-5))


def test_the_exact_interval_is_scipys_documented_example() -> None:
    _, lo, hi = rate_interval(7, 50, 0.95, method="clopper-pearson")
    assert (lo, hi) == (pytest.approx(0.05819170033997342, rel=1e-12),
                        pytest.approx(0.26739600249700846, rel=1e-12))


def test_a_one_sided_bound_is_an_end_of_the_two_sided_interval_at_2c_minus_1() -> None:
    # the one-sided 95 % Wilson lower bound of 81/263 uses z = 1.6449 (the 95th percentile)
    z = normal_quantile(0.95)
    assert z == pytest.approx(1.644854, abs=1e-6)
    p, n = 81 / 263, 263
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * (p * (1 - p) / n + z * z / (4 * n * n)) ** 0.5 / (1 + z * z / n)
    assert rate_interval(81, 263, one_sided(0.95)).lo == pytest.approx(centre - half, rel=1e-12)


@pytest.mark.parametrize(("count", "limits"), [
    (0, (0.0, 3.689)), (1, (0.0253, 5.572)), (5, (1.623, 11.668)), (10, (4.795, 18.390))])
def test_poisson_intervals_are_the_garwood_limits(count: int, limits: tuple[float, float]
                                                  ) -> None:
    rate, lo, hi = poisson_interval(count, 1.0, 0.95)
    assert rate == count
    assert lo == pytest.approx(limits[0], abs=5e-4)
    assert hi == pytest.approx(limits[1], abs=5e-4)
    # per unit of exposure: the same limits scaled
    assert poisson_interval(count, 4.0, 0.95)[2] == pytest.approx(limits[1] / 4, abs=2e-4)


@pytest.mark.parametrize(("n", "ranks"), [(10, (2, 9)), (20, (6, 15))])
def test_the_median_interval_is_the_order_statistic_table(n: int, ranks: tuple[int, int]
                                                         ) -> None:
    values = [float(i) for i in range(1, n + 1)]      # X(i) = i
    _, lo, hi = quantile_interval(values, 0.5, 0.95)
    assert (lo, hi) == (float(ranks[0]), float(ranks[1]))


def test_t_quantiles_and_the_mean_interval_are_the_tables() -> None:
    assert t_quantile(0.95, 10) == pytest.approx(2.2281, abs=1e-4)
    assert t_quantile(0.95, 30) == pytest.approx(2.0423, abs=1e-4)
    values = [float(v) for v in range(11)]           # mean 5, sd sqrt(11), n 11
    est, lo, hi = mean_interval(values, 0.95)
    half = 2.2281 * (11 ** 0.5) / (11 ** 0.5)
    assert est == 5.0 and (lo, hi) == (pytest.approx(5 - half, abs=1e-3),
                                       pytest.approx(5 + half, abs=1e-3))
