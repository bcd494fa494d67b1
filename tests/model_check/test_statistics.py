"""The statistics model-check rests on, against references nobody here wrote."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from opspec.usermodels.duration_check import anderson_darling
from opspec.usermodels.holm import holm_adjust
from opspec.usermodels.rate_check import check_rate, commission_counts


def test_holm_worked_example() -> None:
    """Wikipedia, "Holm–Bonferroni method", Example: "Suppose we have four hypotheses
    H1,...,H4 with unadjusted p-values p1=0.01, p2=0.04, p3=0.03 and p4=0.005, to be tested
    at significance level α=0.05. ... H4 (0.005 < 0.0125) is rejected ... H1 (0.01 <
    0.0167) is rejected ... H3 is not rejected (0.03 > 0.025) ... H1 and H4 are rejected
    while H2 and H3 are not rejected." Adjusted p-values: Holm (1979), the running maximum
    of (m − i + 1)·p_(i)."""
    adjusted = holm_adjust([0.01, 0.04, 0.03, 0.005])
    assert adjusted == pytest.approx([0.03, 0.06, 0.06, 0.02])
    assert [a <= 0.05 for a in adjusted] == [True, False, False, True]


def test_holm_is_not_bonferroni_nor_benjamini_hochberg() -> None:
    """Holm rejects what Bonferroni rejects and more (the step-down), and never more than
    the false-discovery-rate procedure's set, which controls a weaker error."""
    p = [0.001, 0.012, 0.02, 0.04, 0.3]
    holm = [a <= 0.05 for a in holm_adjust(p)]
    bonferroni = [x * len(p) <= 0.05 for x in p]
    bh = [a <= 0.05 for a in stats.false_discovery_control(p)]
    assert bonferroni == [True, False, False, False, False]
    assert holm == [True, True, False, False, False]
    assert bh == [True, True, True, True, False]


def test_population_rates_are_checked_against_the_beta_binomial() -> None:
    """People whose rates come from Beta(a, b): each person's count of n trials is
    beta-binomial (scipy.stats.betabinom), so the mean of the people's own rates has mean
    a/(a+b) and variance mean(Var(BetaBinomial(n_p, a, b)) / n_p²) / P — the predictive
    interval the check reports is that distribution's."""
    a, b = 3.0, 17.0
    trials = {"P1": 40, "P2": 60, "P3": 80, "P4": 50}
    counts = {p: (int(0.15 * n), n) for p, n in trials.items()}
    item = check_rate("x omission", "omission", "x", counts, np.array([0.1, 0.2]), (a, b),
                      np.random.default_rng(5))
    variance = np.mean([stats.betabinom.var(n, a, b) / n ** 2 for n in trials.values()]) / 4
    sd = float(np.sqrt(variance))
    assert item.predicted["value"] == pytest.approx(a / (a + b), abs=0.003)
    assert item.predicted["high"] - item.predicted["low"] == pytest.approx(2 * 1.96 * sd,
                                                                           rel=0.08)
    assert item.p > 0.5                  # 15 % observed against a mean of 15 %
    far = {p: (int(0.35 * n), n) for p, n in trials.items()}
    assert check_rate("x omission", "omission", "x", far, np.array([0.1, 0.2]), (a, b),
                      np.random.default_rng(5)).p < 0.001


def test_one_rate_for_everyone_is_the_exact_binomial_test() -> None:
    """One rate for all: the pooled count, p-value of scipy.stats.binomtest."""
    counts = {"P1": (9, 40), "P2": (4, 30)}
    item = check_rate("x omission", "omission", "x", counts, np.full(10, 0.1), None,
                      np.random.default_rng(0))
    assert item.statistic == 13
    assert item.p == pytest.approx(stats.binomtest(13, 70, 0.1).pvalue)


