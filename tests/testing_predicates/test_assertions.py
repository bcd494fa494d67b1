"""Statistical assertions: intervals checked against scipy, messages, too few replications,
and the sequential mode's early stop."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest
import scipy.stats

from opspec.errors import ConfigurationError
from opspec.testing.assertions import (
    assert_mean,
    assert_quantile,
    assert_rate,
    assert_rate_sequential,
    mean_interval,
    quantile_interval,
    rate_interval,
)


@dataclass
class FakeResult:
    """The parts of a SimulationResult the assertions read, with chosen numbers."""

    successes: int = 0
    trials: int = 0
    values: list[float] = field(default_factory=list)
    replications: int = 10
    seed: int = 5

    def counts(self, num: str, den: str) -> tuple[int, int]:
        return self.successes, self.trials

    def samples(self, metric: str) -> list[float]:
        return self.values

    def observations(self, metric: str) -> list[float]:
        return self.values


@pytest.mark.parametrize("k, n", [(0, 10), (8, 10), (10, 10), (3, 250), (2391, 2400)])
@pytest.mark.parametrize("method, scipy_name", [("wilson", "wilson"),
                                                ("clopper-pearson", "exact")])
def test_rate_intervals_equal_scipys(k: int, n: int, method: str, scipy_name: str) -> None:
    ci = scipy.stats.binomtest(k, n).proportion_ci(0.95, method=scipy_name)
    est, lo, hi = rate_interval(k, n, 0.95, method=method)
    assert est == k / n
    assert lo == pytest.approx(ci.low, abs=1e-12) and hi == pytest.approx(ci.high, abs=1e-12)


def test_the_wilson_interval_covers_the_true_rate_about_as_often_as_claimed() -> None:
    rng = np.random.default_rng(11)
    p, n, runs = 0.97, 200, 2000
    hits = sum(lo <= p <= hi for lo, hi in
               (rate_interval(int(k), n, 0.95)[1:] for k in rng.binomial(n, p, runs)))
    assert 0.92 <= hits / runs <= 0.98


def test_the_t_interval_equals_scipys_and_the_bootstrap_is_seeded() -> None:
    values = [1.0, 1.2, 0.9, 1.4, 1.1, 1.0, 1.3]
    lo, hi = scipy.stats.t.interval(0.9, len(values) - 1, loc=np.mean(values),
                                    scale=scipy.stats.sem(values))
    assert mean_interval(values, 0.9)[1:] == pytest.approx((lo, hi))
    first = mean_interval(values, 0.9, method="bootstrap", seed=3)
    assert first == mean_interval(values, 0.9, method="bootstrap", seed=3)
    assert first.lo < first.estimate < first.hi


def test_the_quantile_interval_covers_the_true_quantile_at_least_as_often_as_claimed() -> None:
    rng = np.random.default_rng(5)
    true_p90 = -math.log(0.1)          # exponential(1)
    runs = 1000
    hits = sum(lo <= true_p90 <= hi for _, lo, hi in
               (quantile_interval(list(rng.exponential(size=150)), 0.9, 0.9)
                for _ in range(runs)))
    assert hits / runs >= 0.88


def test_a_passing_rate_returns_its_decision() -> None:
    decision = assert_rate(FakeResult(990, 1000), ("taken", "due"), at_least=0.98)
    assert decision.passed and decision.n == 1000 and decision.lo > 0.98


def test_a_refuted_rate_states_estimate_interval_bound_and_n() -> None:
    with pytest.raises(AssertionError) as info:
        assert_rate(FakeResult(900, 1000), ("taken", "due"), at_least=0.95)
    text = str(info.value)
    assert text.splitlines()[0] == "expected rate taken/due >= 0.95 with 95% confidence"
    assert "estimate 0.9 (900/1000 due, 10 replication(s)); n = 1000" in text
    assert "95% one-sided Wilson interval [0.8833, 0.9145]; bound >= 0.95" in text  # scipy: 90 % two-sided
    assert "refuted: the claim is false at 95% confidence" in text
    assert "(seed 5, 10 replication(s))" in text


def test_too_few_replications_say_how_many_would_decide() -> None:
    with pytest.raises(AssertionError, match="too few replications to decide: about "
                                             r"(\d+) replications would") as info:
        assert_rate(FakeResult(40, 40, replications=10), ("taken", "due"), at_least=0.99)
    needed = int(str(info.value).split("about ")[1].split()[0])
    # the computed number does decide it: 4 trials per replication, all successes
    assert assert_rate(FakeResult(4 * needed, 4 * needed, replications=needed),
                       ("taken", "due"), at_least=0.99).passed
    with pytest.raises(AssertionError, match="too few"):
        assert_rate(FakeResult(4 * needed - 4, 4 * needed - 4, replications=needed - 1),
                    ("taken", "due"), at_least=0.99)


def test_too_few_replications_for_a_mean_compute_the_number_from_the_spread() -> None:
    rng = np.random.default_rng(2)
    values = list(rng.normal(1.15, 0.2, 20))
    with pytest.raises(AssertionError, match=r"too few replications to decide: about (\d+)"
                       ) as info:
        assert_mean(FakeResult(values=values), "alarms", at_most=1.2)
    needed = int(str(info.value).split("about ")[1].split()[0])
    mean, sd = float(np.mean(values)), float(np.std(values, ddof=1))

    def half(n: int) -> float:
        return float(scipy.stats.t.ppf(0.95, n - 1)) * sd / math.sqrt(n)

    assert half(needed) < 1.2 - mean <= half(needed - 1)


def test_a_mean_over_some_replications_says_how_many_were_left_out() -> None:
    # 12 carts, 3 never found the patient: their time_to_find has no value
    result = FakeResult(values=[100.0, 110.0, 90.0, 400.0] * 2 + [95.0], replications=12)
    with pytest.raises(AssertionError, match=r"3 of 12 replications have no value of "
                                             r"time_to_find_s and are left out"):
        assert_mean(result, "time_to_find_s", at_most=100.0)


def test_a_mean_of_fewer_than_two_values_cannot_be_decided() -> None:
    with pytest.raises(AssertionError, match="at least 2 replications"):
        assert_mean(FakeResult(values=[1.0]), "alarms", at_least=0.5)


def test_quantile_claims_pass_refute_or_ask_for_more_observations() -> None:
    values = [float(v) for v in range(1, 1001)]          # p95 is 950
    assert assert_quantile(FakeResult(values=values), "latency", 0.95, at_most=1000).passed
    with pytest.raises(AssertionError, match=r"(?s)estimate 950 \(1000 observations\).*"
                                             "refuted"):
        assert_quantile(FakeResult(values=values), "latency", 0.95, at_most=900)
    with pytest.raises(AssertionError, match=r"too few observations to decide: about \d+ "
                                             "observations would"):
        assert_quantile(FakeResult(values=values[:50]), "latency", 0.95, at_most=49)


@pytest.mark.parametrize("call, match", [
    (lambda r: assert_rate(r, ("a", "b")), "needs a bound"),
    (lambda r: assert_rate(r, ("a", "b"), at_least=0.9, confidence=1.0), "below 1"),
    (lambda r: assert_rate(r, ("a", "b"), at_least=0.9, method="wald"), "unknown rate method"),
    (lambda r: assert_mean(r, "x", at_least=2, between=(1, 3)), "not both"),
    (lambda r: assert_rate(r, ("taken", "due"), at_least=1.5), "can never hold"),
    (lambda r: assert_mean(r, "x", between=(3, 1)), "empty"),
], ids=["no-bound", "confidence-1", "wald", "both-bounds", "rate-above-1", "empty-range"])
def test_bad_arguments_are_configuration_errors(call: Any, match: str) -> None:
    with pytest.raises(ConfigurationError, match=match):
        call(FakeResult(9, 10, values=[1.0, 2.0]))


def test_rate_assertions_name_metrics_the_spec_has(absent_user: Any) -> None:
    with pytest.raises(ConfigurationError, match="no metric 'doses'.*doses_due"):
        assert_rate(absent_user, "doses", at_least=0.5)
    with pytest.raises(ConfigurationError, match="not a proportion"):
        assert_rate(absent_user, "alarms_per_dose", at_least=0.5)


class Batches:
    """simulate_batch for the sequential tests: Bernoulli(p) trials, 4 per user."""

    def __init__(self, p: float) -> None:
        self.p = p
        self.calls: list[tuple[int, int]] = []

    def __call__(self, k: int, n: int) -> FakeResult:
        self.calls.append((k, n))
        rng = np.random.default_rng([99, k])
        trials = 4 * n
        return FakeResult(int(rng.binomial(trials, self.p)), trials, replications=n)


def test_sequential_mode_stops_early_when_the_answer_is_clear() -> None:
    batches = Batches(0.999)
    outcome = assert_rate_sequential(batches, ("taken", "due"), at_least=0.95,
                                     batch_users=50, max_users=2000)
    assert outcome.looks == 1 and outcome.users == 50 and len(batches.calls) == 1
    assert outcome.max_looks == 40
    assert outcome.look_confidence == pytest.approx(1 - 0.05 / 40)


def test_sequential_mode_keeps_simulating_a_close_call_and_refutes_a_false_one() -> None:
    batches = Batches(0.96)
    outcome = assert_rate_sequential(batches, ("taken", "due"), at_least=0.95,
                                     batch_users=100, max_users=5000)
    assert 1 < outcome.looks < 50 and [k for k, _ in batches.calls] == list(
        range(outcome.looks))
    with pytest.raises(AssertionError, match=r"refuted(?s:.*)decided after \d+ of 10 look"):
        assert_rate_sequential(Batches(0.90), ("taken", "due"), at_least=0.95,
                               batch_users=100, max_users=1000)


def test_sequential_mode_reports_the_cap_when_undecided() -> None:
    with pytest.raises(AssertionError, match="stopped at the cap: 300 users in 3 look"):
        assert_rate_sequential(Batches(0.95), ("taken", "due"), at_least=0.95,
                               batch_users=100, max_users=300)


def test_a_rate_with_no_trials_says_there_is_nothing_to_judge() -> None:
    with pytest.raises(AssertionError, match=r"\(no due at all in 10 replication\(s\)\).*\n.*\n"
                                             "  nothing to judge: simulate longer or more users"):
        assert_rate(FakeResult(0, 0), ("taken", "due"), at_least=0.9)
