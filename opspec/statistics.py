"""Confidence intervals, on ``scipy.stats``: the one statistics module of opspec.

Spec tests (:mod:`opspec.testing`), evaluation reports (:mod:`opspec.evaluation`) and user-model
fitting (:mod:`opspec.usermodels.fitting`) all take their intervals from here:

* :func:`rate_interval` — a proportion: Wilson score (good coverage near 0 and 1, unlike the
  Wald interval) or Clopper-Pearson (exact, conservative), ``scipy.stats.binomtest``;
* :func:`poisson_interval` — a rate of events per unit of exposure (violations per user-day):
  the exact (Garwood) interval, from the chi-square distribution;
* :func:`mean_interval` — a mean of independent values: Student t, or a seeded BCa bootstrap;
* :func:`quantile_interval` — a quantile of pooled observations: the distribution-free
  order-statistic interval (binomial ranks; any continuous distribution);
* :func:`ratio_estimate`, :func:`paired_difference` — a ratio ``Σy/Σn`` over users (the
  independent replications of an evaluation) with the cluster-robust (delta-method) t
  interval, and the paired difference of two designs on the same users.

Every interval is two-sided at ``confidence``; a one-sided bound at level C is one end of the
two-sided interval at ``2C - 1`` (:func:`one_sided`). scipy is imported when first needed (it
is slow to import).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

from opspec.errors import ConfigurationError

__all__ = [
    "MEAN_METHODS",
    "RATE_METHODS",
    "Interval",
    "RatioEstimate",
    "mean_interval",
    "normal_quantile",
    "one_sided",
    "paired_difference",
    "poisson_interval",
    "quantile_interval",
    "rate_interval",
    "ratio_estimate",
    "t_quantile",
]

RATE_METHODS = ("wilson", "clopper-pearson")
MEAN_METHODS = ("t", "bootstrap")


class Interval(NamedTuple):
    """A point estimate and its interval (a tuple, so ``est, lo, hi = ...`` works)."""

    estimate: float
    lo: float
    hi: float


def _stats() -> Any:
    import scipy.stats  # type: ignore[import-untyped]

    return scipy.stats


def one_sided(level: float) -> float:
    """The two-sided confidence whose interval's ends are one-sided bounds at ``level``."""
    return 2.0 * level - 1.0


def normal_quantile(p: float) -> float:
    """The standard normal quantile: ``normal_quantile(0.975)`` is 1.95996…"""
    from scipy import special  # norm.ppf's own function

    return float(special.ndtri(p))


def t_quantile(level: float, df: int) -> float:
    """The two-sided Student-t quantile for confidence ``level`` on ``df`` degrees of freedom
    (``inf`` when there are none)."""
    # scipy.special's stdtrit is what scipy.stats.t.ppf computes, without importing
    # scipy.stats (a third of a second of `opspec evaluate` when nothing else needs it)
    from scipy import special

    return float(special.stdtrit(df, 0.5 + level / 2.0)) if df > 0 else math.inf


# ---------------------------------------------------------------- proportions and counts
def rate_interval(successes: int, trials: int, confidence: float = 0.95, *,
                  method: str = "wilson") -> Interval:
    """Two-sided interval of the proportion ``successes/trials`` at ``confidence``: Wilson
    score or Clopper-Pearson (``"clopper-pearson"``); ``(nan, 0, 1)`` without trials."""
    if method not in RATE_METHODS:
        raise ConfigurationError(f"unknown rate method {method!r}",
                                 hint="use " + " or ".join(RATE_METHODS))
    if trials <= 0:
        return Interval(math.nan, 0.0, 1.0)
    if not 0 <= successes <= trials:
        raise ConfigurationError(f"a rate needs 0 <= successes <= trials, not "
                                 f"{successes}/{trials}",
                                 hint="this is not a proportion; use assert_mean for it")
    if method == "clopper-pearson":
        # The exact interval's ends are beta quantiles (Clopper & Pearson 1934), scipy.special's
        # betaincinv (what scipy.stats.beta.ppf computes; binomtest root-finds the same ends):
        # an evaluation's summaries need nothing else from scipy.stats, a third of a second
        # to import.
        from scipy import special

        k, n, tail = int(successes), int(trials), (1.0 - confidence) / 2.0
        low = 0.0 if k == 0 else float(special.betaincinv(k, n - k + 1, tail))
        high = 1.0 if k == n else float(special.betaincinv(k + 1, n - k, 1.0 - tail))
        return Interval(successes / trials, low, high)
    ci = _stats().binomtest(int(successes), int(trials)).proportion_ci(
        confidence_level=confidence, method="wilson")
    return Interval(successes / trials, max(0.0, float(ci.low)), min(1.0, float(ci.high)))


