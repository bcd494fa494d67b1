"""Redraws of a fitted model's parameters by the bootstrap (``opspec fit --draws B``).

A model fitted from 40 observations is not known, only estimated. The simulation literature
carries that into the output by running the simulation at parameters redrawn from their
sampling distribution — Barton & Schruben's direct bootstrap (Barton & Schruben 2001,
"Resampling methods for input modeling", Proc. Winter Simulation Conference; Barton,
Nelson & Xie 2014, INFORMS J. Computing 26(1)). The redraws are made here, once, from the
traces; :mod:`opspec.usermodels.uncertainty` keeps them in the model file and
:mod:`opspec.evaluation.input_uncertainty` runs them.

Why a nonparametric bootstrap and not the MLE with its covariance: the fitted parameters
include rates (omission, commission: bounded, skewed near 0 with few events), the time a
wrong pick costs (a difference of means) and duration families whose parameters are far from
normal at n = 40 (a lognormal's sigma, an ex-Gaussian's tau); resampling the data and fitting
again, exactly as ``opspec fit`` fits, gives every one of them its own sampling distribution
and their correlations without a formula per parameter.

What is resampled (Davison & Hinkley 1997, *Bootstrap Methods and their Application*,
section 3.8, two-stage data): the independent units are **persons**, not sessions nor single
observations — the sessions of one person share their speed and their forgetfulness. With at
least :data:`MIN_PERSONS` persons, persons are drawn with replacement and keep all their
observations (Davison & Hinkley's recommended strategy when there are enough clusters). With
fewer (one participant recorded for a week), between-person differences cannot be estimated
at all and each person's durations are resampled within that person, while each rate
(omission, commission) is drawn from its Jeffreys posterior Beta(k + 1/2, n - k + 1/2)
(Chick 2001, "Input distribution selection for simulation experiments: accounting for input
uncertainty", Operations Research 49(5)): resampling 20 prompts with 2 omissions would spread
the rate like the Wald interval, which covers far less than it says at such counts (Brown,
Cai & DasGupta 2001, Statistical Science 16(2)); the Jeffreys interval keeps its level.

Each resample is fitted as the data were: the duration family ``opspec fit`` chose (AIC/BIC
on the whole data) is fitted again by maximum likelihood — the choice of family is not
redrawn —, a rate is events / trials of the resample, the time lost to a wrong pick the
difference of means. A population's centre and between-person spread (``[vary]``) are
not resampled but drawn from their posterior — under the normal random-effects model of
the persons' log mean times for a duration (:class:`_PersonLevel`), under the hierarchical
beta-binomial model of their counts for a rate (:class:`_RateLevel`: own rates near 0 are
skewed, and the normal model's symmetric draws are too narrow above a low estimate): a
percentile bootstrap of 30 persons gives them normal tails with (P - 1)/P of their
variance, and groups of new people simulated under it are too alike — ``opspec
model-check`` of a freshly fitted model then calls misfits above its level
(docs/fitting.md). So is the centre of a lognormal duration everyone shares (its median),
from the same posterior with the persons' own log mean times (:func:`_shared_level`):
whether or not people differ, their own values' spread holds the estimate's error, and the
t-based draws keep the tails a check of new people needs (a lognormal's sigma and the other
duration families are still resampled). An omission or commission rate everyone shares (no
``[vary]``) is drawn from the Jeffreys posterior of the pooled counts (:class:`_SharedRate`):
the model says the persons' counts are one binomial sample of one rate. A resample that cannot be fitted (too few distinct durations) keeps the
estimate for that parameter and is counted in ``failed``. Rates the data show no event of
(no omission in 40 offers) are not written by ``opspec fit``, hence not redrawn.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from opspec.usermodels.distributions import Constant, Gamma, LogNormal, Weibull
from opspec.usermodels.families import fit_family
from opspec.usermodels.uncertainty import ParameterDraws

if TYPE_CHECKING:
    from opspec.usermodels.fitting import FitResult
    from opspec.usermodels.rate_posterior import RatePosterior
    from opspec.usermodels.spread import PersonMoments

__all__ = ["MIN_PERSONS", "parameter_draws"]

#: fewer persons than this and observations are resampled within each person
MIN_PERSONS = 5

_STREAM = 0x1F17_0019          # the bootstrap's own stream, apart from the spread's


@dataclass
class _Data:
    """One person's (or one resample's) observations of one activity."""

    durations: list[float] = field(default_factory=list)
    omitted: int = 0
    answered: int = 0
    picks: list[list[str]] = field(default_factory=list)
    by_pick: dict[str, list[float]] = field(default_factory=dict)

    def add(self, other: _Data) -> None:
        self.durations.extend(other.durations)
        self.omitted += other.omitted
        self.answered += other.answered
        self.picks.extend(other.picks)
        for pick, values in other.by_pick.items():
            self.by_pick.setdefault(pick, []).extend(values)

    def within(self, rng: np.random.Generator) -> _Data:
        """This person's durations resampled with replacement; the counts behind the rates
        are kept (their rates are drawn from the Jeffreys posterior, see :func:`_rate`)."""
        def again(values: Sequence[Any]) -> list[Any]:
            if not values:
                return []
            return [values[i] for i in rng.integers(0, len(values), len(values))]

        return _Data(again(self.durations), self.omitted, self.answered, list(self.picks),
                     {p: again(v) for p, v in self.by_pick.items()})


def _family(dist: Any) -> str | None:
    if isinstance(dist, LogNormal):
        return "lognormal"
    if isinstance(dist, Gamma):
        return "gamma"
    if isinstance(dist, Weibull):
        return "weibull"
    if dist.to_params().get("kind") == "exgauss":
        return "exgauss"
    return None


def _refit(family: str, values: Sequence[float]) -> dict[str, float] | None:
    """The family's maximum-likelihood parameters, in the model file's words."""
    x = np.asarray(values, dtype=float)
    if x.size < 2 or float(np.ptp(x)) <= 0:
        return None
    if family == "lognormal":                  # the MLE in closed form (scipy's, faster)
        if not np.all(x > 0):
            return None
        logs = np.log(x)
        return {"median": float(math.exp(logs.mean())), "sigma": float(logs.std())}
    fitted = fit_family(family, x)
    return fitted.named_parameters() if fitted is not None else None


@dataclass(frozen=True)
class _Target:
    """One group of parameters one statistic of the data gives."""

    activity: str                      # whose data
    kind: str                          # duration | omission | commission | loss
    prefix: str                        # the parameter path before the parameter's name
    family: str | None = None
    intended: str | None = None        # duration of a choice: its intended picks only
    between: float = 0.0               # lognormal: the sigma written is the within-person part
    #: a population's omission rate (``[vary]``): the mean of the own rates of the persons
    #: with at least this many offers, as the fit takes it; 0: the rate of the pooled counts
    own_rates_min: int = 0


def _targets(result: FitResult) -> list[_Target]:
    from opspec.usermodels.population import dotted

    model = result.model
    out: list[_Target] = []
    vary = result.vary()
    for fit in result.fits:
        own = model.activities.get(fit.activity)
        if own is None:
            continue
        # how much people differ is estimated from 30 persons as loosely as their mean
        # (a between-person sd's interval easily spans a factor of two): it is redrawn too,
        # or a check of new people would take a spread that came out small for the truth
        written = vary.get(fit.activity, {})
        for param in written.get("duration", {}):
            spread = fit.duration_spread
            out.append(_Target(fit.activity, "duration spread",
                               f"vary.activities.{fit.activity}.duration.{param}.sigma",
                               own_rates_min=spread.min_per_user if spread else 10))
        if "omission" in written:
            spread_o = fit.omission_spread
            out.append(_Target(fit.activity, "omission spread",
                               f"vary.activities.{fit.activity}.omission.probability.sd",
                               own_rates_min=spread_o.min_per_user if spread_o else 10))
        base = dotted(("activities", fit.activity))
        family = _family(own.duration)
        if fit.families and family is not None:
            intended = own.intended if fit.wrong_choice is not None else None
            between = 0.0
            if (family == "lognormal" and isinstance(own.duration, LogNormal)
                    and isinstance(fit.distribution, LogNormal)
                    and own.duration.sigma < fit.distribution.sigma - 1e-12):
                between = math.sqrt(fit.distribution.sigma ** 2 - own.duration.sigma ** 2)
            out.append(_Target(fit.activity, "duration", f"{base}.duration", family,
                               intended, between))
        if own.omission is not None:
            spread = fit.omission_spread
            out.append(_Target(fit.activity, "omission", f"{base}.omission.probability",
                               own_rates_min=spread.min_per_user
                               if spread is not None and spread.varies else 0))
        if own.commission is not None and own.intended is not None:
            out.append(_Target(fit.activity, "commission", f"{base}.commission.probability",
                               intended=own.intended))
        loss = fit.wrong_choice
        if loss is not None:
            for alternative in loss.alternatives:
                if result.observations.durations.get(alternative):
                    continue                # its own durations were fitted
                written = model.activities[alternative].duration
                out.append(_Target(fit.activity, "loss",
                                   dotted(("activities", alternative, "duration")),
                                   _family(written) if not isinstance(written, Constant)
                                   else None, intended=own.intended))
    return out


def _rate(events: int, trials: int, rng: np.random.Generator | None) -> float:
    """A rate of ``events`` in ``trials``: the estimate, or (``rng``) a draw from its
    Jeffreys posterior Beta(events + 1/2, trials - events + 1/2) (Chick 2001's posterior
    draws of input parameters). Resampling one person's 20 prompts would give the Wald
    interval's spread, far too narrow with one or two events (Brown, Cai & DasGupta 2001);
    the Jeffreys draws have the coverage of the Jeffreys interval and are not stuck at 0."""
    if rng is None:
        return events / trials
    return float(rng.beta(events + 0.5, trials - events + 0.5))


def _wrong_picks(picks: Sequence[Sequence[str]], intended: str) -> tuple[int, int]:
    """(wrong picks, eligible offers) as :func:`~opspec.usermodels.choice_estimates.choice_model`
    counts them: at most as many wrong picks per instance as the most seen in one."""
    wrong_counts = [sum(1 for c in seq if c != intended) for seq in picks]
    cap = max(wrong_counts, default=0)
    if cap == 0:
        return 0, sum(1 for seq in picks if seq)
    return (sum(min(w, cap) for w in wrong_counts),
            sum(min(len(seq), cap) for seq in picks))


def _values(target: _Target, data: _Data, rng: np.random.Generator | None = None
            ) -> dict[str, float] | None:
    """The parameters ``target`` gives on ``data`` (path -> value); None: cannot be fitted.
    With ``rng`` (observations resampled within persons) rates are posterior draws."""
    from opspec.usermodels.choice_estimates import choice_model

    if target.kind == "duration":
        values = (data.by_pick.get(target.intended, []) if target.intended is not None
                  else data.durations)
        assert target.family is not None
        found = _refit(target.family, values)
        if found is None:
            return None
        if target.between > 0:
            found["sigma"] = math.sqrt(max(found["sigma"] ** 2 - target.between ** 2,
                                           (0.05 * found["sigma"]) ** 2))
        return {f"{target.prefix}.{k}": v for k, v in found.items()}
    if target.kind == "omission":
        if not data.answered:
            return None
        return {target.prefix: _rate(data.omitted, data.answered, rng)}
    if target.kind == "commission":
        if not data.picks:
            return None
        if rng is not None:
            assert target.intended is not None
            wrong, eligible = _wrong_picks(data.picks, target.intended)
            return {target.prefix: _rate(wrong, eligible, rng)} if eligible else None
        model = choice_model(data.picks)
        if model.get("intended") != target.intended:
            return None
        commission = model.get("commission")
        return {target.prefix: commission.probability if commission is not None else 0.0}
    right = data.by_pick.get(target.intended or "", [])
    wrong_times = [v for p, vs in data.by_pick.items() if p != target.intended for v in vs]
    if not right or not wrong_times:
        return None
    if target.family is None:
        # a constant loss is the difference of means, none when the wrong picks were not
        # slower (choice_estimates.wrong_choice_loss): the mean of the losses clipped at 0
        # would put a cost in every redraw that the estimate does not have
        return {f"{target.prefix}.value": max(float(np.mean(wrong_times))
                                              - float(np.mean(right)), 0.0)}
    lost = np.maximum(np.asarray(wrong_times) - float(np.mean(right)), 0.0)
    found = _refit(target.family, lost.tolist())
    return None if found is None else {f"{target.prefix}.{k}": v for k, v in found.items()}


def _own_rates_mean(target: _Target, persons: Sequence[dict[str, _Data]],
                    rng: np.random.Generator | None) -> dict[str, float] | None:
    """A population's omission rate on ``persons`` (one entry per person drawn, repeats
    included): the mean of their own rates, as the fit centres its ``[vary]`` beta; with
    ``rng`` each own rate is a draw from its Jeffreys posterior."""
    rates = [_rate(d.omitted, d.answered, rng) for person in persons
             if (d := person.get(target.activity)) is not None
             and d.answered >= target.own_rates_min]
    return {target.prefix: float(np.mean(rates))} if rates else None


def _spread(target: _Target, persons: Sequence[dict[str, _Data]]) -> dict[str, float] | None:
    """A ``[vary]`` spread on ``persons`` (one entry per person drawn, repeats included),
    estimated as the fit estimates it (:mod:`opspec.usermodels.spread`)."""
    found = _moments(target, persons)
    return None if found is None else {target.prefix: found.between_sd}


def _moments(target: _Target, persons: Sequence[dict[str, _Data]]) -> PersonMoments | None:
    """What ``target``'s between-person spread is estimated from, on ``persons``: their log
    mean durations or their own omission rates (:mod:`opspec.usermodels.spread`)."""
    from opspec.usermodels.spread import duration_moments, omission_moments

    data = [d for person in persons if (d := person.get(target.activity)) is not None]
    if target.kind == "duration spread":
        return duration_moments([d.durations for d in data], min_per_user=target.own_rates_min)
    return omission_moments([(d.omitted, d.answered) for d in data],
                            min_per_user=target.own_rates_min)


@dataclass(frozen=True)
class _PersonLevel:
    """A parameter as the normal random-effects model over persons sees it: the persons' own
    values (log mean durations, own rates) have mean ``centre`` (on the log scale for a
    duration: ``log=True``) and variance ``between² + sampling``, of which ``moments`` holds
    the estimate from ``moments.users`` persons. ``spread`` names a population's
    between-person sd (``[vary]``); None for a parameter everyone shares (one pill time, one
    commission rate for all): then only its centre is drawn."""

    spread: str | None                 # vary.activities.ID.….sigma / .sd; None: no [vary]
    centre: str                        # activities.ID.duration.PARAM / .omission.probability
    estimate: float                    # the centre as fitted
    log: bool
    moments: Any                       # opspec.usermodels.spread.PersonMoments

    def draw(self, rng: np.random.Generator) -> dict[str, float]:
        """One draw of (centre, between-person sd) from their posterior under the
        reference prior p(centre, V) ∝ 1/V of V = between² + sampling (Gelman et al.,
        *Bayesian Data Analysis*, 3rd ed., §3.2): V = (P - 1) s² / χ²(P - 1), the centre
        normal around its estimate with variance V / P, the between-person variance what V
        leaves above the sampling part. Its predictive for the mean of a new group is
        Student's t — the classical prediction interval of a future sample's mean."""
        m = self.moments
        persons = m.users
        total = (persons - 1) * m.observed / max(float(rng.chisquare(persons - 1)), 1e-12)
        shift = math.sqrt(total / persons) * float(rng.standard_normal())
        if self.log:
            centre = self.estimate * math.exp(shift)
        else:
            centre = min(max(self.estimate + shift, 1e-6), 1 - 1e-6)
        if self.spread is None:
            return {self.centre: centre}
        return {self.spread: math.sqrt(max(total - m.sampling, 0.0)), self.centre: centre}


@dataclass(frozen=True)
class _RateLevel:
    """A rate over persons (a population's omission centre and spread, or a rate everyone
    shares: its centre only) drawn from the posterior of the hierarchical beta-binomial
    model of the persons' counts (:mod:`opspec.usermodels.rate_posterior`), not from the
    normal model of their own rates: own rates near 0 are skewed, their mean and variance
    go together, and the normal model's draws are then too narrow exactly when the
    estimate came out low."""

    spread: str | None
    centre: str
    posterior: RatePosterior

    def draw(self, rng: np.random.Generator) -> dict[str, float]:
        mean, sd = self.posterior.draw(rng)
        if self.spread is None:
            return {self.centre: mean}
        return {self.spread: sd, self.centre: mean}


@dataclass(frozen=True)
class _SharedRate:
    """A rate everyone shares (no ``[vary]``): its value drawn from the Jeffreys posterior of
    the pooled counts, Beta(k + 1/2, n - k + 1/2) (Chick 2001; Brown, Cai & DasGupta 2001).

    The model says every person has this one rate, so the persons' counts are one binomial
    sample of it and the pooled posterior is the whole uncertainty. The hierarchical
    beta-binomial posterior (:class:`_RateLevel`) would let thirty alike persons' alikeness
    be uncertain (``alpha + beta`` loosely fixed), which stretches the draws' upper tail
    beyond what the counts warrant: groups of new people who slip *less* than the estimate
    were then called a misfit too often (docs/fitting.md, what the check can detect)."""

    centre: str
    events: int
    trials: int
    spread: None = None                # no between-person spread to draw

    def draw(self, rng: np.random.Generator) -> dict[str, float]:
        return {self.centre: float(rng.beta(self.events + 0.5,
                                            self.trials - self.events + 0.5))}


def _shared_rate(centre: str, counts: Sequence[tuple[int, int]]) -> _SharedRate | None:
    events = sum(int(k) for k, n in counts if n > 0)
    trials = sum(int(n) for _, n in counts if n > 0)
    return _SharedRate(centre, events, trials) if trials > 0 else None


def _rate_level(spread: str | None, centre: str, counts: Sequence[tuple[int, int]]
                ) -> _RateLevel | None:
    from opspec.usermodels.rate_posterior import rate_posterior

    posterior = rate_posterior(counts)
    return None if posterior is None else _RateLevel(spread, centre, posterior)


def _shared_level(target: _Target, persons: Sequence[dict[str, _Data]],
                  estimate: dict[str, float]) -> _PersonLevel | _SharedRate | None:
    """A parameter without a population whose centre is drawn as a population's is: a
    lognormal's median (not a choice's intended-pick time) and a rate everyone shares.

    Why not the percentile bootstrap of persons: its draws of a mean have normal tails and
    (P - 1)/P of its variance — at 30 persons the predictive of a new group's mean is then
    narrower than Student's t in exactly the tails Holm reaches into (p <= 0.0125 of four
    items). The spread of the persons' own values (which holds the sampling error whether or
    not people differ) gives the t-based posterior instead; a shared rate comes from the
    Jeffreys posterior of the pooled counts (:class:`_SharedRate`)."""
    from opspec.usermodels.spread import duration_moments

    data = [d for person in persons if (d := person.get(target.activity)) is not None]
    if (target.kind == "duration" and target.family == "lognormal" and target.between == 0
            and target.intended is None):
        centre = f"{target.prefix}.median"
        moments = duration_moments([d.durations for d in data])
    elif target.kind == "commission" and target.intended is not None:
        if target.prefix not in estimate:
            return None
        return _shared_rate(target.prefix,
                            [_wrong_picks(d.picks, target.intended) for d in data])
    elif target.kind == "omission" and not target.own_rates_min:
        if target.prefix not in estimate:
            return None
        return _shared_rate(target.prefix, [(d.omitted, d.answered) for d in data])
    else:
        return None
    if moments is None or moments.observed <= 0 or centre not in estimate:
        return None
    return _PersonLevel(None, centre, estimate[centre], target.kind == "duration", moments)


def _person_levels(targets: Sequence[_Target], persons: Sequence[dict[str, _Data]],
                   estimate: dict[str, float], shared: bool
                   ) -> list[_PersonLevel | _RateLevel | _SharedRate]:
    """The parameters whose centre (and a population's spread) are drawn from their
    posterior; ``shared``: those without a population too (enough persons to resample)."""
    out: list[_PersonLevel | _RateLevel | _SharedRate] = []
    for target in targets:
        if not target.kind.endswith(" spread"):
            continue
        centre = target.prefix.removeprefix("vary.").rsplit(".", 1)[0]
        if target.kind == "omission spread":
            if centre not in estimate:
                continue
            rate = _rate_level(target.prefix, centre, [
                (d.omitted, d.answered) for person in persons
                if (d := person.get(target.activity)) is not None
                and d.answered >= target.own_rates_min])
            if rate is not None:
                out.append(rate)
            continue
        moments = _moments(target, persons)
        if moments is None or centre not in estimate or moments.observed <= 0:
            continue
        out.append(_PersonLevel(target.prefix, centre, estimate[centre],
                                target.kind == "duration spread", moments))
    varied = {t.activity for t in targets if t.kind.endswith(" spread")}
    for target in targets if shared else ():
        if target.activity in varied and target.kind in ("duration", "omission"):
            continue                    # a population's centre: drawn above
        level = _shared_level(target, persons, estimate)
        if level is not None:
            out.append(level)
    return out


def _per_person(result: FitResult, activities: Sequence[str]) -> dict[str, dict[str, _Data]]:
    obs = result.observations
    people: dict[str, dict[str, _Data]] = {p: {} for p in obs.persons}

    def data(session: tuple[int, int], activity: str) -> _Data:
        return people.setdefault(obs.person(session), {}).setdefault(activity, _Data())

    for activity in activities:
        for session, values in obs.user_durations.get(activity, {}).items():
            data(session, activity).durations.extend(values)
        for session, (k, n) in obs.user_omissions.get(activity, {}).items():
            d = data(session, activity)
            d.omitted += k
            d.answered += n
        for session, sequences in obs.user_picks.get(activity, {}).items():
            data(session, activity).picks.extend(sequences)
        for pick, per_session in obs.user_pick_durations.get(activity, {}).items():
            for session, values in per_session.items():
                data(session, activity).by_pick.setdefault(pick, []).extend(values)
    return {p: d for p, d in people.items() if d}


def parameter_draws(result: FitResult, draws: int, *, seed: int = 0) -> ParameterDraws | None:
    """``draws`` bootstrap redraws of the fitted parameters of ``result`` (None when the model
    has no fitted parameter to redraw: only constants). Same traces and seed, same draws."""
    targets = _targets(result)
    if not targets or draws < 1:
        return None
    # every order below is fixed (sorted, or as first seen in the traces): the same traces
    # and seed draw the same resamples whatever the hash seed of the process
    activities = sorted({t.activity for t in targets})
    people = _per_person(result, activities)
    names = list(people)
    whole = {a: _Data() for a in activities}
    for person in names:
        for activity, d in people[person].items():
            whole[activity].add(d)
    estimate: dict[str, float] = {}

    def values(target: _Target, data: _Data, persons: Sequence[dict[str, _Data]],
               draw: np.random.Generator | None) -> dict[str, float] | None:
        if target.kind.endswith(" spread"):
            return _spread(target, persons)
        if target.own_rates_min:
            return _own_rates_mean(target, persons, draw)
        if target.kind == "duration" and target.between > 0 and spread_of.get(target.activity):
            # the within-person sigma is what the resample's between-person part leaves
            found = _spread(spread_of[target.activity], persons)
            if found:
                target = replace(target, between=next(iter(found.values())))
        return _values(target, data, draw)

    spread_of = {t.activity: t for t in targets if t.kind == "duration spread"}

    everyone = [people[p] for p in names]
    for target in targets:
        found = values(target, whole[target.activity], everyone, None)
        if found is not None:
            estimate.update(found)
    parameters = tuple(estimate)
    if not parameters:
        return None
    by_persons = len(names) >= MIN_PERSONS
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), _STREAM]))
    # a population's centres and spreads: drawn from their posterior (_PersonLevel.draw),
    # not resampled — a percentile bootstrap of 30 persons centres a between-person variance
    # at (P-1)/P of a downward-biased estimate and lacks the long upper tail a variance
    # estimated from 30 persons has: groups of new people simulated under it are too alike
    # (docs/fitting.md, what the check can detect); so are the centres of the parameters
    # everyone shares (a pill time, a commission rate), whose bootstrap lacks Student's tails
    levels = _person_levels(targets, everyone, estimate, by_persons)
    drawn = {path for level in levels for path in (level.spread, level.centre) if path}
    level_rng = np.random.default_rng(np.random.SeedSequence([int(seed), _STREAM, 1]))
    rows = []
    failed = 0
    for _ in range(draws):
        sample = {a: _Data() for a in whole}
        if by_persons:
            chosen = [people[names[i]] for i in rng.integers(0, len(names), len(names))]
        else:
            chosen = [{a: d.within(rng) for a, d in people[p].items()} for p in names]
        for person in chosen:
            for activity, d in person.items():
                sample[activity].add(d)
        row = dict(estimate)
        for target in targets:
            if target.prefix in drawn:
                continue
            found = values(target, sample[target.activity], chosen,
                           None if by_persons else rng)
            if found is None:
                failed += 1
                continue
            row.update({k: v for k, v in found.items() if k in row and k not in drawn})
        for level in levels:
            row.update(level.draw(level_rng))
        rows.append(tuple(row[p] for p in parameters))
    # a parameter every resample gives the same (a constant loss) is no uncertainty
    keep = [i for i in range(len(parameters)) if any(r[i] != estimate[parameters[i]]
                                                     for r in rows)]
    if not keep:
        return None
    parameters = tuple(parameters[i] for i in keep)
    rows = [tuple(r[i] for i in keep) for r in rows]
    obs = result.observations
    resampled = ("persons" if by_persons else "observations within each person")
    source = (f"opspec fit: {draws} nonparametric bootstrap redraws (Barton & Schruben 2001) "
              f"resampling {resampled} ({len(names)} person(s), {obs.sessions} session(s); "
              f"Davison & Hinkley 1997, 3.8), each fitted as the data were (family kept)"
              + ("; centres and between-person spreads drawn from their posterior over "
                 "persons (Gelman et al. 2013: 3.2 for times, 5.3's beta-binomial for "
                 "a population's rate)" if levels else "")
              + ("; a rate everyone shares drawn from the Jeffreys posterior of its pooled "
                 "counts" if any(isinstance(level, _SharedRate) for level in levels) else "")
              + ("" if by_persons else "; rates drawn from their Jeffreys posterior "
                 "(Chick 2001)")
              + (f"; {failed} parameter fit(s) of a resample failed and kept the estimate"
                 if failed else ""))
    return ParameterDraws(parameters, tuple(estimate[p] for p in parameters), tuple(rows),
                          method="bootstrap", resampled=resampled, persons=len(names),
                          sessions=obs.sessions, seed=int(seed), source=source)
