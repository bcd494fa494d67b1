"""Checking a user model against people it was not fitted on (``opspec model-check``).

The question, per user-lane activity: does what these people did fall inside what the model
predicts for people like them? "People like them" is the model's *predictive* distribution
(:mod:`opspec.usermodels.predictive_people`):

1. when the model file carries ``[uncertainty]`` (a fitted model's bootstrap redraws of its
   parameters), each replicate group of people uses one redraw — the model was estimated
   from a finite sample, and a check that ignored it would flag the estimation error of a
   correct model as a misfit as soon as the held-out people are many;
2. each simulated person is drawn from the population (``[vary]``, subgroups): people differ,
   and their observations are not independent of each other;
3. that person's observations are drawn from their own model, as many as the real person
   has.

**Durations** (per activity, :mod:`opspec.usermodels.duration_check`): the Anderson-Darling
statistic of all held-out durations against the predictive distribution, calibrated by a
parametric bootstrap over the replicate groups.

**Rates** (omission per offer, commission per eligible pick at a choice, repetition per
completion; :mod:`opspec.usermodels.rate_check`): with one rate for everyone, the pooled
count against the exact binomial; when people differ, the mean of the people's own rates
against its predictive distribution.

**Family-wise error**: Holm's step-down adjustment over every item checked
(:mod:`opspec.usermodels.holm`); an item misfits when its adjusted p-value is at most the
level (:func:`finish`, with the items and the report in :mod:`opspec.usermodels.check_report`).

This module runs the checks an activity's observations call for
(:func:`check_observations`) and counts the decisions a trace records
(:func:`count_decisions`); the names of the modules above stay importable from here.

Not in these checks (said in the output): the model's routine (time-of-day windows,
adherence drift) — it changes durations and rates by time of day, which a per-activity
check pools; the outcome metrics of a spec run with ``--spec`` check them as a whole.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from opspec.usermodels.check_report import CheckItem, CheckReport, finish
from opspec.usermodels.duration_check import (
    REFERENCE_SIZE,
    anderson_darling,
    check_duration,
    sample_durations,
)
from opspec.usermodels.predictive_people import POOL_SIZE, PredictivePeople
from opspec.usermodels.rate_check import (
    RATE_GROUPS,
    RateGroups,
    check_rate,
    commission_counts,
    rate_item,
)

if TYPE_CHECKING:
    from opspec.usermodels.model import UserModel
    from opspec.usermodels.observations import Observations
    from opspec.usermodels.uncertainty import ParameterDraws

__all__ = [
    "POOL_SIZE",
    "RATE_GROUPS",
    "REFERENCE_SIZE",
    "CheckItem",
    "CheckReport",
    "PredictivePeople",
    "RateGroups",
    "anderson_darling",
    "check_duration",
    "check_observations",
    "check_rate",
    "commission_counts",
    "count_decisions",
    "finish",
    "sample_durations",
]


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
    picked = {a for sequences in obs.picks.values() for seq in sequences for a in seq}
    alternatives = {a for am in model.activities.values() for a in am.choice_ids()}
    unseen = sorted(set(model.activities) - set(activities) - picked - alternatives)
    if unseen:
        # a verdict over what was seen says nothing of these: traces of another spec, or
        # of another lane, would otherwise "fit" on the few activities the two share
        notes.append("in the model but not in these traces (not checked): "
                     + ", ".join(unseen))
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
            items.append(rate_item("omission", activity, omissions, model, people, draws,
                                   seed))
        if am.intended is not None and obs.user_picks.get(activity):
            cap = am.commission.max_per_instance if am.commission is not None else 1
            by_person = obs.lists_by_person(obs.user_picks[activity])
            counts = {p: commission_counts(seqs, am.intended, cap)
                      for p, seqs in by_person.items()}
            if am.commission is not None or any(w for w, _ in counts.values()):
                items.append(rate_item("commission", activity, counts, model, people,
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
                items.append(rate_item("repetition", activity, counts, model, people,
                                       draws, seed))
    return items, notes


def count_decisions(paths: Sequence[Any], obs: Observations, kind: str = "user.repeated"
                    ) -> tuple[dict[str, dict[str, int]], bool]:
    """Per activity, per person: how many ``kind`` events the traces hold (sessions mapped
    to persons as ``obs`` maps them); and whether any ``user.*`` decision event was seen."""
    from opspec.engine.trace import EventKind
    from opspec.usermodels.trace_reader import read_trace

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
