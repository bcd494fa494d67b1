"""The posterior of a rate over persons: the hierarchical beta-binomial model.

Each person ``i`` was offered ``n_i`` chances and missed (or slipped) ``k_i`` of them; their
own rate ``theta_i`` is drawn from ``Beta(alpha, beta)``, the population's law (a fitted
``[vary]`` beta; with no spread, ``alpha + beta`` is very large). With the prior
``p(alpha, beta) ∝ (alpha + beta)^(-5/2)`` the posterior of ``(alpha, beta)`` is computed on
a grid over ``(logit(alpha / (alpha + beta)), log(alpha + beta))`` and drawn from it —
Gelman et al., *Bayesian Data Analysis*, 3rd ed., §5.3 (the rat tumour example), eqs. 5.8
and 5.9, and §3.7 for drawing from a grid.

Why not the normal random-effects model of the persons' own rates: own rates near 0 are
skewed (a person with 54 picks and a rate of 0.05 makes 0, 1, 2 ... 6 slips), so their mean
and their variance go together — 30 persons who slip less than the population also *vary*
less — and a normal model, which takes mean and variance as unrelated, predicts too narrow
a range exactly when the estimate is low: new people are then called a misfit for slipping
*more* far more often than for slipping less (docs/fitting.md measures it). The
beta-binomial likelihood ties each person's sampling variance to the rate, as binomial
counts have it, and the posterior of ``alpha + beta`` carries the uncertainty of the
between-person spread. A missed alarm that rings again offers it again: the number of offers
then depends on the outcomes, but the likelihood of a sequence of offers does not depend on
that stopping rule, so the model holds as written.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["RatePosterior", "rate_posterior"]

#: grid points per axis (a first coarse pass finds where the posterior lives)
_GRID = 160
#: log density below the maximum that is treated as no mass (e^-20 ≈ 2e-9)
_CUT = 20.0


def _log_posterior(u: np.ndarray, v: np.ndarray, k: np.ndarray, n: np.ndarray) -> np.ndarray:
    """log p(u, v | data) up to a constant, u = logit(mean), v = log(alpha + beta)
    (BDA3 eq. 5.8 with the prior of eq. 5.9 and its Jacobian: alpha beta (alpha+beta)^-5/2)."""
    from scipy.special import betaln  # type: ignore[import-untyped]

    mean = 1.0 / (1.0 + np.exp(-u))
    total = np.exp(v)
    a, b = mean * total, (1.0 - mean) * total
    out = np.log(a) + np.log(b) - 2.5 * np.log(total)
    base = betaln(a, b)
    for ki, ni in zip(k, n, strict=True):
        out += betaln(a + ki, b + ni - ki) - base
    return out


def _grid(u_range: tuple[float, float], v_range: tuple[float, float], k: np.ndarray,
          n: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    u = np.linspace(*u_range, _GRID)
    v = np.linspace(*v_range, _GRID)
    return u, v, _log_posterior(u[:, None], v[None, :], k, n)


def _box(axis: np.ndarray, alive: np.ndarray) -> tuple[float, float]:
    """The range of ``axis`` where the posterior has mass, one grid step wider each side."""
    where = np.flatnonzero(alive)
    step = axis[1] - axis[0]
    return float(axis[where[0]] - step), float(axis[where[-1]] + step)


@dataclass(frozen=True)
class RatePosterior:
    """Grid cells ``(u, v)`` with their probabilities; :meth:`draw` jitters a cell drawn by
    its probability uniformly within the cell (BDA3 §3.7)."""

    u: np.ndarray
    v: np.ndarray
    cumulative: np.ndarray             # over the flattened (u, v) grid
    persons: int

    def draw(self, rng: np.random.Generator) -> tuple[float, float]:
        """One draw of the population's (mean rate, between-person sd)."""
        cell = int(np.searchsorted(self.cumulative, rng.random() * self.cumulative[-1]))
        cell = min(cell, self.cumulative.size - 1)
        i, j = divmod(cell, self.v.size)
        du, dv = self.u[1] - self.u[0], self.v[1] - self.v[0]
        u = self.u[i] + du * (rng.random() - 0.5)
        v = self.v[j] + dv * (rng.random() - 0.5)
        mean = 1.0 / (1.0 + math.exp(-u))
        return mean, math.sqrt(mean * (1.0 - mean) / (math.exp(v) + 1.0))


def rate_posterior(counts: Sequence[tuple[int, int]]) -> RatePosterior | None:
    """The posterior of a beta-binomial population from persons' ``(events, offers)``
    (persons with no offer left out); None with fewer than 2 persons or no event and no
    non-event at all (nothing to learn a rate from)."""
    pairs = [(int(k), int(n)) for k, n in counts if n > 0]
    if len(pairs) < 2:
        return None
    k = np.array([p[0] for p in pairs], dtype=float)
    n = np.array([p[1] for p in pairs], dtype=float)
    if k.sum() <= 0 or k.sum() >= n.sum():
        return None
    centre = math.log((k.sum() + 0.5) / (n.sum() - k.sum() + 0.5))
    # first a wide look (logit ± 6; alpha + beta from 0.05 to 9e6: from a U-shaped law to
    # one rate for everyone), then the box where the posterior lives, finely
    u, v, lp = _grid((centre - 6.0, centre + 6.0), (-3.0, 16.0), k, n)
    alive = lp > lp.max() - _CUT
    u, v, lp = _grid(_box(u, alive.any(axis=1)), _box(v, alive.any(axis=0)), k, n)
    weights = np.exp(lp - lp.max()).ravel()
    return RatePosterior(u, v, np.cumsum(weights), len(pairs))
