"""Duration families fitted by maximum likelihood (scipy.stats) and compared by AIC and BIC.

``opspec fit`` fits every family below to an activity's observed durations and keeps the one
with the lowest information criterion (AIC by default, BIC on request), showing the whole
comparison to the user:

==========  ==========================================  ======  ============================
family      scipy.stats fit                             params  opspec distribution
==========  ==========================================  ======  ============================
lognormal   ``lognorm.fit(x, floc=0)``                   2       ``LogNormal(mu, sigma)``
gamma       ``gamma.fit(x, floc=0)``                     2       ``Gamma(shape, scale)``
weibull     ``weibull_min.fit(x, floc=0)``               2       ``Weibull(shape, scale)``
exgauss     ``exponnorm.fit(x)`` (from the moments)      3       ``ExGaussian(mu, sigma, tau)``
==========  ==========================================  ======  ============================

The three positive families need every duration > 0 (a zero duration has zero likelihood
under them); the ex-Gaussian needs at least 3 values. AIC = 2k - 2 log L and BIC = k ln n -
2 log L (Akaike 1974; Schwarz 1978): BIC penalises the three-parameter ex-Gaussian more at
large n, so the two can disagree when the data are close to both.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from opspec.errors import ConfigurationError
from opspec.usermodels.distributions import Distribution, ExGaussian, Gamma, LogNormal, Weibull

__all__ = ["CRITERIA", "FAMILIES", "FamilyFit", "choose", "fit_families", "fit_family"]

FAMILIES = ("lognormal", "gamma", "weibull", "exgauss")
CRITERIA = ("aic", "bic")


@dataclass(frozen=True, slots=True)
class FamilyFit:
    """One family's maximum-likelihood fit to ``n`` durations."""

    family: str
    distribution: Distribution
    log_likelihood: float
    parameters: int
    n: int

    @property
    def aic(self) -> float:
        return 2.0 * self.parameters - 2.0 * self.log_likelihood

    @property
    def bic(self) -> float:
        return self.parameters * math.log(self.n) - 2.0 * self.log_likelihood

    def score(self, criterion: str) -> float:
        return self.aic if criterion == "aic" else self.bic

    def named_parameters(self) -> dict[str, float]:
        """The fitted parameters in the user-model file's words (a lognormal's median)."""
        d = self.distribution
        if isinstance(d, LogNormal):
            return {"median": math.exp(d.mu), "sigma": d.sigma}
        if isinstance(d, (Gamma, Weibull)):
            return {"shape": d.shape, "scale": d.scale}
        if isinstance(d, ExGaussian):
            return {"mu": d.mu, "sigma": d.sigma, "tau": d.tau}
        return {}

    def describe(self) -> str:
        return " ".join(f"{k}={v:.4g}" for k, v in self.named_parameters().items())

    def to_json(self) -> dict[str, Any]:
        return {"family": self.family, "parameters": self.distribution.to_params(),
                "log_likelihood": self.log_likelihood, "k": self.parameters, "n": self.n,
                "aic": self.aic, "bic": self.bic}


def _stats() -> Any:
    from scipy import stats  # type: ignore[import-untyped]

    return stats


def _quiet_fit(fit: Any, *args: Any, **kwargs: Any) -> Any:
    """A scipy fit with its optimiser's warnings silenced; None when it fails."""
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        try:
            return fit(*args, **kwargs)
        except (ValueError, RuntimeError, FloatingPointError, OverflowError):
            return None


def _exgauss(x: np.ndarray) -> tuple[Distribution, float] | None:
    stats = _stats()
    m, s = float(x.mean()), float(x.std())
    skew = float(stats.skew(x))
    tau0 = s * (max(skew, 0.05) / 2) ** (1 / 3)          # method of moments, kept positive
    sigma0 = math.sqrt(max(s * s - tau0 * tau0, (0.1 * s) ** 2))
    fitted = _quiet_fit(stats.exponnorm.fit, x, tau0 / sigma0, loc=m - tau0, scale=sigma0)
    if fitted is None:
        return None
    k, loc, scale = (float(v) for v in fitted)
    if not (scale > 0 and k > 0):
        return None
    with np.errstate(all="ignore"):
        ll = float(np.sum(stats.exponnorm.logpdf(x, k, loc=loc, scale=scale)))
    return ExGaussian(loc, scale, k * scale), ll


def fit_family(family: str, values: Sequence[float] | np.ndarray) -> FamilyFit | None:
    """The maximum-likelihood fit of ``family`` to ``values``; None when the family cannot
    describe them (a zero duration for a positive family, too few values, no convergence)."""
    if family not in FAMILIES:
        raise ConfigurationError(f"unknown duration family {family!r}",
                                 hint="use one of: " + ", ".join(FAMILIES))
    x = np.asarray(values, dtype=float)
    n = int(x.size)
    if n < 2 or float(np.ptp(x)) <= 0 or not np.all(np.isfinite(x)):
        return None
    stats = _stats()
    result: tuple[Distribution, float] | None
    if family == "exgauss":
        if n < 3:
            return None
        result = _exgauss(x)
        k = 3
    else:
        if not np.all(x > 0):
            return None
        k = 2
        if family == "lognormal":
            fitted = _quiet_fit(stats.lognorm.fit, x, floc=0)
            if fitted is None:
                return None
            s, _, scale = (float(v) for v in fitted)
            dist: Distribution = LogNormal(math.log(scale), s)
            ll = float(np.sum(stats.lognorm.logpdf(x, s, scale=scale)))
        elif family == "gamma":
            fitted = _quiet_fit(stats.gamma.fit, x, floc=0)
            if fitted is None:
                return None
            a, _, scale = (float(v) for v in fitted)
            dist = Gamma(a, scale)
            ll = float(np.sum(stats.gamma.logpdf(x, a, scale=scale)))
        else:
            fitted = _quiet_fit(stats.weibull_min.fit, x, floc=0)
            if fitted is None:
                return None
            c, _, scale = (float(v) for v in fitted)
            dist = Weibull(c, scale)
            ll = float(np.sum(stats.weibull_min.logpdf(x, c, scale=scale)))
        result = dist, ll
    if result is None or not math.isfinite(result[1]):
        return None
    return FamilyFit(family, result[0], result[1], k, n)


def fit_families(values: Sequence[float] | np.ndarray,
                 families: Sequence[str] = FAMILIES) -> list[FamilyFit]:
    """Every family of ``families`` that fits ``values``, in the order given."""
    fits = (fit_family(f, values) for f in families)
    return [f for f in fits if f is not None]


def choose(fits: Sequence[FamilyFit], criterion: str = "aic") -> FamilyFit:
    """The fit with the lowest ``criterion`` (``aic`` or ``bic``); ties go to the family
    listed first (fewer parameters first in :data:`FAMILIES`)."""
    if criterion not in CRITERIA:
        raise ConfigurationError(f"unknown selection criterion {criterion!r}",
                                 hint="use aic or bic")
    if not fits:
        raise ValueError("no fitted family to choose from")
    return min(fits, key=lambda f: f.score(criterion))