def poisson_interval(count: int, exposure: float, confidence: float = 0.95
                     ) -> tuple[float, float, float]:
    """``(rate, lo, hi)`` of ``count`` events over ``exposure`` (e.g. user-days): the exact
    two-sided Garwood interval at ``confidence`` (each tail at most (1-confidence)/2);
    ``lo`` is 0 when ``count`` is 0."""
    if exposure <= 0:
        raise ConfigurationError(f"the exposure must be positive, not {exposure!r}")
    if count < 0 or not 0 < confidence < 1:
        raise ConfigurationError("need count >= 0 and 0 < confidence < 1")
    # chi2.ppf(q, 2c) / 2 is the gamma quantile gammaincinv(c, q) (scipy.stats computes chi2's
    # ppf with it): the same numbers without importing scipy.stats
    from scipy import special

    tail = (1 - confidence) / 2
    lower = 0.0 if count == 0 else float(special.gammaincinv(count, tail))
    upper = float(special.gammaincinv(count + 1, 1 - tail))
    return count / exposure, lower / exposure, upper / exposure


# ---------------------------------------------------------------- means and quantiles
def mean_interval(values: Sequence[float], confidence: float = 0.95, *, method: str = "t",
                  seed: int = 0, resamples: int = 9999) -> Interval:
    """Two-sided interval of the mean of ``values``: Student t, or a BCa bootstrap seeded
    with ``seed`` (same values and seed, same interval). Needs at least 2 values."""
    if method not in MEAN_METHODS:
        raise ConfigurationError(f"unknown mean method {method!r}",
                                 hint="use " + " or ".join(MEAN_METHODS))
    n = len(values)
    if n < 2:
        raise ConfigurationError(f"a mean's interval needs at least 2 values, not {n}")
    mean = math.fsum(values) / n
    sd = math.sqrt(math.fsum((v - mean) ** 2 for v in values) / (n - 1))
    if sd == 0:
        return Interval(mean, mean, mean)
    if method == "t":
        half = t_quantile(confidence, n - 1) * sd / math.sqrt(n)
        return Interval(mean, mean - half, mean + half)
    import numpy as np

    res = _stats().bootstrap((np.asarray(values, dtype=float),), np.mean,
                             confidence_level=confidence, n_resamples=resamples,
                             method="BCa", random_state=np.random.default_rng(seed))
    ci = res.confidence_interval
    return Interval(mean, float(ci.low), float(ci.high))


def quantile_interval(values: Sequence[float], q: float, confidence: float = 0.95
                      ) -> Interval:
    """Distribution-free two-sided interval of the ``q``-quantile: order statistics
    ``X(l) <= x_q <= X(u)`` with binomial ranks so that each tail has probability at most
    ``(1 - confidence)/2``; a bound the data cannot give is ``-inf``/``inf``. The estimate is
    the ``ceil(q·n)``-th smallest value."""
    if not 0 < q < 1:
        raise ConfigurationError(f"q must be between 0 and 1, not {q!r}", hint="q=0.95 is p95")
    n = len(values)
    if n == 0:
        return Interval(math.nan, -math.inf, math.inf)
    binom = _stats().binom
    ordered = sorted(values)
    tail = (1 - confidence) / 2
    k_lo = int(binom.ppf(tail, n, q))             # 1-based rank of the lower bound
    k_hi = int(binom.ppf(1 - tail, n, q)) + 1     # 1-based rank of the upper bound
    lo = ordered[k_lo - 1] if k_lo >= 1 else -math.inf
    hi = ordered[k_hi - 1] if k_hi <= n else math.inf
    estimate = ordered[min(n - 1, max(0, math.ceil(q * n) - 1))]
    return Interval(estimate, lo, hi)


