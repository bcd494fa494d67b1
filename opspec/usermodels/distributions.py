"""Duration distributions for user models (and for activity durations in the engine).

Every distribution is a frozen dataclass whose parameters are checked on construction; a bad
parameter raises :class:`ParameterError` (a :class:`~opspec.errors.UserModelError`) that names
the parameter, so the TOML loader can report ``file: dotted.key.param: must be > 0, got -1``.

Contract shared by all of them:

* ``sample(rng) -> float`` draws one value from the given numpy ``Generator``; the number and
  kind of underlying draws is fixed per distribution (documented on each class), so a user
  model consumes its stream in a reproducible order;
* ``sample_many(rng, n) -> numpy.ndarray`` draws ``n`` values at once (vectorised);
* ``mean`` and ``var`` are analytic properties;
* ``cdf(x)`` and ``quantile(q)`` where they are cheap;
* ``scaled(factor)`` returns the distribution of ``factor * X`` (age slowing, learning);
* ``to_params()`` returns the TOML form (``{"kind": ..., ...}``) that :func:`make_distribution`
  reads back.

Build one from a TOML table or a spec's BPSim parameter with :func:`make_distribution` /
:func:`from_model`. The base class lives in :mod:`~opspec.usermodels.distbase`, the
parametric families in :mod:`~opspec.usermodels.parametric`; this module holds the bounded
and data-driven ones, the factories, and re-exports everything.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from opspec.usermodels.distbase import (
    Distribution,
    FloatArray,
    ParameterError,
    _check_q,
    _finite,
    _non_negative,
    _positive,
)
from opspec.usermodels.parametric import (
    Constant,
    ExGaussian,
    Exponential,
    Gamma,
    LogNormal,
    TruncatedNormal,
    Weibull,
)

if TYPE_CHECKING:
    from opspec.model import Distribution as ModelDistribution

__all__ = [
    "KINDS",
    "Constant",
    "Distribution",
    "Empirical",
    "ExGaussian",
    "Exponential",
    "Gamma",
    "LogNormal",
    "ParameterError",
    "Triangular",
    "TruncatedNormal",
    "Uniform",
    "Weibull",
    "WithExponentialTail",
    "from_model",
    "make_distribution",
]


@dataclass(frozen=True, slots=True)
class Triangular(Distribution):
    """Triangular on [``low``, ``high``] with peak ``mode``. One uniform per draw."""

    low: float
    mode: float
    high: float
    kind = "triangular"

    def __post_init__(self) -> None:
        low = _non_negative("low", self.low)
        mode = _finite("mode", self.mode)
        high = _finite("high", self.high)
        if not low < high:
            raise ParameterError("high", f"must be > low ({low:g}), got {high:g}")
        if not low <= mode <= high:
            raise ParameterError("mode", f"must be within [low, high] = [{low:g}, {high:g}], "
                                 f"got {mode:g}")
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "mode", mode)
        object.__setattr__(self, "high", high)

    def sample(self, rng: np.random.Generator) -> float:
        return self.quantile(float(rng.random()))

    def sample_many(self, rng: np.random.Generator, n: int) -> FloatArray:
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

    def to_params(self) -> dict[str, Any]:
        return {"kind": "triangular", "low": self.low, "mode": self.mode, "high": self.high}


@dataclass(frozen=True, slots=True)
class Uniform(Distribution):
    """Uniform on [``low``, ``high``]. One uniform per draw."""

    low: float
    high: float
    kind = "uniform"

    def __post_init__(self) -> None:
        low = _non_negative("low", self.low)
        high = _finite("high", self.high)
        if not low < high or math.isinf(high):
            raise ParameterError("high", f"must be finite and > low ({low:g}), got {high:g}")
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)

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

    def to_params(self) -> dict[str, Any]:
        return {"kind": "uniform", "low": self.low, "high": self.high}


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
        if self.jitter > 0.0:
            raise NotImplementedError("empirical with jitter: cdf is not available")
        return float(np.count_nonzero(self._array <= x)) / len(self.values)

    def quantile(self, q: float) -> float:
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
        object.__setattr__(self, "tau", _positive("tau", self.tau))

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


# --------------------------------------------------------------------------- construction


class _Params:
    """Named parameters of one distribution table, consumed one by one so leftovers (typos)
    are reported with the names that were expected."""

    def __init__(self, kind: str, params: Mapping[str, Any]) -> None:
        self.kind = kind
        self.left = {k: v for k, v in params.items() if k not in ("kind", "source")}
        self.expected: list[str] = []

    def has(self, *names: str) -> bool:
        self.expected.extend(n for n in names if n not in self.expected)
        return any(n in self.left for n in names)

    def take(self, *names: str, default: Any = None, required: bool = True) -> Any:
        self.expected.extend(n for n in names if n not in self.expected)
        for name in names:
            if name in self.left:
                return self.left.pop(name)
        if required and default is None:
            if self.left:  # a misspelt name is likelier than a forgotten one
                typo = min(self.left)
                close = difflib.get_close_matches(typo, names, n=1)
                raise ParameterError(
                    typo, f"is not a parameter of a {self.kind} distribution",
                    hint=f"did you mean {close[0]}?" if close else
                    f"{names[0]} is required")
            raise ParameterError(
                names[0], f"is required for a {self.kind} distribution",
                hint=f"add {names[0]} = <number>")
        return default

    def finish(self) -> None:
        if self.left:
            name = min(self.left)
            raise ParameterError(
                name, f"is not a parameter of a {self.kind} distribution",
                hint="expected one of: " + ", ".join(self.expected))


def _build_lognormal(p: _Params) -> Distribution:
    if p.has("median"):
        d = LogNormal.from_median(p.take("median"), p.take("sigma"))
    elif p.has("mu"):
        d = LogNormal(p.take("mu"), p.take("sigma"))
    elif p.has("mean"):
        d = LogNormal.from_mean_sd(p.take("mean"), p.take("sd", "standardDeviation"))
    else:
        raise ParameterError("median", "lognormal needs median+sigma, mu+sigma or mean+sd",
                             hint="for example { kind = \"lognormal\", median = 60, "
                             "sigma = 0.6 }")
    return d


def _build_gamma(p: _Params) -> Distribution:
    shape = p.take("shape", "k")
    if p.has("rate"):
        return Gamma(shape, 1.0 / _positive("rate", p.take("rate")))
    return Gamma(shape, p.take("scale", "theta"))


def _build_normal(p: _Params) -> Distribution:
    return TruncatedNormal(p.take("mean", "mu"), p.take("sd", "standardDeviation", "sigma"),
                           p.take("low", "min", default=0.0, required=False),
                           p.take("high", "max", default=math.inf, required=False))


def _build_exponential(p: _Params) -> Distribution:
    if p.has("rate"):
        return Exponential(1.0 / _positive("rate", p.take("rate")))
    return Exponential(p.take("mean", "scale"))


def _build_empirical(p: _Params) -> Distribution:
    return Empirical(tuple(p.take("values")), p.take("jitter", default=0.0, required=False))


def _build_tail(p: _Params) -> Distribution:
    base = p.take("base")
    if not isinstance(base, Mapping):
        raise ParameterError("base", "must be a distribution table")
    try:
        inner = make_distribution(base)
    except ParameterError as error:
        raise ParameterError(f"base.{error.param}", error.detail, hint=error.hint) from None
    return WithExponentialTail(inner, p.take("tau"))


_BUILDERS: dict[str, Callable[[_Params], Distribution]] = {
    "constant": lambda p: Constant(p.take("value", "mean")),
    "lognormal": _build_lognormal,
    "gamma": _build_gamma,
    "weibull": lambda p: Weibull(p.take("shape", "k"), p.take("scale", "lambda")),
    "normal": _build_normal,
    "truncated_normal": _build_normal,
    "exponential": _build_exponential,
    "exgauss": lambda p: ExGaussian(p.take("mu"), p.take("sigma"), p.take("tau")),
    "triangular": lambda p: Triangular(p.take("low", "min"), p.take("mode"),
                                       p.take("high", "max")),
    "uniform": lambda p: Uniform(p.take("low", "min"), p.take("high", "max")),
    "empirical": _build_empirical,
    "with_tail": _build_tail,
}

# BPSim names (as found in XPDL/BPMN simulation parameters) and spelling variants.
_ALIASES: dict[str, str] = {
    "constantparameter": "constant",
    "normaldistribution": "normal",
    "lognormaldistribution": "lognormal",
    "uniformdistribution": "uniform",
    "exponentialdistribution": "exponential",
    "triangulardistribution": "triangular",
    "gammadistribution": "gamma",
    "weibulldistribution": "weibull",
    "truncatednormaldistribution": "truncated_normal",
    "truncnorm": "truncated_normal",
    "ex-gaussian": "exgauss",
    "exgaussian": "exgauss",
    "ex_gaussian": "exgauss",
    "log-normal": "lognormal",
    "fixed": "constant",
}

KINDS: tuple[str, ...] = tuple(sorted(_BUILDERS))


def make_distribution(params: Mapping[str, Any] | float) -> Distribution:
    """Build a distribution from its TOML table (``{"kind": "lognormal", "median": 60,
    "sigma": 0.6}``) or a bare number (a constant). Accepted kinds: :data:`KINDS` plus the BPSim
    names (``LogNormalDistribution``…). Raises :class:`ParameterError` naming the offending
    parameter (``kind`` for an unknown kind)."""
    if isinstance(params, (int, float)) and not isinstance(params, bool):
        return Constant(params)
    if not isinstance(params, Mapping):
        raise ParameterError("kind", f"must be a number or a table with a 'kind', got "
                             f"{params!r}", hint='for example { kind = "lognormal", '
                             "median = 60, sigma = 0.6 }")
    raw = params.get("kind")
    if not isinstance(raw, str):
        raise ParameterError("kind", "is missing", hint="one of: " + ", ".join(KINDS))
    kind = _ALIASES.get(raw.lower(), raw.lower())
    builder = _BUILDERS.get(kind)
    if builder is None:
        raise ParameterError("kind", f"unknown distribution {raw!r}",
                             hint="use one of: " + ", ".join(KINDS))
    p = _Params(kind, params)
    dist = builder(p)
    p.finish()
    return dist


# BPSim parameter names -> ours, per kind, for the spec adapter.
_BPSIM_NAMES = {"standardDeviation": "sd", "min": "low", "max": "high"}


def from_model(dist: ModelDistribution) -> Distribution:
    """Adapter for the spec model's BPSim-style ``opspec.model.Distribution(kind,
    parameters)``: ``ConstantParameter(value)``, ``NormalDistribution(mean,
    standardDeviation)`` (truncated at 0: a duration), ``LogNormalDistribution(mean,
    standardDeviation)`` (moments of the variable itself, as BPSim defines it; ``median``/``mu``
    with ``sigma`` are accepted too), ``UniformDistribution(min, max)``,
    ``ExponentialDistribution(mean)``, ``TriangularDistribution(min, mode, max)``,
    ``GammaDistribution(shape, scale)``, ``WeibullDistribution(shape, scale)``,
    ``TruncatedNormalDistribution(mean, standardDeviation, min, max)`` and the short names
    (``lognormal``, ``exgauss``…) with the TOML parameter names."""
    params: dict[str, Any] = {"kind": dist.kind}
    for name, value in dist.parameters:
        params[_BPSIM_NAMES.get(name, name)] = value
    return make_distribution(params)
