"""Parametric duration distributions: constant, lognormal, gamma, Weibull, truncated normal,
exponential and ex-Gaussian. Contract: :class:`~opspec.distributions.base.Distribution`."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Self

from opspec.distributions.base import (
    _STD_NORMAL,
    Distribution,
    ParameterError,
    _check_fields,
    _check_q,
    _finite,
    _ncdf,
    _non_negative,
    _phi,
    _positive,
)

if TYPE_CHECKING:
    # imported where an array is made (FloatArray: base.py)
    import numpy as np

    from opspec.distributions.base import FloatArray

__all__ = ["Constant", "ExGaussian", "Exponential", "Gamma", "LogNormal", "TruncatedNormal",
           "Weibull"]


@dataclass(frozen=True, slots=True)
class Constant(Distribution):
    """Always ``value``; consumes no random numbers."""

    value: float
    kind = "constant"

    def __post_init__(self) -> None:
        _check_fields(self, value=_non_negative)

    def sample(self, rng: np.random.Generator) -> float:
        return self.value

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        import numpy as np
        return np.full(n, self.value, dtype=float)

    @property
    def mean(self) -> float:
        return self.value

    @property
    def var(self) -> float:
        return 0.0

    def cdf(self, x: float) -> float:
        return 1.0 if x >= self.value else 0.0

    def quantile(self, q: float) -> float:
        _check_q(q)
        return self.value

    def scaled(self, factor: float) -> Constant:
        return Constant(self.value * factor)


@dataclass(frozen=True, slots=True)
class LogNormal(Distribution):
    """``exp(N(mu, sigma²))``; the median is ``exp(mu)``. One standard normal per draw."""

    mu: float
    sigma: float
    kind = "lognormal"

    def __post_init__(self) -> None:
        _check_fields(self, mu=_finite, sigma=_positive)

    @classmethod
    def from_median(cls, median: float, sigma: float) -> LogNormal:
        return cls(math.log(_positive("median", median)), sigma)

    @classmethod
    def from_mean_sd(cls, mean: float, sd: float) -> LogNormal:
        """BPSim form: ``mean`` and ``sd`` of the distribution itself (not of its log)."""
        m, s = _positive("mean", mean), _positive("standardDeviation", sd)
        s2 = math.log1p((s / m) ** 2)
        return cls(math.log(m) - s2 / 2.0, math.sqrt(s2))

    @property
    def median(self) -> float:
        return math.exp(self.mu)

    def sample(self, rng: np.random.Generator) -> float:
        return math.exp(self.mu + self.sigma * float(rng.standard_normal()))

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        import numpy as np
        return np.exp(self.mu + self.sigma * rng.standard_normal(n))

    @property
    def mean(self) -> float:
        return math.exp(self.mu + self.sigma**2 / 2.0)

    @property
    def var(self) -> float:
        return math.expm1(self.sigma**2) * math.exp(2.0 * self.mu + self.sigma**2)

    def cdf(self, x: float) -> float:
        return _ncdf((math.log(x) - self.mu) / self.sigma) if x > 0 else 0.0

    def quantile(self, q: float) -> float:
        _check_q(q)
        if q in (0.0, 1.0):
            return 0.0 if q == 0.0 else math.inf
        return math.exp(self.mu + self.sigma * _STD_NORMAL.inv_cdf(q))

    def scaled(self, factor: float) -> LogNormal:
        return LogNormal(self.mu + math.log(_positive("factor", factor)), self.sigma)

    def to_params(self) -> dict[str, Any]:
        # Prefer the readable median (60.0, not 59.999999999999986) when it reads back exactly.
        median = float(f"{self.median:.15g}")
        if math.log(median) == self.mu:
            return {"kind": "lognormal", "median": median, "sigma": self.sigma}
        return {"kind": "lognormal", "mu": self.mu, "sigma": self.sigma}


@dataclass(frozen=True, slots=True)
class _ShapeScale(Distribution):
    """A family of a ``shape`` and a ``scale``, both > 0; ``factor * X`` is the same shape
    with the scale times ``factor``."""

    shape: float
    scale: float

    def __post_init__(self) -> None:
        _check_fields(self, shape=_positive, scale=_positive)

    def scaled(self, factor: float) -> Self:
        return type(self)(self.shape, self.scale * _positive("factor", factor))


@dataclass(frozen=True, slots=True)
class Gamma(_ShapeScale):
    """Gamma with ``shape`` k and ``scale`` θ (mean kθ). numpy's gamma sampler per draw."""

    kind = "gamma"

    def sample(self, rng: np.random.Generator) -> float:
        return float(rng.gamma(self.shape, self.scale))

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        return rng.gamma(self.shape, self.scale, n)

    @property
    def mean(self) -> float:
        return self.shape * self.scale

    @property
    def var(self) -> float:
        return self.shape * self.scale**2

    def cdf(self, x: float) -> float:
        from scipy import special  # type: ignore[import-untyped,unused-ignore]  # lazy: 0.3 s at start-up

        return float(special.gammainc(self.shape, x / self.scale)) if x > 0 else 0.0

    def quantile(self, q: float) -> float:
        from scipy import special  # type: ignore[import-untyped,unused-ignore]  # lazy: 0.3 s at start-up

        return float(special.gammaincinv(self.shape, _check_q(q))) * self.scale


