"""Checking a user model against people it was not fitted on (``opspec model-check``).

The question, per user-lane activity: does what these people did fall inside what the model
predicts for people like them? "People like them" is the model's *predictive* distribution:

1. when the model file carries ``[uncertainty]`` (a fitted model's bootstrap redraws of its
   parameters), each replicate group of people uses one redraw — the model was estimated
   from a finite sample, and a check that ignored it would flag the estimation error of a
   correct model as a misfit as soon as the held-out people are many;
2. each simulated person is drawn from the population (``[vary]``, subgroups): people differ,
   and their observations are not independent of each other;
3. that person's observations are drawn from their own model, as many as the real person
   has.

**Durations** (per activity): the Anderson-Darling statistic of all held-out durations
against the predictive distribution (a large sample of it, as an empirical CDF), calibrated
by a *parametric bootstrap*: the same statistic for ``replicates`` groups simulated as
above (same number of people, same number of observations each). Its p-value is
``(1 + #{A²_rep >= A²_obs}) / (replicates + 1)`` (Davison & Hinkley 1997, §4.2): valid
whatever the reference CDF, because observed and simulated groups are measured alike, and
it counts a population's between-person spread and the parameters' estimation uncertainty
as what they are — variation the model predicts.

**Rates** (omission per offer, commission per eligible pick at a choice, repetition per
completion): with one rate for everyone, the pooled count against the exact binomial
(``scipy.stats.binomtest``); when people differ, the mean of the people's own rates against
its predictive distribution — each person's count beta-binomial when a population draws the
rate from a beta, otherwise binomial with a rate drawn from the simulated people's (see
:func:`check_rate` for why the counts are not pooled then).

**Family-wise error**: Holm's step-down adjustment over every item checked
(:mod:`opspec.usermodels.holm`); an item misfits when its adjusted p-value is at most the
level.

Not in these checks (said in the output): the model's routine (time-of-day windows,
adherence drift) — it changes durations and rates by time of day, which a per-activity
check pools; the outcome metrics of a spec run with ``--spec`` check them as a whole.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from opspec.usermodels.holm import holm_adjust

if TYPE_CHECKING:
    from opspec.usermodels.fitting import Observations
    from opspec.usermodels.model import ActivityModel, UserModel
    from opspec.usermodels.uncertainty import ParameterDraws

__all__ = [
    "CheckItem",
    "CheckReport",
    "PredictivePeople",
    "anderson_darling",
    "check_observations",
    "finish",
]

#: size of the pooled predictive sample a duration is compared with (its empirical CDF)
REFERENCE_SIZE = 20_000
#: probabilities at which the QQ figure compares quantiles
_QQ_POINTS = np.linspace(0.02, 0.98, 49)


@dataclass(frozen=True)
class CheckItem:
    """One thing checked: its test, statistic, p-value and what was observed and predicted.

    ``observed``/``predicted`` are short summaries (``predicted`` with a 95 % interval
    ``low``/``high`` for what a group of this many people would show); ``figure`` holds what
    the report draws (quantiles for a QQ plot, a predictive distribution for an interval).
    ``p_holm`` and ``misfit`` are set by :func:`finish` once all items are known.
    """

    name: str
    kind: str                    # duration | omission | commission | repetition | metric
    activity: str | None
    test: str
    statistic: float
    p: float
    persons: int
    n: int
    observed: Mapping[str, float]
    predicted: Mapping[str, float]
    unit: str = ""
    figure: Mapping[str, Any] = field(default_factory=dict)
    p_holm: float = math.nan
    misfit: bool = False

    def comparison(self) -> str:
        """What was observed against what the model predicts for a group of this size."""
        o, p = self.observed, self.predicted
        fmt = _fmt_rate if self.kind in _RATES else _fmt_value
        return (f"observed {self.observed_label} {fmt(o['value'], self.unit)}, predicted "
                f"{fmt(p['value'], self.unit)} (95 % of groups of {self.persons}: "
                f"[{fmt(p['low'], self.unit)}, {fmt(p['high'], self.unit)}])")

    def describe(self) -> str:
        """One line: the verdict, what was observed against what was predicted, the test."""
        what = self.comparison()
        verdict = "MISFIT" if self.misfit else "fits  "
        return (f"{verdict} {self.name}: {what}; {self.test}: {self.statistic_label} = "
                f"{self.statistic:.4g}, "
                f"p = {_fmt_p(self.p)}, Holm-adjusted p = {_fmt_p(self.p_holm)}")

    @property
    def pooled(self) -> bool:
        """A rate item tested on the pooled count (one rate for everyone)."""
        return self.test.startswith("exact binomial")

    @property
    def statistic_label(self) -> str:
        if self.kind in _RATES:
            return "count" if self.pooled else "mean rate"
        return {"duration": "A²", "metric": "mean"}.get(self.kind, "value")

    @property
    def observed_label(self) -> str:
        if self.kind in _RATES:
            return "rate" if self.pooled else "mean rate per person"
        return {"duration": "median", "metric": "mean per person"}.get(self.kind, "value")

    def to_json(self) -> dict[str, Any]:
        return {"item": self.name, "kind": self.kind, "activity": self.activity,
                "test": self.test, "statistic": _finite(self.statistic), "p": self.p,
                "p_holm": self.p_holm, "misfit": self.misfit, "persons": self.persons,
                "n": self.n, "unit": self.unit or None,
                "observed": {k: _finite(v) for k, v in self.observed.items()},
                "predicted": {k: _finite(v) for k, v in self.predicted.items()}}


_RATES = ("omission", "commission", "repetition")


def _finite(value: float) -> float | None:
    return float(value) if value is not None and math.isfinite(value) else None


def _fmt_p(p: float) -> str:
    return "nan" if math.isnan(p) else f"{p:.3g}" if p >= 0.001 else f"{p:.1e}"


def _fmt_rate(value: float, unit: str) -> str:
    return f"{100 * value:.1f} %"


def _fmt_value(value: float, unit: str) -> str:
    return f"{value:.4g}" + (f" {unit}" if unit else "")


@dataclass(frozen=True)
class CheckReport:
    """Every item checked, Holm-adjusted at ``level``, and what was not checked (``notes``)."""

    items: tuple[CheckItem, ...]
    level: float
    persons: int
    sessions: int
    replicates: int
    seed: int
    uncertainty: str
    notes: tuple[str, ...] = ()

    @property
    def misfits(self) -> tuple[CheckItem, ...]:
        return tuple(i for i in self.items if i.misfit)

    @property
    def fits(self) -> bool:
        return not self.misfits

    def method(self) -> str:
        return (f"Holm's step-down adjustment over {len(self.items)} item(s): the chance that "
                f"any item of a correct model is called a misfit is at most {self.level:g}")

    def lines(self) -> list[str]:
        out = [item.describe() for item in self.items]
        out.append(f"family-wise error: {self.method()}")
        out.extend(f"note: {n}" for n in self.notes)
        if self.misfits:
            names = ", ".join(i.name for i in self.misfits)
            out.append(f"verdict: {len(self.misfits)} of {len(self.items)} item(s) misfit "
                       f"at family-wise level {self.level:g}: {names}")
        else:
            out.append(f"verdict: the model fits these {self.persons} person(s): none of "
                       f"{len(self.items)} item(s) misfits at family-wise level {self.level:g}")
        return out

    def to_json(self) -> dict[str, Any]:
        return {"fits": self.fits, "level": self.level,
                "family_wise": {"method": "holm", "items": len(self.items),
                                "statement": self.method()},
                "persons": self.persons, "sessions": self.sessions,
                "replicates": self.replicates, "seed": self.seed,
                "parameter_uncertainty": self.uncertainty,
                "misfits": [i.name for i in self.misfits],
                "items": [i.to_json() for i in self.items], "notes": list(self.notes)}


def finish(items: Sequence[CheckItem], level: float) -> tuple[CheckItem, ...]:
    """``items`` with their Holm-adjusted p-values and verdicts at family-wise ``level``."""
    adjusted = holm_adjust([i.p for i in items])
    return tuple(replace(i, p_holm=a, misfit=a <= level) for i, a in zip(items, adjusted,
                                                                          strict=True))


# ------------------------------------------------------------------ the predictive people


#: simulated people drawn for a population without parameter redraws (a person costs
#: milliseconds to draw); each replicate group takes its people at random from them
POOL_SIZE = 1000


class PredictivePeople:
    """``replicates`` groups of ``size`` simulated people, each group under one parameter
    redraw of ``draws`` (when given) and each person drawn from the population.

    Without redraws, people are drawn once into a pool of :data:`POOL_SIZE` (users ``0 …``
    of the population seeded ``seed``, its own stream) and each group takes ``size`` of
    them at random: the groups are as varied as the population. With redraws the people of
    one group share its redraw — that is what parameter uncertainty means for a group: all
    its people are off in the same direction — so every replicate group is drawn on its own
    (group ``b`` under redraw ``1 + b mod B``, its own people). Reusing a few groups for
    many replicates would make the replicates dependent, and the bootstrap p-value
    ``(1 + #exceed) / (B + 1)`` then too small: it would count one unusual group several
    times. ``bases[b]`` is group ``b``'s model (the redrawn one, before people are drawn).
    """

    def __init__(self, model: UserModel, size: int, replicates: int, seed: int,
                 draws: ParameterDraws | None = None) -> None:
        self.model = model
        self.size = size
        self.replicates = replicates
        self.draws = draws
        self.seed = seed
        distinct: list[list[UserModel]] = []
        self.bases: list[UserModel] = []
        if draws is None:
            if model.population is None:
                distinct = [[model] * size]
                self.groups = [distinct[0]] * replicates
            else:
                pool = [model.individual(seed, u).model
                        for u in range(min(POOL_SIZE, replicates * size))]
                distinct = [pool]
                rng = _stream(seed, "people")
                self.groups = [[pool[i] for i in rng.choice(len(pool), size,
                                                            replace=len(pool) < size)]
                               for _ in range(replicates)]
        else:
            applied: dict[int, UserModel] = {}
            for g in range(replicates):
                index = 1 + g % draws.count
                base = applied.get(index)
                if base is None:
                    base = applied[index] = draws.apply(model, index)
                self.bases.append(base)
                if base.population is None:
                    distinct.append([base] * size)
                else:
                    distinct.append([base.individual(seed, g * size + j).model
                                     for j in range(size)])
            self.groups = distinct
        self.distinct = distinct

    def people(self) -> list[UserModel]:
        return [p for g in self.distinct for p in g]


# ------------------------------------------------------------------ durations


def anderson_darling(sample: np.ndarray, reference: np.ndarray) -> float:
    """The Anderson-Darling statistic A² of ``sample`` against the empirical CDF of the
    sorted ``reference`` (mid-ranks for ties, kept inside (0, 1))."""
    x = np.sort(np.asarray(sample, dtype=float))
    n = x.size
    if n == 0:
        return math.nan
    size = reference.size
    ranks = (np.searchsorted(reference, x, "left") + np.searchsorted(reference, x, "right"))
    f = (ranks / 2.0 + 0.5) / (size + 1.0)
    i = np.arange(1, n + 1)
    return float(-n - np.sum((2 * i - 1) * (np.log(f) + np.log1p(-f[::-1]))) / n)


def _choice_extra(person: UserModel, activity: ActivityModel) -> ActivityModel | None:
    """The model of the intended alternative, whose duration a pick adds (performer step 3)."""
    intended = activity.intended
    if intended is not None and person.covers(intended):
        return person.activity(intended)
    return None


def sample_durations(person: UserModel, activity_id: str, n: int,
                     rng: np.random.Generator) -> np.ndarray:
    """``n`` offer-to-completion durations of ``activity_id`` for ``person``, as the
    performer draws them outside routine windows: delay, duration, repetition, a slip's
    recovery; at a choice, the intended pick (what the observed choice durations are)."""
    am = person.activity(activity_id)
    if n <= 0:
        return np.zeros(0)
    out = np.asarray(am.duration.sample_many(rng, n), dtype=float).copy()
    extra = _choice_extra(person, am) if am.is_choice_model else None
    if extra is not None:
        out += extra.duration.sample_many(rng, n)
    if am.delay is not None:
        hit = rng.random(n) < am.delay.probability
        if hit.any():
            out[hit] += am.delay.duration.sample_many(rng, int(hit.sum()))
    if am.repetition is not None:
        hit = rng.random(n) < am.repetition.probability
        if hit.any():
            out[hit] += am.duration.sample_many(rng, int(hit.sum()))
    if am.commission is not None and not am.is_choice_model:
        hit = rng.random(n) < am.commission.probability
        if hit.any():
            out[hit] += am.commission.recovery.sample_many(rng, int(hit.sum()))
    return np.maximum(out, 0.0)


def _stream(seed: int, item: str) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(
        seed, spawn_key=(zlib.crc32(item.encode()),)))


def check_duration(activity: str, observed: Mapping[str, Sequence[float]],
                   people: PredictivePeople, seed: int) -> CheckItem | str:
    """The parametric-bootstrap Anderson-Darling check of one activity's durations (a note
    instead when the model says one constant and every observation is that constant)."""
    rng = _stream(seed, f"duration/{activity}")
    counts = [len(v) for v in observed.values() if len(v)]
    values = np.sort(np.concatenate([np.asarray(v, float) for v in observed.values()]))
    everyone = people.people()
    per_person = max(5, math.ceil(REFERENCE_SIZE / len(everyone)))
    reference = np.sort(np.concatenate([sample_durations(p, activity, per_person, rng)
                                        for p in everyone]))
    replicate_stats = np.empty(people.replicates)
    medians = np.empty(people.replicates)
    quantiles = np.empty((people.replicates, _QQ_POINTS.size))
    for b, group in enumerate(people.groups):
        # the b-th simulated group: person j gives as many durations as observed person j
        sim = np.concatenate([sample_durations(group[j % len(group)], activity, n, rng)
                              for j, n in enumerate(counts)])
        replicate_stats[b] = anderson_darling(sim, reference)
        medians[b] = float(np.median(sim))
        quantiles[b] = np.quantile(sim, _QQ_POINTS)
    if float(np.ptp(reference)) < 1e-9:
        # the model says one constant: any other value is impossible under it
        constant = float(reference[0])
        off = int(np.sum(np.abs(values - constant) > 1e-6 * max(1.0, abs(constant))))
        if off == 0:
            return (f"{activity} duration: the model says {constant:g} s every time, as "
                    f"observed ({values.size} times; not an item)")
        statistic, p, test = float(off), 0.0, f"durations other than the constant {constant:g} s"
    else:
        statistic = anderson_darling(values, reference)
        exceed = int(np.sum(replicate_stats >= statistic - 1e-12))
        p = (1 + exceed) / (people.replicates + 1)
        test = f"Anderson-Darling A² (parametric bootstrap, {people.replicates} groups)"
    low, high = np.percentile(medians, [2.5, 97.5])
    figure = {"probabilities": _QQ_POINTS.tolist(),
              "observed": np.quantile(values, _QQ_POINTS).tolist(),
              "predicted": np.quantile(reference, _QQ_POINTS).tolist(),
              "low": np.percentile(quantiles, 2.5, axis=0).tolist(),
              "high": np.percentile(quantiles, 97.5, axis=0).tolist()}
    return CheckItem(f"{activity} duration", "duration", activity, test, statistic, p,
                     len(counts), int(values.size),
                     {"value": float(np.median(values)), "mean": float(values.mean())},
                     {"value": float(np.median(reference)), "mean": float(reference.mean()),
                      "low": float(low), "high": float(high)}, "s", figure)


# ------------------------------------------------------------------ rates


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


def _rate_item(kind: str, activity: str, counts: Mapping[str, tuple[int, int]],
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
                      _stream(seed, f"{kind}/{activity}"), grouped=grouped)


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


# ------------------------------------------------------------------ all of it


def check_observations(model: UserModel, obs: Observations, *, replicates: int = 399,
                       seed: int = 0, draws: ParameterDraws | None = None,
                       repeated: Mapping[str, Mapping[str, int]] | None = None,
                       decisions_traced: bool = False) -> tuple[list[CheckItem], list[str]]:
    """The duration and rate items of ``model`` against held-out ``obs`` (not yet adjusted:
    :func:`finish` does that over these and any metric items), and notes on what was not
    checked. ``repeated``: per activity, per person, the ``user.repeated`` events counted in
    the traces (``decisions_traced``: whether the traces carry a model's decisions at all)."""
    notes: list[str] = []
    persons = obs.persons
    people = PredictivePeople(model, max(1, len(persons)), replicates, seed, draws)
    items: list[CheckItem] = []
    activities = sorted(set(obs.activities) | set(obs.picks))
    uncovered = [a for a in activities if not model.covers(a)]
    if uncovered:
        notes.append("observed but not in the model (not checked): " + ", ".join(uncovered))
    if not model.routine.is_trivial:
        notes.append("the model's routine (time-of-day windows, adherence drift) is not part "
                     "of the per-activity checks, which pool all times of day; with --spec "
                     "the outcome metrics check it as a whole")
    for activity in activities:
        if not model.covers(activity):
            continue
        am = model.activity(activity)
        # durations: a choice's own time is that of its intended picks (as opspec fit)
        if am.intended is not None and activity in obs.user_pick_durations:
            per_session = obs.user_pick_durations[activity].get(am.intended, {})
        else:
            per_session = obs.user_durations.get(activity, {})
        durations = {p: v for p, v in obs.lists_by_person(per_session).items() if v}
        if durations:
            checked = check_duration(activity, durations, people, seed)
            if isinstance(checked, str):
                notes.append(checked)
            else:
                items.append(checked)
        omissions = obs.counts_by_person(obs.user_omissions.get(activity, {}))
        if omissions and (am.omission is not None or obs.omitted.get(activity)):
            items.append(_rate_item("omission", activity, omissions, model, people, draws,
                                    seed))
        if am.intended is not None and obs.user_picks.get(activity):
            cap = am.commission.max_per_instance if am.commission is not None else 1
            by_person = obs.lists_by_person(obs.user_picks[activity])
            counts = {p: commission_counts(seqs, am.intended, cap)
                      for p, seqs in by_person.items()}
            if am.commission is not None or any(w for w, _ in counts.values()):
                items.append(_rate_item("commission", activity, counts, model, people,
                                        draws, seed))
        elif am.probabilities and obs.picks.get(activity):
            notes.append(f"{activity}: a choice by fixed probabilities is not checked")
        if am.repetition is not None:
            if not decisions_traced:
                notes.append(f"{activity} repetition: not observable in these traces (a "
                             "person's repeated action is not marked in a recording); it is "
                             "part of the duration check")
            else:
                completions = {p: n - k for p, (k, n) in omissions.items()}
                seen = (repeated or {}).get(activity, {})
                counts = {p: (min(seen.get(p, 0), c), c) for p, c in completions.items()}
                items.append(_rate_item("repetition", activity, counts, model, people,
                                        draws, seed))
    return items, notes


def count_decisions(paths: Sequence[Any], obs: Observations, kind: str = "user.repeated"
                    ) -> tuple[dict[str, dict[str, int]], bool]:
    """Per activity, per person: how many ``kind`` events the traces hold (sessions mapped
    to persons as ``obs`` maps them); and whether any ``user.*`` decision event was seen."""
    from opspec.engine.trace import EventKind
    from opspec.usermodels.fitting import read_trace

    out: dict[str, dict[str, int]] = {}
    traced = False
    for file_index, path in enumerate(paths):
        run = 0
        for event in read_trace(path):
            if event.kind == EventKind.RUN_STARTED:
                run += 1
                continue
            if not str(event.kind).startswith("user."):
                continue
            traced = True
            if event.kind == kind:
                activity = str(event.data.get("activity", event.activity))
                person = obs.person((file_index, run))
                per = out.setdefault(activity, {})
                per[person] = per.get(person, 0) + 1
    return out, traced