def test_anderson_darling_against_a_known_cdf() -> None:
    """Against a fine reference sample of U(0, 1) the statistic is the one-sample A² of
    Anderson & Darling (1954) for the uniform CDF:
    A² = −n − (1/n) Σ (2i − 1) [ln u_(i) + ln(1 − u_(n+1−i))]."""
    rng = np.random.default_rng(3)
    u = np.sort(rng.random(50))
    reference = (np.arange(1, 200_000) / 200_000)
    i = np.arange(1, 51)
    exact = -50 - np.sum((2 * i - 1) * (np.log(u) + np.log(1 - u[::-1]))) / 50
    assert anderson_darling(u, reference) == pytest.approx(exact, rel=1e-3)
    # and it grows when the sample is not from the reference
    assert anderson_darling(u ** 2, reference) > 5 * exact


def test_commission_trials_count_the_picks_that_could_go_wrong() -> None:
    """With at most one wrong pick per instance, every instance is one trial; with two, a
    pick after two wrong ones is forced and not a trial."""
    sequences = [["ok"], ["wrong", "ok"], ["wrong", "wrong", "ok"], ["ok"]]
    assert commission_counts(sequences[:2] + [["ok"]], "ok", cap=1) == (1, 3)
    assert commission_counts(sequences, "ok", cap=2) == (3, 1 + 2 + 2 + 1)


def test_a_groups_people_share_its_parameter_redraw() -> None:
    """Parameter uncertainty is one error of the whole fitted model: all people of a
    simulated group are off in the same direction (Gelman et al., *Bayesian Data Analysis*,
    posterior predictive replications: "each replicated data set drawn under one draw of the
    parameters"). Redraws at 5 % and 15 % of one rate for everyone: a group of ten people
    at 15 % each is one the model predicts half the time; mixing the redraws person by
    person instead would make every group's mean about 10 % and call it a misfit."""
    from opspec.usermodels.rate_check import RateGroups

    trials = {f"P{i}": 100 for i in range(10)}
    counts = {p: (15, n) for p, n in trials.items()}
    groups = RateGroups(None, None, np.repeat(np.array([[0.05], [0.15]]), 10, axis=1))
    shared = check_rate("x commission", "commission", "x", counts, np.array([0.05, 0.15]),
                        None, np.random.default_rng(1), grouped=groups)
    assert shared.p > 0.3
    assert shared.predicted["low"] < 0.07 and shared.predicted["high"] > 0.13
    mixed = check_rate("x commission", "commission", "x", counts,
                       np.repeat([0.05, 0.15], 500), None, np.random.default_rng(1))
    assert mixed.p < 0.02 and mixed.predicted["high"] < 0.15   # what sharing avoids


def test_a_population_omission_centre_is_the_mean_of_the_peoples_own_rates() -> None:
    """A missed prompt is offered again, so the forgetful are offered most: their pooled
    rate sum(k)/sum(n) weighs them more than the population's per-person rate, whose mean is
    the mean of the people's own rates k_p/n_p (what the check compares, and the centre of
    the beta a population draws). Beta-binomial moments (Kleinman 1973): between-person
    variance = var(k_p/n_p) minus the mean sampling variance p_p(1-p_p)/n_p."""
    from opspec.usermodels.spread import omission_spread

    rng = np.random.default_rng(7)
    rates = rng.beta(1.0, 4.0, 400)                       # mean 0.2, sd 0.163
    pairs = {}
    for person, p in enumerate(rates):
        misses = rng.geometric(1 - p, 50) - 1             # each of 50 doses rings until heard
        pairs[person] = (int(misses.sum()), int(50 + misses.sum()))
    spread = omission_spread(pairs)
    assert spread is not None and spread.varies
    own = np.mean([k / n for k, n in pairs.values()])
    pooled = sum(k for k, _ in pairs.values()) / sum(n for _, n in pairs.values())
    assert spread.mean == pytest.approx(own)
    # the people's own rates average what they were drawn with; the pooled rate sits high
    assert abs(spread.mean - rates.mean()) < 0.01
    assert pooled - rates.mean() > 0.04
    assert spread.between_sd == pytest.approx(float(np.sqrt(4 / (25 * 6))), rel=0.1)
