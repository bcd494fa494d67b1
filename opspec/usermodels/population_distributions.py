"""Distributions of a person's parameters (drawn once per simulated user), and correlations.

A *duration* distribution (:mod:`~opspec.usermodels.distributions`) is drawn at every
offer; a *per-user* distribution here is drawn once per simulated user and fixes one parameter
of that person's model (their omission probability, their median walking time). They are
scipy.stats frozen distributions, built from a TOML table with the parameterisations people
use:

========== ========================================================= =====================
kind       parameters                                                for
========== ========================================================= =====================
beta       ``a`` + ``b``, or ``mean`` + ``sd``                         probabilities
lognormal  ``median`` + ``sigma``, ``mu`` + ``sigma``, ``mean`` + ``sd`` scales, medians
gamma      ``shape`` + ``scale`` (or ``rate``), or ``mean`` + ``sd``     scales
weibull    ``shape`` + ``scale``                                       scales
normal     ``mean`` + ``sd``, optional ``low``/``high`` (truncated)       locations, times
uniform    ``low`` + ``high``                                          bounds
triangular ``low`` + ``mode`` + ``high``                               expert ranges
========== ========================================================= =====================

Locations of a normal, uniform or triangular distribution may be times of day (``"23:00"``),
read as seconds since midnight, for routine windows.

Correlations between a person's parameters use a Gaussian copula (Nelsen, *An Introduction
to Copulas*, 2006, section 2.3): a vector of standard normals with correlation matrix ``R``
is drawn, each component turned into a uniform by the normal CDF and into the parameter by its
distribution's quantile function. A rank correlation is what people can state without
knowing the marginals; for the Gaussian copula Spearman's rho and Kendall's tau map to ``R``
in closed form (Kruskal 1958): ``r = 2 sin(pi rho_S / 6)`` and ``r = sin(pi tau / 2)``.
scipy.stats has no copula class; the construction uses its ``multivariate_normal``, ``norm``
and each marginal's ``ppf``/``isf``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from opspec.usermodels.distbase import ParameterError

__all__ = ["CORRELATION_KINDS", "PER_USER_KINDS", "PerUserDistribution",
           "copula", "copula_correlation", "draw_copula", "make_per_user", "smallest_eigenvalue"]


def _stats() -> Any:
    """scipy.stats, imported when a population is built: a user model without one never
    needs it, and importing it is a third of a second of every command's start."""
    from scipy import stats  # type: ignore[import-untyped,unused-ignore]

    return stats

FloatArray = npt.NDArray[np.float64]

#: How a correlation may be stated, and its map to the Gaussian copula's ``r``.
CORRELATION_KINDS: dict[str, Callable[[float], float]] = {
    "spearman": lambda rho: 2.0 * math.sin(math.pi * rho / 6.0),
    "kendall": lambda tau: math.sin(math.pi * tau / 2.0),
    "gaussian": lambda r: r,
}


@dataclass(frozen=True, eq=False)
class PerUserDistribution:
    """One parameter's distribution over people: ``kind``, the ``params`` as written (for the
    report), and the scipy.stats frozen distribution ``frozen``."""

    kind: str
    params: Mapping[str, float]
    frozen: Any = field(repr=False)

    @property
    def support(self) -> tuple[float, float]:
        low, high = self.frozen.support()
        return float(low), float(high)

    @property
    def mean(self) -> float:
        return float(self.frozen.mean())

    @property
    def sd(self) -> float:
        return float(self.frozen.std())

    def quantile(self, q: float) -> float:
        return float(self.frozen.ppf(q))

    def from_normal(self, z: float) -> float:
        """The parameter value whose normal score is ``z``: the quantile of Phi(z), taken
        from the upper tail for z > 0 so that precision is kept in both tails."""
        from scipy import special  # type: ignore[import-untyped,unused-ignore]  # loaded with self.frozen

        if z <= 0.0:
            return float(self.frozen.ppf(special.ndtr(z)))
        return float(self.frozen.isf(special.ndtr(-z)))

    def describe(self) -> str:
        """``beta (mean 0.15, sd 0.08)``."""
        shown = ", ".join(f"{k} {v:g}" for k, v in self.params.items())
        return f"{self.kind} ({shown})"


