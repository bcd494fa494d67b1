"""Estimates with confidence intervals over simulated users.

Users are the independent replications; observations within a user are not independent (one
slow walker has many slow doses). Every metric is therefore reduced per user ``u`` to a pair
``(y_u, n_u)`` — a count: (total, 1); a duration: (sum of observations, number of them); a
ratio: (numerator, denominator) — and estimated by the ratio estimator ``r = Σy / Σn`` with
the cluster-robust (delta-method) standard error

    se(r)² = Σ (y_u − r·n_u)² / (U·(U−1)·n̄²),    n̄ = Σn / U,

and a Student-t interval on U−1 degrees of freedom. For counts (n_u = 1) this is exactly the
t interval of the per-user mean. A paired comparison of two designs on the same users uses the
linearised per-user contributions ``(y_u − r·n_u)/n̄`` of each design, differenced per user.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

__all__ = ["Estimate", "paired_difference", "ratio_estimate", "t_quantile"]


def t_quantile(level: float, df: int) -> float:
    """The two-sided Student-t quantile for confidence ``level`` (normal when df is huge)."""
    from scipy import stats  # type: ignore[import-untyped]

    return float(stats.t.ppf(0.5 + level / 2.0, df)) if df > 0 else math.inf


@dataclass(frozen=True, slots=True)
class Estimate:
    value: float | None
    low: float | None
    high: float | None
    users: int            # users contributing (n_u > 0)

    @property
    def ci(self) -> list[float | None]:
        return [self.low, self.high]


def ratio_estimate(pairs: Sequence[tuple[float, float]], level: float = 0.95) -> Estimate:
    """``Σy/Σn`` over users with its cluster-robust t interval (``None`` when Σn is 0)."""
    users = len(pairs)
    total_n = sum(n for _, n in pairs)
    if users == 0 or total_n <= 0:
        return Estimate(None, None, None, 0)
    r = sum(y for y, _ in pairs) / total_n
    contributing = sum(1 for _, n in pairs if n > 0)
    if users < 2:
        return Estimate(r, None, None, contributing)
    nbar = total_n / users
    resid = sum((y - r * n) ** 2 for y, n in pairs)
    se = math.sqrt(resid / (users * (users - 1))) / nbar
    half = t_quantile(level, users - 1) * se
    low = r - half
    if low < 0.0 and all(y >= 0.0 for y, _ in pairs):
        # counts, durations and ratios of counts cannot be negative; with few users the t
        # interval would say they might be (a count of collisions "from -1.3 to 7.8")
        low = 0.0
    return Estimate(r, low, r + half, contributing)


def paired_difference(a: Sequence[tuple[float, float]], b: Sequence[tuple[float, float]],
                      level: float = 0.95) -> Estimate:
    """``r_B − r_A`` for the same users (same order) with a paired delta-method interval."""
    if len(a) != len(b):
        raise ValueError("paired designs need the same users")
    users = len(a)
    est_a, est_b = ratio_estimate(a, level), ratio_estimate(b, level)
    if est_a.value is None or est_b.value is None:
        return Estimate(None, None, None, 0)
    diff = est_b.value - est_a.value
    if users < 2:
        return Estimate(diff, None, None, users)
    nbar_a = sum(n for _, n in a) / users
    nbar_b = sum(n for _, n in b) / users
    z = [(yb - est_b.value * nb) / nbar_b - (ya - est_a.value * na) / nbar_a
         for (ya, na), (yb, nb) in zip(a, b, strict=True)]
    mean_z = sum(z) / users
    var = sum((v - mean_z) ** 2 for v in z) / (users - 1)
    half = t_quantile(level, users - 1) * math.sqrt(var / users)
    return Estimate(diff, diff - half, diff + half, users)
