"""Estimating a user model from recorded traces (``opspec fit TRACE... -o model.toml``).

Input: JSON Lines trace files (``docs/trace-format.md``, read by
:mod:`opspec.usermodels.trace_reader`), whose offers and answers for the lane being fitted
are paired per (run, instance, activity) by :mod:`opspec.usermodels.observations`.

Estimated, per activity:

* duration (offer to completion): every family by maximum likelihood, the one with the lowest
  AIC (or BIC) written, the comparison written as a comment above the activity's table
  (:mod:`opspec.usermodels.duration_family`);
* omission rate (omissions / answered offers, omissions with reason ``busy`` excluded) with
  a Wilson 95 % interval;
* choices: an intended alternative with a commission rate when every instance ends on the
  same alternative, fixed probabilities otherwise, and the time a wrong pick costs
  (:mod:`opspec.usermodels.choice_estimates`);
* busy: activities in progress in another instance when a prompt was omitted as ``busy``;
* how much people differ (:mod:`opspec.usermodels.spread`), written as ``[vary]`` tables
  (:meth:`~opspec.usermodels.fit_report.FitResult.vary`) when they do: a lognormal's sigma
  is then a person's own, and the omission rate the mean of the persons' own rates.

:func:`fit_traces` does it; what it says about each activity is
:mod:`opspec.usermodels.fit_report`. The names of those modules stay importable from here.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from opspec.errors import UserModelError
from opspec.statistics import rate_interval
from opspec.usermodels.choice_estimates import WrongChoiceLoss, choice_model, wrong_choice_loss
from opspec.usermodels.distributions import LogNormal
from opspec.usermodels.duration_family import fit_duration, fit_duration_families
from opspec.usermodels.errors import Busy, Omission
from opspec.usermodels.families import CRITERIA
from opspec.usermodels.fit_report import ActivityFit, FitResult
from opspec.usermodels.model import ActivityModel, UserModel
from opspec.usermodels.observations import Observations, collect
from opspec.usermodels.persons import PersonRule
from opspec.usermodels.spread import duration_spread, omission_spread
from opspec.usermodels.trace_reader import iter_paths, read_trace

__all__ = [
    "ActivityFit",
    "FitResult",
    "Observations",
    "WrongChoiceLoss",
    "collect",
    "fit_duration",
    "fit_traces",
    "iter_paths",
    "read_trace",
]

#: the name opspec.usermodels.bootstrap imports it by
_choice_model = choice_model


def fit_traces(paths: Sequence[str | Path], *, lane: str = "user", name: str = "fitted",
               criterion: str = "aic", min_per_user: int = 10,
               persons: PersonRule | None = None) -> FitResult:
    """Fit a :class:`UserModel` for ``lane`` from the trace files ``paths``: per activity the
    best duration family by ``criterion`` (``aic`` or ``bic``), omission rates, choices with
    the time a wrong pick costs, and the between-user spread of persons with at least
    ``min_per_user`` observations (``persons`` says whose each session is: several sessions
    of one participant are one person; :mod:`opspec.usermodels.persons`)."""
    if not paths:
        raise UserModelError("no trace files given", hint="opspec fit TRACE... -o model.toml")
    if criterion not in CRITERIA:
        raise UserModelError(f"unknown selection criterion {criterion!r}",
                             hint="use --criterion aic or --criterion bic")
    if persons is not None:
        persons.check_used([Path(p) for p in paths])
    obs = collect(paths, lane, persons)
    origin = f"{len(paths)} trace file(s), {obs.events} events"
    activities: dict[str, ActivityModel] = {}
    fits = []
    losses: dict[str, WrongChoiceLoss] = {}
    for activity in obs.activities:
        values = obs.durations.get(activity, [])
        kwargs: dict[str, Any] = {}
        wrong_choice = None
        if obs.picks.get(activity):
            kwargs.update(choice_model(obs.picks[activity]))
            intended = kwargs.get("intended")
            if intended is not None and activity in obs.pick_durations:
                wrong_choice = wrong_choice_loss(activity, intended,
                                                 obs.pick_durations[activity], criterion)
                if wrong_choice is not None:
                    # the choice's own duration: the intended picks only
                    values = obs.pick_durations[activity][intended]
                    for alternative in wrong_choice.alternatives:
                        losses[alternative] = wrong_choice
        dist, chosen, families, note = fit_duration_families(values, criterion)
        if not values and obs.unusable.get(activity):
            note = (f"no duration timed in real time ({obs.unusable[activity]} completion(s) "
                    "left out): duration 0")
        omitted = obs.omitted.get(activity, 0)
        # every offer answered, by an omission or a completion, timed in real time or not:
        # a walkthrough answer whose duration is left out still answered its offer (without
        # it, 6 omissions beside 24 untimed completions were written as a rate of 6/6)
        answered = sum(n for _, n in obs.user_omissions.get(activity, {}).values())
        omission_stats = None
        kwargs["duration"] = dist
        if omitted:
            _, low, high = rate_interval(omitted, answered)
            lo_hi = (low, high)
            omission_stats = (omitted, answered, lo_hi)
            kwargs["omission"] = Omission(
                omitted / answered, source=f"fitted: {omitted}/{answered} omitted, Wilson 95 % "
                f"interval [{lo_hi[0]:.4f}, {lo_hi[1]:.4f}]")
        by = criterion.upper()
        scores = ", ".join(f"{f.family} {by} {f.score(criterion):.2f}"
                           for f in sorted(families, key=lambda f: f.score(criterion)))
        kwargs["source"] = (f"fitted by opspec fit from {origin}: n = {len(values)}, "
                            f"{chosen}" + (f" by {by} ({scores})" if families else ""))
        spread_d = duration_spread(obs.lists_by_person(obs.user_durations.get(activity, {})),
                                   min_per_user=min_per_user,
                                   family=chosen if families else None)
        if (isinstance(dist, LogNormal) and spread_d is not None
                and spread_d.between_sd_ci[0] > 0 and 0 < spread_d.between_sd < dist.sigma):
            # the pooled sigma holds both within- and between-user spread; the person-level
            # median varies with between_sd (the [vary] table), so one person's own sigma is
            # the rest, and the population's spread stays what was observed
            within = math.sqrt(dist.sigma ** 2 - spread_d.between_sd ** 2)
            kwargs["duration"] = LogNormal(dist.mu, within)
            note = (note + "; " if note else "") + (
                f"sigma {within:.4g} within a user, {spread_d.between_sd:.4g} between users")
        spread_o = omission_spread(obs.counts_by_person(obs.user_omissions.get(activity, {})),
                                   min_per_user=min_per_user) if omitted else None
        if spread_o is not None and spread_o.varies:
            # people differ: the rate a person has is drawn around the mean of the people's
            # own rates, not the pooled one (a missed prompt is offered again, so the pooled
            # rate weighs the forgetful more than the population draws them)
            kwargs["omission"] = replace(
                kwargs["omission"], probability=spread_o.mean,
                source=f"fitted: mean of {spread_o.users} persons' own rates "
                f"(pooled {omitted}/{answered} = {omitted / answered:.4f})")
        activities[activity] = ActivityModel(**kwargs)
        fits.append(ActivityFit(activity, len(values), dist, chosen,
                                {f.family: f.aic for f in families}, omission_stats, note,
                                families, criterion, spread_d, spread_o, wrong_choice))
    for alternative, loss in losses.items():
        if obs.durations.get(alternative):
            continue           # performed as its own activity: its own durations stand
        old = activities.get(alternative, ActivityModel())
        activities[alternative] = replace(
            old, duration=loss.distribution,
            source=f"fitted by opspec fit: the time a wrong pick at {loss.choice} costs, "
            f"{max(loss.seconds, 0.0):.4g} s on average ({loss.wrong} wrong picks"
            + ("" if loss.seconds > 0 else f"; the difference of means, {loss.seconds:.4g} s, "
               "is not above 0") + ")")
    busy = None
    if obs.busy_omitted:
        engaged = obs.engaged or set(obs.durations) - set(obs.busy_omitted)
        busy = Busy(frozenset(engaged), ignore=frozenset(obs.busy_omitted),
                    source=f"fitted: {sum(obs.busy_omitted.values())} prompt(s) ignored "
                    "while busy in another instance")
    model = UserModel(name=name, activities=activities, busy=busy,
                      description=f"Fitted from {origin} (lane {lane!r}).",
                      source=f"opspec fit on {', '.join(str(p) for p in paths[:5])}"
                      + (" ..." if len(paths) > 5 else ""))
    return FitResult(model, tuple(fits), obs)