def _number(name: str, value: Any, *, time_of_day: bool = False) -> float:
    if time_of_day and isinstance(value, str):
        from opspec.usermodels.routine import parse_time_of_day

        return parse_time_of_day(name, value)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(
            value):
        raise ParameterError(name, f"must be a finite number, got {value!r}")
    return float(value)


def _positive(name: str, value: Any) -> float:
    v = _number(name, value)
    if v <= 0:
        raise ParameterError(name, f"must be > 0, got {v:g}")
    return v


class _Table:
    """The parameters of one table, taken one by one; leftovers are typos."""

    def __init__(self, kind: str, table: Mapping[str, Any]) -> None:
        self.kind = kind
        self.left = {k: v for k, v in table.items() if k not in ("kind", "source")}
        self.used: dict[str, float] = {}

    def has(self, name: str) -> bool:
        return name in self.left

    def take(self, name: str, check: Callable[[str, Any], float] = _positive) -> float:
        if name not in self.left:
            raise ParameterError(name, f"is required for a per-user {self.kind} distribution",
                                 hint=f"add {name} = <number>")
        value = check(name, self.left.pop(name))
        self.used[name] = value
        return value

    def finish(self, allowed: str) -> None:
        if self.left:
            name = min(self.left)
            raise ParameterError(name, f"is not a parameter of a per-user {self.kind} "
                                 "distribution", hint=f"give {allowed}")


def _location(name: str, value: Any) -> float:
    return _number(name, value, time_of_day=True)


def _beta(t: _Table) -> Any:
    if t.has("mean"):
        mean = t.take("mean", _number)
        sd = t.take("sd")
        if not 0 < mean < 1:
            raise ParameterError("mean", f"must be in (0, 1) for a beta distribution, got "
                                 f"{mean:g}")
        most = math.sqrt(mean * (1 - mean))
        if sd >= most:
            raise ParameterError("sd", f"must be < sqrt(mean (1 - mean)) = {most:.4g} for a "
                                 f"beta distribution of mean {mean:g}, got {sd:g}",
                                 hint="a beta's sd is below that bound; a smaller sd, or "
                                 "give a and b")
        concentration = mean * (1 - mean) / sd**2 - 1
        return _stats().beta(mean * concentration, (1 - mean) * concentration)
    return _stats().beta(t.take("a"), t.take("b"))


def _lognormal(t: _Table) -> Any:
    if t.has("median"):
        median = t.take("median")
        return _stats().lognorm(s=t.take("sigma"), scale=median)
    if t.has("mu"):
        mu = t.take("mu", _number)
        return _stats().lognorm(s=t.take("sigma"), scale=math.exp(mu))
    mean, sd = t.take("mean"), t.take("sd")
    ratio = 1 + (sd / mean) ** 2
    return _stats().lognorm(s=math.sqrt(math.log(ratio)), scale=mean / math.sqrt(ratio))


def _gamma(t: _Table) -> Any:
    if t.has("mean"):
        mean, sd = t.take("mean"), t.take("sd")
        return _stats().gamma((mean / sd) ** 2, scale=sd**2 / mean)
    shape = t.take("shape")
    if t.has("rate"):
        return _stats().gamma(shape, scale=1 / t.take("rate"))
    return _stats().gamma(shape, scale=t.take("scale"))


def _normal(t: _Table) -> Any:
    mean, sd = t.take("mean", _location), t.take("sd")
    low = t.take("low", _location) if t.has("low") else -math.inf
    high = t.take("high", _location) if t.has("high") else math.inf
    if not low < high:
        raise ParameterError("high", f"must be > low ({low:g}), got {high:g}")
    if math.isinf(low) and math.isinf(high):
        return _stats().norm(mean, sd)
    return _stats().truncnorm((low - mean) / sd, (high - mean) / sd, loc=mean, scale=sd)


