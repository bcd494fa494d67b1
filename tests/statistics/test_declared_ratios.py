"""A ratio's interval follows its declaration, never the numbers of one run
(:mod:`opspec.statistics.ratios`): Wilson's on the effective trials for a declared
proportion, an error when the run contradicts the declaration, the ratio's t interval
otherwise, widened to the exact Poisson interval of its events per trial when they are few
(checked against scipy's chi-square quantiles and the closed form of no events)."""

from __future__ import annotations

import math

import pytest
from scipy import stats

from opspec.errors import OpspecError
from opspec.statistics import proportion_interval, ratio_estimate
from opspec.statistics.methods import METHODS
from opspec.statistics.ratios import FalseProportion, ratio_interval

# alarms per dose of three users in a short run: every user's alarms at most their doses
# (the old guess took that for a proportion and capped the interval at 1)
AT_MOST_ONE_EACH = [(3.0, 4.0), (4.0, 4.0), (4.0, 4.0), (2.0, 4.0), (4.0, 4.0), (4.0, 4.0),
                    (3.0, 4.0)]


def test_an_undeclared_ratio_gets_the_ratio_interval_though_no_numerator_exceeds_its_denominator():
    got = ratio_interval(AT_MOST_ONE_EACH, proportion=False, of_counts=True)
    t = ratio_estimate(AT_MOST_ONE_EACH)
    assert got.method == "t" and got.ci == t.ci
    assert got.high is not None and got.high > 1.0      # not capped: it may be 2.5 per dose
    assert proportion_interval(AT_MOST_ONE_EACH)[1] <= 1.0  # what the guess gave


def test_a_declared_proportion_gets_wilson_on_the_effective_trials():
    got = ratio_interval(AT_MOST_ONE_EACH, proportion=True, of_counts=True)
    assert got.method == "wilson-neff"
    assert got.ci == proportion_interval(AT_MOST_ONE_EACH)
    assert got.value == pytest.approx(24 / 28)


def test_a_declared_proportion_a_user_contradicts_is_an_error_naming_it():
    pairs = [(4.0, 4.0), (5.0, 4.0), (3.0, 4.0), (6.0, 4.0)]
    with pytest.raises(FalseProportion) as raised:
        ratio_interval(pairs, proportion=True, of_counts=True, name="alarms_per_dose",
                       numerator="alarms", denominator="doses_due")
    text = str(raised.value)
    assert isinstance(raised.value, OpspecError)      # the CLI prints it and exits non-zero
    assert "alarms_per_dose is declared a proportion" in text
    assert 'Proportion="true"' in text and "2 of 4 users" in text and "5 of 4" in text
    assert 'opspec:Ratio Name="alarms_per_dose"' in raised.value.hint


@pytest.mark.parametrize("pairs", [[(0.0, 40.0), (1.0, 40.0), (0.0, 40.0)],
                                   [(3.0, 10.0), (2.0, 12.0), (4.0, 9.0)],
                                   [(0.0, 40.0), (0.0, 40.0)]],
                         ids=["one-event", "nine-events", "none"])
def test_a_ratio_of_counts_with_few_events_covers_the_exact_poisson_rate(pairs):
    events = int(sum(y for y, _ in pairs))
    trials = sum(n for _, n in pairs)
    got = ratio_interval(pairs, proportion=False, of_counts=True)
    t = ratio_estimate(pairs)
    # Garwood's interval of k events over the trials, from scipy's chi-square quantiles
    low = 0.0 if events == 0 else stats.chi2.ppf(0.025, 2 * events) / 2 / trials
    high = stats.chi2.ppf(0.975, 2 * events + 2) / 2 / trials
    assert got.method == "t+garwood-rate" and "t+garwood-rate" in METHODS
    assert got.low == pytest.approx(min(low, t.low), rel=1e-12)
    assert got.high == pytest.approx(max(high, t.high), rel=1e-12)
    if events == 0:
        # the closed form: P(0 events) = exp(-λ) = 0.025, where the t interval says [0, 0]
        assert got.high == pytest.approx(-math.log(0.025) / trials, rel=1e-12)
        assert t.ci == [0.0, 0.0]


def test_ten_events_or_a_ratio_of_durations_keep_the_t_interval():
    ten = [(4.0, 10.0), (3.0, 12.0), (3.0, 9.0)]
    assert ratio_interval(ten, proportion=False, of_counts=True).method == "t"
    few = [(0.5, 10.0), (0.0, 12.0)]
    assert ratio_interval(few, proportion=False, of_counts=False) == ratio_estimate(few)


def test_no_trials_no_interval_whatever_the_declaration():
    for proportion in (True, False):
        got = ratio_interval([(0.0, 0.0), (0.0, 0.0)], proportion=proportion, of_counts=True)
        assert got.value is None and got.ci == [None, None] and got.method is None
