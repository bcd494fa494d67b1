"""The interval of a pooled proportion over users (``missed_rate`` = missed / due doses):
Wilson's score interval on the effective number of trials (issue 19, docs/evaluation.md,
"Rare events").

Checked against references nobody here wrote: Newcombe's (1998) published Wilson intervals
when users differ only by chance, Kish's design effect 1 + (m - 1)·ICC of a beta-binomial
population, and coverage of the known truth by simulation — for users who differ only by
chance (the reference user's missed-dose probability, 0.35 %) and for overdispersed
populations (Beta-distributed omission probabilities, whose truth is the Beta mean), where
the pooled Wilson interval alone is shown to fail.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from opspec.statistics.proportions import effective_trials, proportion_interval

#: the reference user's missed-dose probability (shared/bench/analytic.py, 3 alarms)
P_MISSED = 0.0034562262209500982


@pytest.mark.parametrize(("events", "trials", "expected"), [
    # Newcombe (1998), Stat Med 17:857, Table II, method 3 (Wilson score)
    (81, 263, (0.2553, 0.3662)),
    (15, 148, (0.0624, 0.1605)),
    (0, 20, (0.0, 0.1611)),
])
def test_users_who_do_not_differ_get_wilsons_interval(events: int, trials: int,
                                                      expected: tuple[float, float]) -> None:
    one_user = proportion_interval([(float(events), float(trials))])
    assert one_user == pytest.approx(list(expected), abs=6e-5)
    if events == 0:
        # four users with no event: nothing to estimate a design effect from
        split = proportion_interval([(0.0, trials / 4)] * 4)
        assert split == pytest.approx(list(expected), abs=6e-5)
        assert split[1] > 0          # never [0 %, 0 %]


def test_one_or_two_events_get_the_modified_wilson_bound() -> None:
    """Brown, Cai & DasGupta (2001, Stat Sci 16:101, section 4.1.1): with x = 1 or 2 events
    the lower bound is the one-sided Poisson one, lambda_x / n with lambda_1 = 0.051 and
    lambda_2 = 0.355 at 95 %; the upper bound stays Wilson's (Newcombe 1998: 1/29 ->
    0.1718), and the same holds mirrored near n."""
    low, high = proportion_interval([(1.0, 29.0)])
    assert low == pytest.approx(0.051 / 29, rel=0.01)
    assert high == pytest.approx(0.1718, abs=6e-5)
    low, _ = proportion_interval([(1.0, 1000.0), (1.0, 1000.0)])
    assert low == pytest.approx(0.355 / 2000, rel=0.01)
    _, high = proportion_interval([(1000.0, 1000.0), (999.0, 1000.0)])
    assert high == pytest.approx(1 - 0.051 / 2000, rel=1e-6)
    # from 3 events on, Wilson's own bound, above the Poisson one
    assert proportion_interval([(3.0, 1000.0)])[0] > 0.818 / 1000


def test_users_more_alike_than_chance_do_not_narrow_the_interval() -> None:
    # 8 events in each of 10 users of 100 trials: the spread is less than binomial, yet a
    # dose is never worth more than one trial (Korn & Graubard truncate the design effect)
    pairs = [(8.0, 100.0)] * 10
    assert effective_trials(pairs) == 1000
    assert proportion_interval(pairs) == pytest.approx(proportion_interval([(80.0, 1000.0)]))


def test_effective_trials_follow_kishs_design_effect() -> None:
    """Beta-binomial users (m trials each, intraclass correlation rho = 1/(a + b + 1)): the
    pooled proportion's design effect is 1 + (m - 1)·rho (Kish 1965), so the trials are
    worth n / deff independent ones."""
    rng = np.random.default_rng(2019)
    users, m, a, b = 20_000, 50, 2.0, 38.0
    rho = 1 / (a + b + 1)
    missed = rng.binomial(m, rng.beta(a, b, users))
    pairs = [(float(y), float(m)) for y in missed]
    deff = users * m / effective_trials(pairs)
    assert deff == pytest.approx(1 + (m - 1) * rho, rel=0.05)     # 2.195; se about 2 %


def _coverage(rng: np.random.Generator, repetitions: int, users: int, trials: int,
              draw_p, truth: float) -> float:
    covered = 0
    for _ in range(repetitions):
        events = rng.binomial(trials, draw_p(users))
        low, high = proportion_interval([(float(y), float(trials)) for y in events])
        assert low is not None and high is not None and high > 0
        covered += low <= truth <= high
    return covered / repetitions


def _pooled_wilson_coverage(rng: np.random.Generator, repetitions: int, users: int,
                            trials: int, draw_p, truth: float) -> float:
    covered = 0
    for _ in range(repetitions):
        events = int(rng.binomial(trials, draw_p(users)).sum())
        low, high = proportion_interval([(float(events), float(users * trials))])
        covered += low <= truth <= high  # type: ignore[operator]
    return covered / repetitions


@pytest.mark.parametrize(("users", "trials"), [(10, 120), (20, 120), (100, 120), (10, 28)])
def test_rare_events_are_covered_95_percent_of_the_time(users: int, trials: int) -> None:
    """The reference user over 30 days (120 doses) and 7 days (28), 1.0 to 41 expected missed
    doses in all: over 2,000 repetitions a correct interval covers in 94.0-96.0 % (measured:
    96.2, 94.8, 96.0 and 94.0 %); the previous rule, the wider of the t and the Wilson
    interval below 10 events, covered 97.8 % and 99.9 % at 10 users (30 and 7 days)."""
    rng = np.random.default_rng(19_000 + users + trials)
    coverage = _coverage(rng, 2000, users, trials, lambda k: np.full(k, P_MISSED), P_MISSED)
    assert 0.93 <= coverage <= 0.97, coverage


def test_a_fraction_of_an_event_expected_is_still_covered() -> None:
    """The four-alarm dispenser (0.052 % missed) over 7 days at 10 users: 0.15 missed doses
    expected in 280. Wilson's lower bound for one event (0.18/280) is above the truth, so
    plain Wilson covers only when there is no event (86.5 %); the modified bound covers 0
    and 1 event (99.0 %: the lattice allows nothing between 86.5 and 99.0 %)."""
    p = 0.0005186876829259557
    rng = np.random.default_rng(7)
    coverage = _coverage(rng, 2000, 10, 28, lambda k: np.full(k, p), p)
    assert coverage >= 0.98, coverage


def _beta(mean: float, sd: float):
    k = mean * (1 - mean) / (sd * sd) - 1
    return lambda rng: (lambda users: rng.beta(mean * k, (1 - mean) * k, users))


@pytest.mark.parametrize(("users", "floor"), [(10, 0.90), (20, 0.92), (100, 0.93)])
def test_users_who_differ_keep_the_coverage(users: int, floor: float) -> None:
    """Omission probabilities ~ Beta(mean 2 %, sd 2 %): 120 doses per user, design effect
    about 3.4. The pooled Wilson interval treats every dose as independent and covers the
    Beta mean in about 72 % of repetitions; the effective-trials interval keeps about
    92 % (10 users, where 10 users carry little information about the spread), 93 % (20) and
    94.5 % (100) — 1,000 repetitions, so the floors leave about 2 standard errors."""
    rng = np.random.default_rng(1998 + users)
    draw = _beta(0.02, 0.02)(rng)
    coverage = _coverage(rng, 1000, users, 120, draw, 0.02)
    assert floor <= coverage <= 0.975, coverage
    naive = _pooled_wilson_coverage(rng, 300, users, 120, draw, 0.02)
    assert naive < 0.85, naive          # what the design effect is there for


def test_zero_and_all_events_mirror_each_other() -> None:
    missed = proportion_interval([(0.0, 120.0)] * 10)
    taken = proportion_interval([(120.0, 120.0)] * 10)
    assert missed[0] == 0 and 0 < missed[1] < 0.01          # type: ignore[operator]
    assert taken == pytest.approx([1 - missed[1], 1.0])     # type: ignore[operator]
    assert math.isclose(missed[1], 3.841458820694124 / (1200 + 3.841458820694124))  # type: ignore[arg-type]
