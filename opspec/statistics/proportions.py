"""The interval of a proportion pooled over users: missed of due doses (docs/evaluation.md,
"Rare events"; method ``"wilson-neff"`` of :mod:`opspec.statistics.methods`).

Users are clusters of trials (the doses of one person are not independent when people
differ), and the events are often rare (a missed dose in 300). Both are handled the way the
survey literature handles clustered proportions: a score interval, which stays right with
few or no events, on the *effective* number of trials, Kish's ``n / deff``, with the design
effect estimated from the between-user (cluster-robust) variance:
:func:`proportion_interval` is Wilson's (1927) score interval on the effective trials (Korn &
Graubard 1998; Franco, Little, Louis & Slud 2019).

Which ratio is a proportion is the spec's declaration (``Proportion="true"``), not a test of
the numbers (:mod:`opspec.statistics.ratios`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from opspec.statistics.clustered import ratio_variance
from opspec.statistics.intervals import normal_quantile, t_quantile

__all__ = ["effective_trials", "proportion_interval"]

Pairs = Sequence[tuple[float, float]]


def _wilson(p: float, n: float, z: float) -> tuple[float, float]:
    """Wilson's (1927) score interval of a proportion ``p`` observed on ``n`` trials (``n``
    need not be whole: an effective sample size), with normal quantile ``z``."""
    a = z * z / n
    centre = (p + a / 2) / (1 + a)
    half = z * math.sqrt(p * (1 - p) / n + a / (4 * n)) / (1 + a)
    return (0.0 if p <= 0 else max(0.0, centre - half),
            1.0 if p >= 1 else min(1.0, centre + half))


def effective_trials(pairs: Pairs, level: float = 0.95) -> float:
    """How many independent trials the users' pooled trials are worth (Kish's effective
    sample size ``n/deff``): ``p(1-p) / v``, where ``v`` is the binomial variance of the
    pooled proportion ``p`` plus the between-user excess of the cluster-robust variance over
    it, scaled by ``(t[U-1]/z)²`` because it is estimated from only U users (Korn &
    Graubard's 1998 degrees-of-freedom adjustment, applied to the part of the variance that
    is estimated). At most the pooled trials: Korn & Graubard truncate the design effect at
    1, since users who look more alike than chance would make them do not make a trial
    worth more than one. The pooled trials when ``p`` is 0 or 1 or there are fewer than 2
    users (nothing to estimate the excess from)."""
    trials = math.fsum(n for _, n in pairs)
    p = math.fsum(y for y, _ in pairs) / trials
    estimated = ratio_variance(pairs)
    if not 0 < p < 1 or estimated is None:
        return trials
    independent = p * (1 - p) / trials
    df_factor = (t_quantile(level, len(pairs) - 1) / normal_quantile(0.5 + level / 2)) ** 2
    return trials * independent / (independent
                                   + df_factor * max(estimated[1] - independent, 0.0))


#: Brown, Cai & DasGupta's (2001) modification of Wilson's interval near 0 (and n): with 1 or
#: 2 events the score interval's lower bound (about 0.18/n for one event) is above rates a
#: single event is quite compatible with, and coverage of a rate of 0.15 events per
#: evaluation falls to 87 %; their modified Wilson takes the one-sided Poisson bound λ_x/n
#: there (0.051/n and 0.355/n at 95 %). They use it up to x = 3 for n of 51-100; with the
#: hundreds to millions of trials of an evaluation x = 3 would lift the coverage of the
#: reference user's missed rate over 7 days at 10 users from 94 % to 98 %
#: (benchmarks/proportion_coverage.py), so it stops at 2.
MODIFIED_WILSON_EVENTS = 2


def _poisson_lower(events: int, level: float) -> float:
    """λ with P(Poisson(λ) >= events) = 1 - level: the one-sided Poisson lower bound."""
    from scipy import special  # type: ignore[import-untyped]  # chi2.ppf(q, 2k)/2, exactly

    return float(special.gammaincinv(events, 1 - level))


def proportion_interval(pairs: Pairs, level: float = 0.95) -> list[float | None]:
    """The interval of a pooled proportion ``Σy/Σn`` over users (events out of trials per
    user): Wilson's score interval on the effective number of trials
    (:func:`effective_trials`), with Brown, Cai & DasGupta's modification for 1 or 2 events
    (or non-events; :data:`MODIFIED_WILSON_EVENTS`): the bound near 0 is at most
    ``λ_x / Σn``. With users who differ only by chance it is the (modified) Wilson interval
    of the pooled trials, right for rare events and never [0, 0] (0 of 40: [0 %, 8.76 %]);
    when users differ (overdispersion) it widens by the design effect, and as the
    between-user variance dominates it tends to the cluster-robust interval with Korn &
    Graubard's degrees of freedom. ``[None, None]`` without trials."""
    trials = math.fsum(n for _, n in pairs)
    if trials <= 0:
        return [None, None]
    events = math.fsum(y for y, _ in pairs)
    p = events / trials
    low, high = _wilson(p, effective_trials(pairs, level), normal_quantile(0.5 + level / 2))
    if 1 <= events <= MODIFIED_WILSON_EVENTS:
        low = min(low, _poisson_lower(int(events), level) / trials)
    if 1 <= trials - events <= MODIFIED_WILSON_EVENTS:
        high = max(high, 1 - _poisson_lower(int(trials - events), level) / trials)
    return [low, high]
