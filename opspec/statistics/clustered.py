"""Ratios over users, the independent replications of an evaluation: ``Σy/Σn`` with the
cluster-robust (delta-method) Student-t interval, and the paired difference of two designs on
the same users (docs/evaluation.md, *Statistics*)."""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any

from opspec.statistics.intervals import poisson_interval, t_quantile

__all__ = ["RARE_DISCORDANT", "RARE_EVENTS", "RatioEstimate", "ValuesAsPairs", "count_estimate",
           "count_estimate_from_sums",
           "hazard_estimate", "paired_difference", "paired_variance", "ratio_estimate",
           "ratio_variance", "unpaired_difference"]


@dataclass(frozen=True, slots=True)
class RatioEstimate:
    """``Σy/Σn`` over users with its interval; ``users`` counts those contributing
    (``n_u > 0``). ``None`` where there is nothing to estimate."""

    value: float | None
    low: float | None
    high: float | None
    users: int
    #: the id of the interval's method (:data:`opspec.statistics.methods.METHODS`); None
    #: when there is no interval
    method: str | None = "t"

    @property
    def ci(self) -> list[float | None]:
        return [self.low, self.high]


Pairs = Sequence[tuple[float, float]]


class ValuesAsPairs(Sequence[tuple[float, float]]):
    """``(v, 1.0)`` for each of ``values``: one value per user as a ratio's pair (the t
    interval of a mean is :func:`ratio_estimate` of them), made as they are read, so that
    no tuple per user is held (``values`` may be read from disk at each pass)."""

    __slots__ = ("values",)

    def __init__(self, values: Sequence[float]) -> None:
        self.values = values

    def __len__(self) -> int:
        return len(self.values)

    def __iter__(self) -> Iterator[tuple[float, float]]:
        return ((v, 1.0) for v in self.values)

    def __getitem__(self, index: Any) -> Any:
        if isinstance(index, slice):
            return [(v, 1.0) for v in self.values[index]]
        return self.values[index], 1.0


def ratio_variance(pairs: Pairs) -> tuple[float, float] | None:
    """``(r, v)``: ``r = Σy/Σn`` and its cluster-robust (delta-method) variance
    ``Σ(y_u − r·n_u)² / (U·(U−1)·n̄²)``; None without two users or any denominator."""
    users = len(pairs)
    total_n = math.fsum(n for _, n in pairs)
    if users < 2 or total_n <= 0:
        return None
    r = math.fsum(y for y, _ in pairs) / total_n
    resid = math.fsum((y - r * n) ** 2 for y, n in pairs)
    return r, resid / (users * (users - 1)) / (total_n / users) ** 2


def paired_variance(a: Pairs, b: Pairs) -> tuple[float, float] | None:
    """``(r_B − r_A, v)`` on the same users (same order): ``v`` the variance of the mean of
    the per-user linearised differences ``(y_Bu − r_B·n_Bu)/n̄_B − (y_Au − r_A·n_Au)/n̄_A``;
    None without two users or a denominator in either design."""
    if len(a) != len(b):
        raise ValueError("paired designs need the same users")
    ea, eb = ratio_variance(a), ratio_variance(b)
    if ea is None or eb is None:
        return None
    users = len(a)
    nbar_a = math.fsum(n for _, n in a) / users
    nbar_b = math.fsum(n for _, n in b) / users
    z = [(yb - eb[0] * nb) / nbar_b - (ya - ea[0] * na) / nbar_a
         for (ya, na), (yb, nb) in zip(a, b, strict=True)]
    mean_z = math.fsum(z) / users
    return eb[0] - ea[0], math.fsum((v - mean_z) ** 2 for v in z) / (users - 1) / users


def unpaired_difference(a: Pairs, b: Pairs, level: float = 0.95) -> RatioEstimate:
    """``r_B − r_A`` as if the two designs had run on different users: their cluster-robust
    variances added, with Welch's degrees of freedom (method ``"welch-t"``). Beside the
    paired interval it shows what common random numbers gained."""
    ea, eb = ratio_variance(a), ratio_variance(b)
    if ea is None or eb is None:
        return RatioEstimate(None, None, None, 0, None)
    diff, spread = eb[0] - ea[0], math.sqrt(ea[1] + eb[1])
    if spread == 0.0:
        return RatioEstimate(diff, diff, diff, len(a), "welch-t")
    df = spread ** 4 / ((ea[1] ** 2 + eb[1] ** 2) / (len(a) - 1))
    half = t_quantile(level, max(1, int(df))) * spread
    return RatioEstimate(diff, diff - half, diff + half, len(a), "welch-t")


