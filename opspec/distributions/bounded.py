"""Bounded and data-driven duration distributions: triangular, uniform, empirical (a
bootstrap of observations), and any distribution with an exponential tail added.
Contract: :class:`~opspec.distributions.base.Distribution`."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from opspec.distributions.base import (
    Distribution,
    ParameterError,
    _check_fields,
    _check_q,
    _finite,
    _non_negative,
    _positive,
)

if TYPE_CHECKING:
    # imported where an array is made (FloatArray: base.py)
    import numpy as np

    from opspec.distributions.base import FloatArray

__all__ = ["Empirical", "Triangular", "Uniform", "WithExponentialTail"]


@dataclass(frozen=True, slots=True)
class Triangular(Distribution):
    """Triangular on [``low``, ``high``] with peak ``mode``. One uniform per draw."""

    low: float
    mode: float
    high: float
    kind = "triangular"

    def __post_init__(self) -> None:
        _check_fields(self, low=_non_negative, mode=_finite, high=_finite)
        low, mode, high = self.low, self.mode, self.high
        if not low < high:
            raise ParameterError("high", f"must be > low ({low:g}), got {high:g}")
        if not low <= mode <= high:
            raise ParameterError("mode", f"must be within [low, high] = [{low:g}, {high:g}], "
                                 f"got {mode:g}")

    def sample(self, rng: np.random.Generator) -> float:
        return self.quantile(float(rng.random()))

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        import numpy as np
        u = rng.random(n)
        a, c, b = self.low, self.mode, self.high
        fc = (c - a) / (b - a)
        return np.where(u < fc, a + np.sqrt(u * (b - a) * (c - a)),
                        b - np.sqrt((1.0 - u) * (b - a) * (b - c)))

    @property
    def mean(self) -> float:
        return (self.low + self.mode + self.high) / 3.0

    @property
    def var(self) -> float:
        a, c, b = self.low, self.mode, self.high
        return (a * a + b * b + c * c - a * b - a * c - b * c) / 18.0

    def cdf(self, x: float) -> float:
        a, c, b = self.low, self.mode, self.high
        if x <= a:
            return 0.0
        if x >= b:
            return 1.0
        if x <= c:
            return (x - a) ** 2 / ((b - a) * (c - a))
        return 1.0 - (b - x) ** 2 / ((b - a) * (b - c))

    def quantile(self, q: float) -> float:
        u = _check_q(q)
        a, c, b = self.low, self.mode, self.high
        if u < (c - a) / (b - a):
            return a + math.sqrt(u * (b - a) * (c - a))
        return b - math.sqrt((1.0 - u) * (b - a) * (b - c))

    def scaled(self, factor: float) -> Triangular:
        f = _positive("factor", factor)
        return Triangular(self.low * f, self.mode * f, self.high * f)


@dataclass(frozen=True, slots=True)
class Uniform(Distribution):
    """Uniform on [``low``, ``high``]. One uniform per draw."""

    low: float
    high: float
    kind = "uniform"

    def __post_init__(self) -> None:
        _check_fields(self, low=_non_negative, high=_finite)
        if not self.low < self.high or math.isinf(self.high):
            raise ParameterError("high", f"must be finite and > low ({self.low:g}), got "
                                 f"{self.high:g}")

    def sample(self, rng: np.random.Generator) -> float:
        return self.low + (self.high - self.low) * float(rng.random())

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        return self.low + (self.high - self.low) * rng.random(n)

    @property
    def mean(self) -> float:
        return (self.low + self.high) / 2.0

    @property
    def var(self) -> float:
        return (self.high - self.low) ** 2 / 12.0

    def cdf(self, x: float) -> float:
        return min(max((x - self.low) / (self.high - self.low), 0.0), 1.0)

    def quantile(self, q: float) -> float:
        return self.low + _check_q(q) * (self.high - self.low)

    def scaled(self, factor: float) -> Uniform:
        f = _positive("factor", factor)
        return Uniform(self.low * f, self.high * f)


@dataclass(frozen=True, slots=True)
class Empirical(Distribution):
    """Resampled from observed ``values`` (a bootstrap). With ``jitter`` > 0 a Gaussian kernel
    of that standard deviation is added (a smoothed bootstrap) and results below 0 are clipped
    to 0. One integer draw per sample, plus one normal when ``jitter`` > 0. ``mean`` and
    ``var`` ignore the clipping (exact when the data sit several ``jitter`` above 0)."""

    values: tuple[float, ...]
    jitter: float = 0.0
    kind = "empirical"
    _array: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        import numpy as np
        if isinstance(self.values, (str, bytes)) or not isinstance(self.values, Sequence):
            raise ParameterError("values", "must be a list of durations in seconds")
        if not self.values:
            raise ParameterError("values", "must hold at least one observation")
        values = tuple(_non_negative(f"values[{i}]", v) for i, v in enumerate(self.values))
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "jitter", _non_negative("jitter", self.jitter))
        object.__setattr__(self, "_array", np.asarray(values, dtype=float))

    def sample(self, rng: np.random.Generator) -> float:
        x = self.values[int(rng.integers(len(self.values)))]
        if self.jitter > 0.0:
            x = max(0.0, x + self.jitter * float(rng.standard_normal()))
        return x

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        import numpy as np
        x = self._array[rng.integers(len(self.values), size=n)]
        if self.jitter > 0.0:
            x = np.maximum(0.0, x + self.jitter * rng.standard_normal(n))
        return x

    @property
    def mean(self) -> float:
        return float(self._array.mean())

    @property
    def var(self) -> float:
        return float(self._array.var()) + self.jitter**2

    def cdf(self, x: float) -> float:
        import numpy as np
        if self.jitter > 0.0:
            raise NotImplementedError("empirical with jitter: cdf is not available")
        return float(np.count_nonzero(self._array <= x)) / len(self.values)

    def quantile(self, q: float) -> float:
        import numpy as np
        return float(np.quantile(self._array, _check_q(q)))

    def scaled(self, factor: float) -> Empirical:
        f = _positive("factor", factor)
        return Empirical(tuple(v * f for v in self.values), self.jitter * f)

    def to_params(self) -> dict[str, Any]:
        out: dict[str, Any] = {"kind": "empirical", "values": list(self.values)}
        if self.jitter:
            out["jitter"] = self.jitter
        return out


@dataclass(frozen=True, slots=True)
class WithExponentialTail(Distribution):
    """``base`` plus an independent Exponential(mean ``tau``): a heavier slow tail added to
    any distribution (how the MCI preset lengthens response times). Draws the base first,
    then one exponential."""

    base: Distribution
    tau: float
    kind = "with_tail"

    def __post_init__(self) -> None:
        _check_fields(self, tau=_positive)

    def sample(self, rng: np.random.Generator) -> float:
        return self.base.sample(rng) + float(rng.exponential(self.tau))

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
        return self.base.sample_many(rng, n) + rng.exponential(self.tau, n)

    @property
    def mean(self) -> float:
        return self.base.mean + self.tau

    @property
    def var(self) -> float:
        return self.base.var + self.tau**2

    def scaled(self, factor: float) -> WithExponentialTail:
        return WithExponentialTail(self.base.scaled(factor), self.tau * factor)

    def to_params(self) -> dict[str, Any]:
        return {"kind": "with_tail", "base": self.base.to_params(), "tau": self.tau}