# ---------------------------------------------------------------- ratios over users
@dataclass(frozen=True, slots=True)
class RatioEstimate:
    """``Σy/Σn`` over users with its interval; ``users`` counts those contributing
    (``n_u > 0``). ``None`` where there is nothing to estimate."""

    value: float | None
    low: float | None
    high: float | None
    users: int

    @property
    def ci(self) -> list[float | None]:
        return [self.low, self.high]


def ratio_estimate(pairs: Sequence[tuple[float, float]], level: float = 0.95) -> RatioEstimate:
    """Users are the independent replications; observations within a user are not (one slow
    walker has many slow doses). Each user ``u`` gives a pair ``(y_u, n_u)`` — a count:
    (total, 1); a duration: (sum of observations, number of them); a ratio: (numerator,
    denominator) — and the estimate is ``r = Σy/Σn`` with the cluster-robust (delta-method)
    standard error ``se(r)² = Σ (y_u − r·n_u)² / (U·(U−1)·n̄²)``, ``n̄ = Σn/U``, and a
    Student-t interval on U−1 degrees of freedom (for counts exactly the t interval of the
    per-user mean). ``None`` values when Σn is 0; no interval with fewer than 2 users."""
    users = len(pairs)
    total_n = sum(n for _, n in pairs)
    if users == 0 or total_n <= 0:
        return RatioEstimate(None, None, None, 0)
    r = sum(y for y, _ in pairs) / total_n
    contributing = sum(1 for _, n in pairs if n > 0)
    if users < 2:
        return RatioEstimate(r, None, None, contributing)
    nbar = total_n / users
    resid = sum((y - r * n) ** 2 for y, n in pairs)
    se = math.sqrt(resid / (users * (users - 1))) / nbar
    half = t_quantile(level, users - 1) * se
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


def _discordant(a: Sequence[tuple[float, float]], b: Sequence[tuple[float, float]]
                ) -> tuple[int, int, float] | None:
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


def paired_difference(a: Sequence[tuple[float, float]], b: Sequence[tuple[float, float]],
                      level: float = 0.95) -> RatioEstimate:
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
        return RatioEstimate(None, None, None, 0)
    diff = est_b.value - est_a.value
    if users < 2:
        return RatioEstimate(diff, None, None, users)
    nbar_a = sum(n for _, n in a) / users
    nbar_b = sum(n for _, n in b) / users
    z = [(yb - est_b.value * nb) / nbar_b - (ya - est_a.value * na) / nbar_a
         for (ya, na), (yb, nb) in zip(a, b, strict=True)]
    mean_z = sum(z) / users
    var = sum((v - mean_z) ** 2 for v in z) / (users - 1)
    counts = _discordant(a, b)
    df = users - 1
    if counts is None:
        # Not counts (durations): the variance rests on the users in whom the designs differ
        # at all; with few of them it has about that many degrees of freedom (Satterthwaite),
        # and with fewer than two it cannot be estimated - no interval rather than a false
        # [d, d] (the same users, the same draws: most users' values are identical)
        differing = sum(1 for pa, pb in zip(a, b, strict=True) if pa != pb)
        if differing < 2:
            return RatioEstimate(diff, None, None, users)
        if differing < RARE_DISCORDANT:
            df = min(df, differing - 1)
    half = t_quantile(level, df) * math.sqrt(var / users)
    low, high = diff - half, diff + half
    if counts is not None and counts[0] + counts[1] < RARE_DISCORDANT:
        up, down, total = counts
        _, up_lo, up_hi = poisson_interval(up, total, level)
        _, down_lo, down_hi = poisson_interval(down, total, level)
        low, high = min(low, up_lo - down_hi), max(high, up_hi - down_lo)
    return RatioEstimate(diff, low, high, users)