def ratio_estimate(pairs: Pairs, level: float = 0.95) -> RatioEstimate:
    """Users are the independent replications; observations within a user are not (one slow
    walker has many slow doses). Each user ``u`` gives a pair ``(y_u, n_u)`` — a count:
    (total, 1); a duration: (sum of observations, number of them); a ratio: (numerator,
    denominator) — and the estimate is ``r = Σy/Σn`` with the cluster-robust (delta-method)
    standard error ``se(r)² = Σ (y_u − r·n_u)² / (U·(U−1)·n̄²)``, ``n̄ = Σn/U``, and a
    Student-t interval on U−1 degrees of freedom (for counts exactly the t interval of the
    per-user mean). ``None`` values when Σn is 0; no interval with fewer than 2 users."""
    users = len(pairs)
    total_n = math.fsum(n for _, n in pairs)
    if users == 0 or total_n <= 0:
        return RatioEstimate(None, None, None, 0, None)
    contributing = sum(1 for _, n in pairs if n > 0)
    estimated = ratio_variance(pairs)
    if estimated is None:
        return RatioEstimate(math.fsum(y for y, _ in pairs) / total_n, None, None,
                             contributing, None)
    r, variance = estimated
    half = t_quantile(level, users - 1) * math.sqrt(variance)
    low = r - half
    if low < 0.0 and all(y >= 0.0 for y, _ in pairs):
        # counts, durations and ratios of counts cannot be negative; with few users the t
        # interval would say they might be (a count of collisions "from -1.3 to 7.8")
        low = 0.0
    return RatioEstimate(r, low, r + half, contributing)


#: Fewer discordant events than this (events one design has and the other has not, summed
#: over users) and a paired difference of counts is not left to the t interval: with a
#: handful of events the per-user differences are mostly zero and the t interval is too
#: narrow (89 % coverage at 10 users, ``benchmarks/interval_coverage.py``) or [0, 0].
RARE_DISCORDANT = 10


def _discordant(a: Pairs, b: Pairs) -> tuple[int, int, float] | None:
    """``(up, down, N)`` when both designs count whole events over the same denominators
    (``n_A,u == n_B,u``: a count per user, or a ratio of counts such as missed/due): ``up``
    events more in B than in A summed over users, ``down`` fewer, ``N = Σn``. None when the
    pairs are not counts (durations)."""
    up = down = 0
    total = 0.0
    for (ya, na), (yb, nb) in zip(a, b, strict=True):
        if na != nb or ya < 0 or yb < 0 or ya != int(ya) or yb != int(yb):
            return None
        diff = int(yb) - int(ya)
        up += max(diff, 0)
        down += max(-diff, 0)
        total += na
    return (up, down, total) if total > 0 else None


def paired_difference(a: Pairs, b: Pairs, level: float = 0.95) -> RatioEstimate:
    """``r_B − r_A`` for the same users (same order) with a paired delta-method interval:
    the linearised per-user contributions ``(y_u − r·n_u)/n̄`` of each design, differenced
    per user.

    Rare discordant events: when both designs count whole events over the same
    denominators and fewer than :data:`RARE_DISCORDANT` events differ between them, the
    interval is widened to cover ``[(L_up − U_down)/N, (U_up − L_down)/N]``, the exact
    Poisson (Garwood) bounds of the events B adds (``up``) and removes (``down``) — the
    paired analogue of the rare-event rule for a single design's counts and rates.

    Other pairs (durations): on common random numbers most users' values are identical in
    both designs; with fewer than :data:`RARE_DISCORDANT` users whose values differ the t
    quantile has (that number − 1) degrees of freedom, and with fewer than 2 there is no
    interval (``low``/``high`` None): the data cannot say how much the designs differ."""
    if len(a) != len(b):
        raise ValueError("paired designs need the same users")
    users = len(a)
    est_a, est_b = ratio_estimate(a, level), ratio_estimate(b, level)
    if est_a.value is None or est_b.value is None:
        return RatioEstimate(None, None, None, 0, None)
    diff = est_b.value - est_a.value
    paired = paired_variance(a, b)
    if paired is None:
        return RatioEstimate(diff, None, None, users, None)
    variance = paired[1]
    counts = _discordant(a, b)
    df = users - 1
    method = "paired-t"
    if counts is None:
        # Not counts (durations): the variance rests on the users in whom the designs differ
        # at all; with few of them it has about that many degrees of freedom (Satterthwaite),
        # and with fewer than two it cannot be estimated - no interval rather than a false
        # [d, d] (the same users, the same draws: most users' values are identical)
        differing = sum(1 for pa, pb in zip(a, b, strict=True) if pa != pb)
        if differing < 2:
            return RatioEstimate(diff, None, None, users, None)
        if differing < RARE_DISCORDANT:
            df = min(df, differing - 1)
            method = "paired-t-few"
    half = t_quantile(level, df) * math.sqrt(variance)
    low, high = diff - half, diff + half
    if counts is not None and counts[0] + counts[1] < RARE_DISCORDANT:
        up, down, total = counts
        _, up_lo, up_hi = poisson_interval(up, total, level)
        _, down_lo, down_hi = poisson_interval(down, total, level)
        low, high = min(low, up_lo - down_hi), max(high, up_hi - down_lo)
        method = "paired-t+garwood"
    return RatioEstimate(diff, low, high, users, method)


