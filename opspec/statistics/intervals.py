"""Intervals of one sample, on ``scipy``: proportions, Poisson rates, means, quantiles.

* :func:`rate_interval` — a proportion: Wilson score (good coverage near 0 and 1, unlike the
  Wald interval) or Clopper-Pearson (exact, conservative);
* :func:`poisson_interval` — a rate of events per unit of exposure (violations per user-day):
  the exact (Garwood) interval, from the chi-square distribution;
* :func:`mean_interval` — a mean of independent values: Student t, or a seeded BCa bootstrap;
* :func:`quantile_interval` — a quantile of pooled observations: the distribution-free
  order-statistic interval (binomial ranks; any continuous distribution).

Every interval is two-sided at ``confidence``; a one-sided bound at level C is one end of the
two-sided interval at ``2C - 1`` (:func:`one_sided`). scipy is imported when first needed (it
is slow to import).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, NamedTuple

from opspec.errors import ConfigurationError

__all__ = [
    "MEAN_METHODS",
    "RATE_METHODS",
    "Interval",
    "mean_interval",
    "normal_quantile",
    "one_sided",
    "poisson_interval",
    "quantile_interval",
    "rate_interval",
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