@dataclass(frozen=True, slots=True)
class Weibull(_ShapeScale):
    """Weibull with ``shape`` k and ``scale`` λ. One numpy Weibull draw per sample."""

    kind = "weibull"

    def sample(self, rng: np.random.Generator) -> float:
        return self.scale * float(rng.weibull(self.shape))

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        return self.scale * rng.weibull(self.shape, n)

    @property
    def mean(self) -> float:
        return self.scale * math.gamma(1.0 + 1.0 / self.shape)

    @property
    def var(self) -> float:
        g1 = math.gamma(1.0 + 1.0 / self.shape)
        return self.scale**2 * (math.gamma(1.0 + 2.0 / self.shape) - g1 * g1)

    def cdf(self, x: float) -> float:
        return -math.expm1(-((x / self.scale) ** self.shape)) if x > 0 else 0.0

    def quantile(self, q: float) -> float:
        _check_q(q)
        return math.inf if q == 1.0 else self.scale * (-math.log1p(-q)) ** (1.0 / self.shape)


@dataclass(frozen=True, slots=True)
class TruncatedNormal(Distribution):
    """Normal(``mean``, ``sd``) restricted to [``low``, ``high``] (by default [0, ∞): a
    duration is never negative). ``mean``/``sd`` are the *untruncated* parameters; the
    properties ``mean``/``var`` of the distribution are ``truncated_mean``/``var``.
    One uniform per draw (inverse CDF, computed in the accurate tail)."""

    loc: float
    sd_: float
    low: float = 0.0
    high: float = math.inf
    kind = "normal"

    def __post_init__(self) -> None:
        object.__setattr__(self, "loc", _finite("mean", self.loc))
        object.__setattr__(self, "sd_", _positive("sd", self.sd_))
        low = _finite("low", self.low)
        high = _finite("high", self.high)
        if not low < high:
            raise ParameterError("high", f"must be > low ({low:g}), got {high:g}")
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)
        if self._mass() < 1e-12:
            raise ParameterError(
                "low", f"[{low:g}, {high:g}] holds no probability mass of "
                f"normal(mean={self.loc:g}, sd={self.sd_:g})",
                hint="widen the bounds or move the mean inside them")

    def _ab(self) -> tuple[float, float]:
        return (self.low - self.loc) / self.sd_, (self.high - self.loc) / self.sd_

    def _mass(self) -> float:
        a, b = self._ab()
        # Work in the tail where the CDF is small, so far-tail truncation stays accurate.
        return _ncdf(-a) - _ncdf(-b) if a > 0 else _ncdf(b) - _ncdf(a)

    def _from_uniform(self, u: float) -> float:
        a, b = self._ab()
        if a > 0:  # reflect: sample -Z on [-b, -a], whose lower tail is accurate
            lo, hi = _ncdf(-b), _ncdf(-a)
            z = -_STD_NORMAL.inv_cdf(min(max(hi - u * (hi - lo), 1e-300), 1 - 1e-16))
        else:
            lo, hi = _ncdf(a), _ncdf(b)
            z = _STD_NORMAL.inv_cdf(min(max(lo + u * (hi - lo), 1e-300), 1 - 1e-16))
        return min(max(self.loc + self.sd_ * z, self.low), self.high)

    def sample(self, rng: np.random.Generator) -> float:
        return self._from_uniform(float(rng.random()))

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        import numpy as np
        from scipy import special  # type: ignore[import-untyped,unused-ignore]  # lazy: 0.3 s at start-up

        a, b = self._ab()
        u = rng.random(n)
        if a > 0:
            lo, hi = special.ndtr(-b), special.ndtr(-a)
            z = -special.ndtri(hi - u * (hi - lo))
        else:
            lo, hi = special.ndtr(a), special.ndtr(b)
            z = special.ndtri(lo + u * (hi - lo))
        out: FloatArray = np.clip(self.loc + self.sd_ * z, self.low, self.high)
        return out

    @property
    def mean(self) -> float:
        a, b = self._ab()
        return self.loc + self.sd_ * (_phi(a) - _phi(b)) / self._mass()

    @property
    def var(self) -> float:
        a, b = self._ab()
        z = self._mass()
        ta = a * _phi(a) if math.isfinite(a) else 0.0
        tb = b * _phi(b) if math.isfinite(b) else 0.0
        d = (_phi(a) - _phi(b)) / z
        return self.sd_**2 * (1.0 + (ta - tb) / z - d * d)

    def cdf(self, x: float) -> float:
        if x <= self.low:
            return 0.0
        if x >= self.high:
            return 1.0
        from scipy import stats  # lazy: importing scipy.stats takes about 2 s

        return float(stats.truncnorm.cdf(x, *self._ab(), loc=self.loc, scale=self.sd_))

    def quantile(self, q: float) -> float:
        return self._from_uniform(_check_q(q))

    def scaled(self, factor: float) -> TruncatedNormal:
        f = _positive("factor", factor)
        return TruncatedNormal(self.loc * f, self.sd_ * f, self.low * f, self.high * f)

    def to_params(self) -> dict[str, Any]:
        out: dict[str, Any] = {"kind": "normal", "mean": self.loc, "sd": self.sd_}
        if self.low != 0.0:
            out["low"] = self.low
        if math.isfinite(self.high):
            out["high"] = self.high
        return out