#: Fewer events than this and the normal approximation behind the cluster-robust interval of
#: a count is not to be trusted (the usual np >= 10 rule): the interval is widened to cover
#: the exact Poisson (Garwood) interval, which never collapses to [0, 0] with no events.
#: (Proportions of counts have their own interval, :mod:`opspec.statistics.proportions`.)
RARE_EVENTS = 10


def count_estimate(totals: Sequence[float], level: float = 0.95) -> RatioEstimate:
    """The mean of the users' totals of a count with its interval: the t interval
    (:func:`ratio_estimate` of ``(total, 1)`` pairs), widened to cover the exact Poisson
    (Garwood) interval of the sum over users when there are fewer than :data:`RARE_EVENTS`
    events in all (method ``"t+garwood"``)."""
    estimate = ratio_estimate(ValuesAsPairs(totals), level)
    total, users = sum(totals), len(totals)
    if users < 1 or total >= RARE_EVENTS:
        return estimate
    _rate, low, high = poisson_interval(int(total), float(users), level)
    return RatioEstimate(
        estimate.value, low if estimate.low is None else min(estimate.low, low),
        high if estimate.high is None else max(estimate.high, high), estimate.users,
        "t+garwood")


def count_estimate_from_sums(total: float, squares: float, users: int, level: float = 0.95
                             ) -> RatioEstimate:
    """:func:`count_estimate` from the users' sum ``Σy`` and sum of squares ``Σy²`` alone (a
    count per user on one day, summed as the results are stored): the same t interval of
    the mean, and the same widening to the Garwood interval below :data:`RARE_EVENTS`."""
    if users < 1:
        return RatioEstimate(None, None, None, 0, None)
    mean = total / users
    low = high = None
    method: str | None = None
    if users >= 2:
        variance = max(0.0, (squares - users * mean * mean) / (users - 1))
        half = t_quantile(level, users - 1) * math.sqrt(variance / users)
        low, high, method = max(0.0, mean - half), mean + half, "t"
    if total < RARE_EVENTS:
        _rate, p_low, p_high = poisson_interval(int(total), float(users), level)
        low = p_low if low is None else min(low, p_low)
        high = p_high if high is None else max(high, p_high)
        method = "t+garwood" if method else None
    return RatioEstimate(mean, low, high, users, method)


def hazard_estimate(counts: Sequence[int], exposure_each: float, level: float = 0.95
                    ) -> RatioEstimate:
    """Events per unit of exposure over users who each had ``exposure_each`` (violations per
    user-day): the union of the exact Poisson (Garwood) interval, right when events are rare
    and independent and a real upper bound when there are none, and the cluster-robust t
    interval, right when events cluster in some users (a late reporter violates again and
    again); method ``"garwood+t"``."""
    total, users = sum(counts), len(counts)
    rate, p_lo, p_hi = poisson_interval(total, users * exposure_each, level)
    robust = ratio_estimate([(float(c), exposure_each) for c in counts], level)
    return RatioEstimate(rate, p_lo if robust.low is None else min(p_lo, robust.low),
                         p_hi if robust.high is None else max(p_hi, robust.high), users,
                         "garwood+t")
