"""The rate checks of a model check: held-out people's omissions, commissions and
repetitions of one activity against the model's predictive distribution.

A rate is per trial: omission per offer, commission per eligible pick at a choice
(:func:`commission_counts`), repetition per completion. With one rate for everyone, the
pooled count is tested against the exact binomial (``scipy.stats.binomtest``); when people
differ, the mean of the people's own rates against its predictive distribution — each
person's count beta-binomial when a population draws the rate from a beta, otherwise
binomial with a rate drawn from the simulated people's (see :func:`check_rate` for why the
counts are not pooled then), and under parameter redraws the law of each replicate group
(:class:`RateGroups`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from opspec.usermodels.check_report import CheckItem
from opspec.usermodels.predictive_people import PredictivePeople, item_stream

if TYPE_CHECKING:
    from opspec.usermodels.model import UserModel
    from opspec.usermodels.uncertainty import ParameterDraws

__all__ = ["RATE_GROUPS", "RateGroups", "check_rate", "commission_counts", "rate_item"]

#: simulated groups for the predictive distribution of a population's mean rate
RATE_GROUPS = 20_000


def check_rate(name: str, kind: str, activity: str, counts: Mapping[str, tuple[int, int]],
               rates: np.ndarray, beta: tuple[float, float] | None,
               rng: np.random.Generator, *, grouped: RateGroups | None = None) -> CheckItem:
    """Observed counts against their predictive distribution; ``rates`` are the simulated
    people's probabilities, ``beta`` a population's exact per-person law when it has one;
    ``grouped`` (under parameter redraws): the law of each replicate group, whose people
    share its redraw.

    One rate for everyone: the pooled count of all trials, exact binomial test. People who
    differ: the *mean of the people's own rates* ``k_p / n_p``, against the same mean for
    groups whose person ``p`` has ``k ~ BetaBinomial(n_p, a, b)`` (or ``Binomial(n_p, q)``
    with ``q`` one of the simulated people's rates). Pooling counts would be wrong here: the
    number of offers depends on what the person does (a missed alarm rings again), so the
    people who miss most are offered most, and a pooled rate weighs them more than the
    model's per-person rate does."""
    from scipy import stats  # type: ignore[import-untyped]

    used = {p: kn for p, kn in counts.items() if kn[1] > 0}
    k = sum(c for c, _ in used.values())
    n = sum(t for _, t in used.values())
    trials = np.array([t for _, t in used.values()])
    own = np.array([c / t for c, t in used.values()])
    one_rate = grouped is None and rates.size > 0 and float(np.ptp(rates)) == 0.0
    if one_rate:
        q = float(rates[0])
        test, statistic, observed = "exact binomial of the pooled count", float(k), k / n
        p = float(stats.binomtest(k, n, q).pvalue) if 0.0 < q < 1.0 else (
            1.0 if k == round(q * n) else 0.0)
        low, high = (stats.binom.ppf([0.025, 0.975], n, q) / n if 0.0 < q < 1.0
                     else np.array([q, q]))
        centre = q
        singles = stats.binom.ppf([0.025, 0.975], int(np.median(trials)), q) / max(
            1, int(np.median(trials)))
    else:
        draws = np.empty((RATE_GROUPS, trials.size))
        which = (rng.integers(0, grouped.count, size=RATE_GROUPS) if grouped is not None
                 else None)
        for j, t in enumerate(trials):
            if grouped is not None:
                draws[:, j] = rng.binomial(int(t), grouped.person_rates(which, j, rng)) / t
            elif beta is not None:
                draws[:, j] = stats.betabinom.rvs(int(t), *beta, size=RATE_GROUPS,
                                                  random_state=rng) / t
            else:
                q = rates[rng.integers(0, rates.size, size=RATE_GROUPS)]
                draws[:, j] = rng.binomial(int(t), q) / t
        groups = draws.mean(axis=1)
        statistic = observed = float(own.mean())
        below = int(np.sum(groups <= observed + 1e-12))
        above = int(np.sum(groups >= observed - 1e-12))
        p = min(1.0, 2 * (1 + min(below, above)) / (RATE_GROUPS + 1))
        test = (f"mean of the people's own rates, binomial in {grouped.count} simulated "
                f"groups, each under one parameter redraw ({grouped.law})"
                if grouped is not None else
                "mean of the people's own rates, beta-binomial predictive (the "
                "population's per-person beta)" if beta is not None else
                f"mean of the people's own rates, binomial mixed over {rates.size} "
                "simulated people's rates")
        low, high = np.percentile(groups, [2.5, 97.5])
        centre = float(groups.mean())
        singles = np.percentile(draws[:, 0], [2.5, 97.5])
    return CheckItem(name, kind, activity, test, statistic, p, len(used), n,
                     {"value": observed, "count": float(k), "trials": float(n)},
                     {"value": centre, "low": float(low), "high": float(high)}, "",
                     {"people": own.tolist(), "groups_low": float(low),
                      "groups_high": float(high), "person_low": float(singles[0]),
                      "person_high": float(singles[1])})


def _beta_law(model: UserModel, path: tuple[str, ...]) -> tuple[float, float] | None:
    """(a, b) when every person's value at ``path`` is drawn from one beta (a population
    of one subgroup, nothing composed on top that changes it, no per-person notice factor)."""
    population = model.population
    if population is None or len(population.subgroups) != 1 or population.after:
        return None
    group = population.subgroups[0]
    found = None
    for varied in group.varied:
        if varied.path == ("modifier", "notice_factor"):
            return None
        if varied.path == path:
            found = varied.distribution
    if found is None or found.kind != "beta":
        return None
    m, s = found.mean, found.sd
    common = m * (1 - m) / (s * s) - 1
    return (m * common, (1 - m) * common) if common > 0 else None


@dataclass(frozen=True)
class RateGroups:
    """Under parameter redraws, the per-person law of a rate in each replicate group: a
    beta ``(a[g], b[g])`` for every group when the redrawn population draws the rate from
    one (a person's rate then drawn afresh for every simulated group), else the rates of
    group ``g``'s own simulated people (``rates[g, j]``)."""

    a: np.ndarray | None
    b: np.ndarray | None
    rates: np.ndarray

    @property
    def count(self) -> int:
        return int(self.rates.shape[0])

    @property
    def law(self) -> str:
        return ("each person's rate from the redrawn population's beta" if self.a is not None
                else "each person's rate that of one of the group's simulated people")

    def person_rates(self, which: np.ndarray, j: int, rng: np.random.Generator) -> np.ndarray:
        """Person ``j``'s rate in simulated groups that use the replicate groups ``which``."""
        if self.a is not None and self.b is not None:
            return rng.beta(self.a[which], self.b[which])
        return self.rates[which, j % self.rates.shape[1]]


def _probability(person: UserModel, activity: str, kind: str) -> float:
    part = getattr(person.activity(activity), kind)
    return part.probability if part is not None else 0.0


def rate_item(kind: str, activity: str, counts: Mapping[str, tuple[int, int]],
              model: UserModel, people: PredictivePeople,
              draws: ParameterDraws | None, seed: int) -> CheckItem:
    """The check of ``activity``'s ``kind`` (omission, commission, repetition) rate."""
    path = ("activities", activity, kind, "probability")
    rates = np.array([_probability(p, activity, kind) for p in people.people()])
    beta = _beta_law(model, path) if draws is None else None
    grouped = None
    if draws is not None:
        laws = [_beta_law(base, path) for base in people.bases]
        per_group = np.array([[_probability(p, activity, kind) for p in group]
                              for group in people.distinct])
        if all(law is not None for law in laws):
            grouped = RateGroups(np.array([law[0] for law in laws if law is not None]),
                                 np.array([law[1] for law in laws if law is not None]),
                                 per_group)
        else:
            grouped = RateGroups(None, None, per_group)
    return check_rate(f"{activity} {kind}", kind, activity, counts, rates, beta,
                      item_stream(seed, f"{kind}/{activity}"), grouped=grouped)


def commission_counts(sequences: Sequence[Sequence[str]], intended: str, cap: int
                      ) -> tuple[int, int]:
    """(wrong picks, picks at which a wrong pick was possible) of one person's instances of
    a choice: every pick while fewer than ``cap`` wrong ones were made is one trial."""
    wrong = trials = 0
    for seq in sequences:
        w = sum(1 for c in seq if c != intended)
        wrong += min(w, cap)
        trials += len(seq) if w < cap else cap
    return wrong, trials