def _uniform(t: _Table) -> Any:
    low, high = t.take("low", _location), t.take("high", _location)
    if not low < high:
        raise ParameterError("high", f"must be > low ({low:g}), got {high:g}")
    return _stats().uniform(loc=low, scale=high - low)


def _triangular(t: _Table) -> Any:
    low, mode, high = (t.take("low", _location), t.take("mode", _location),
                       t.take("high", _location))
    if not low < high:
        raise ParameterError("high", f"must be > low ({low:g}), got {high:g}")
    if not low <= mode <= high:
        raise ParameterError("mode", f"must be within [low, high] = [{low:g}, {high:g}], "
                             f"got {mode:g}")
    return _stats().triang((mode - low) / (high - low), loc=low, scale=high - low)


def _weibull(t: _Table) -> Any:
    return _stats().weibull_min(t.take("shape"), scale=t.take("scale"))


_BUILDERS: dict[str, tuple[Callable[[_Table], Any], str]] = {
    "beta": (_beta, "a and b, or mean and sd"),
    "lognormal": (_lognormal, "median and sigma, mu and sigma, or mean and sd"),
    "gamma": (_gamma, "shape and scale (or rate), or mean and sd"),
    "weibull": (_weibull, "shape and scale"),
    "normal": (_normal, "mean and sd, and optionally low and high (truncation)"),
    "uniform": (_uniform, "low and high"),
    "triangular": (_triangular, "low, mode and high"),
}

#: The kinds a per-user parameter may be drawn from.
PER_USER_KINDS: tuple[str, ...] = tuple(sorted(_BUILDERS))


def make_per_user(table: Any) -> PerUserDistribution:
    """A per-user distribution from its TOML table (``{ kind = "beta", mean = 0.15,
    sd = 0.08 }``); :class:`ParameterError` naming the parameter otherwise."""
    if not isinstance(table, Mapping):
        raise ParameterError("kind", f"must be a table with a 'kind', got {table!r}",
                             hint='for example { kind = "beta", mean = 0.15, sd = 0.08 }')
    raw = table.get("kind")
    if not isinstance(raw, str):
        raise ParameterError("kind", "is missing", hint="one of: " + ", ".join(PER_USER_KINDS))
    kind = raw.lower().replace("-", "")
    found = _BUILDERS.get(kind)
    if found is None:
        raise ParameterError("kind", f"unknown per-user distribution {raw!r}",
                             hint="use one of: " + ", ".join(PER_USER_KINDS))
    build, allowed = found
    t = _Table(kind, table)
    frozen = build(t)
    t.finish(allowed)
    return PerUserDistribution(kind, dict(t.used), frozen)


def copula_correlation(kind: str, value: float) -> float:
    """The Gaussian copula's ``r`` for a correlation stated as ``kind`` (spearman, kendall,
    gaussian)."""
    return CORRELATION_KINDS[kind](value)


def smallest_eigenvalue(matrix: FloatArray | Sequence[Sequence[float]]) -> float:
    """The smallest eigenvalue of a symmetric matrix (< 0: not positive semi-definite)."""
    return float(np.linalg.eigvalsh(np.asarray(matrix, dtype=float)).min())


def copula(correlation: FloatArray) -> Any:
    """The multivariate normal of the normal scores (scipy.stats, frozen once per subgroup:
    it factors the matrix), or None when there is nothing to draw."""
    k = correlation.shape[0]
    if k == 0:
        return None
    return _stats().multivariate_normal(mean=np.zeros(k), cov=correlation, allow_singular=True)


def draw_copula(law: Any, rng: np.random.Generator) -> FloatArray:
    """One vector of standard normals from :func:`copula`'s ``law`` (the normal scores of one
    person's parameters), drawn from ``rng``."""
    if law is None:
        return np.zeros(0)
    return np.atleast_1d(np.asarray(law.rvs(random_state=rng), dtype=float))
