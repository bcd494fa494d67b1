"""The duration check of a model check: held-out people's durations of one activity against
the model's predictive distribution.

The statistic is Anderson-Darling's A² of all held-out durations against the predictive
distribution (a large sample of it, as an empirical CDF: :data:`REFERENCE_SIZE`), calibrated
by a *parametric bootstrap*: the same statistic for each replicate group of
:class:`~opspec.usermodels.predictive_people.PredictivePeople` (same number of people, same
number of observations each). Its p-value is ``(1 + #{A²_rep >= A²_obs}) / (replicates + 1)``
(Davison & Hinkley 1997, §4.2): valid whatever the reference CDF, because observed and
simulated groups are measured alike, and it counts a population's between-person spread and
the parameters' estimation uncertainty as what they are — variation the model predicts.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from opspec.usermodels.check_report import CheckItem
from opspec.usermodels.predictive_people import PredictivePeople, item_stream

if TYPE_CHECKING:
    from opspec.usermodels.model import ActivityModel, UserModel

__all__ = ["REFERENCE_SIZE", "anderson_darling", "check_duration", "sample_durations"]

#: size of the pooled predictive sample a duration is compared with (its empirical CDF)
REFERENCE_SIZE = 20_000
#: probabilities at which the QQ figure compares quantiles
_QQ_POINTS = np.linspace(0.02, 0.98, 49)


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


def check_duration(activity: str, observed: Mapping[str, Sequence[float]],
                   people: PredictivePeople, seed: int) -> CheckItem | str:
    """The parametric-bootstrap Anderson-Darling check of one activity's durations (a note
    instead when the model says one constant and every observation is that constant)."""
    rng = item_stream(seed, f"duration/{activity}")
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