@dataclass(frozen=True, slots=True)
class Exponential(Distribution):
    """Exponential with mean ``scale`` (rate 1/scale). One numpy exponential per draw."""

    scale: float
    kind = "exponential"

    def __post_init__(self) -> None:
        object.__setattr__(self, "scale", _positive("mean", self.scale))

    def sample(self, rng: np.random.Generator) -> float:
        return float(rng.exponential(self.scale))

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        return rng.exponential(self.scale, n)

    @property
    def mean(self) -> float:
        return self.scale

    @property
    def var(self) -> float:
        return self.scale**2

    def cdf(self, x: float) -> float:
        return -math.expm1(-x / self.scale) if x > 0 else 0.0

    def quantile(self, q: float) -> float:
        _check_q(q)
        return math.inf if q == 1.0 else -self.scale * math.log1p(-q)

    def scaled(self, factor: float) -> Exponential:
        return Exponential(self.scale * _positive("factor", factor))

    def to_params(self) -> dict[str, Any]:
        return {"kind": "exponential", "mean": self.scale}


@dataclass(frozen=True, slots=True)
class ExGaussian(Distribution):
    """Normal(``mu``, ``sigma``) + Exponential(mean ``tau``): the standard shape of human
    response times (a Gaussian core plus a slow tail). One normal then one exponential per
    draw. Values can be negative when ``mu`` is near 0; performers clamp durations at 0."""

    mu: float
    sigma: float
    tau: float
    kind = "exgauss"

    def __post_init__(self) -> None:
        _check_fields(self, mu=_finite, sigma=_positive, tau=_positive)

    def _frozen(self) -> Any:
        from scipy import stats  # lazy: importing scipy.stats takes about 2 s

        return stats.exponnorm(self.tau / self.sigma, loc=self.mu, scale=self.sigma)

    def sample(self, rng: np.random.Generator) -> float:
        return self.mu + self.sigma * float(rng.standard_normal()) + float(
            rng.exponential(self.tau))

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        z = rng.standard_normal(n)
        e = rng.exponential(self.tau, n)
        return self.mu + self.sigma * z + e

    @property
    def mean(self) -> float:
        return self.mu + self.tau

    @property
    def var(self) -> float:
        return self.sigma**2 + self.tau**2

    def cdf(self, x: float) -> float:
        return float(self._frozen().cdf(x))

    def quantile(self, q: float) -> float:
        return float(self._frozen().ppf(_check_q(q)))

    def scaled(self, factor: float) -> ExGaussian:
        f = _positive("factor", factor)
        return ExGaussian(self.mu * f, self.sigma * f, self.tau * f)
