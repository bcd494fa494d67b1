"""Building a distribution from its TOML table (user models) or from a spec's declaration
(``opspec.model.DeclaredDistribution``, BPSim names such as ``LogNormalDistribution``)."""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Mapping
from typing import Any, Protocol

from opspec.distributions.base import Distribution, ParameterError, _positive
from opspec.distributions.bounded import Empirical, Triangular, Uniform, WithExponentialTail
from opspec.distributions.parametric import (
    Constant,
    ExGaussian,
    Exponential,
    Gamma,
    LogNormal,
    TruncatedNormal,
    Weibull,
)

__all__ = ["KINDS", "Declared", "from_model", "make_distribution"]


class Declared(Protocol):
    """A distribution as a spec declares it: ``opspec.model.DeclaredDistribution`` (a kind and its
    named parameters), without this package depending on the model."""

    @property
    def kind(self) -> str: ...

    @property
    def parameters(self) -> tuple[tuple[str, float], ...]: ...


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
    elif p.has("mean") and p.has("sigma"):
        # the mean of the duration itself with the spread of its log: mu = ln(mean) - sigma²/2
        mean, sigma = _positive("mean", p.take("mean")), _positive("sigma", p.take("sigma"))
        d = LogNormal(math.log(mean) - sigma * sigma / 2.0, sigma)
    elif p.has("mean"):
        d = LogNormal.from_mean_sd(p.take("mean"), p.take("sd", "standardDeviation"))
    else:
        needs = "lognormal needs median+sigma, mu+sigma, mean+sd or mean+sigma"
        if p.left:          # a misspelt name (medain = 60) is likelier than none at all
            typo = min(p.left)
            close = difflib.get_close_matches(typo, ("median", "mu", "mean"), n=1)
            raise ParameterError(typo, "is not a parameter of a lognormal distribution",
                                 hint=(f"did you mean {close[0]}? " if close else "")
                                 + f"({needs})")
        raise ParameterError("median", needs,
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


def from_model(dist: Declared) -> Distribution:
    """Adapter for the spec model's BPSim-style ``opspec.model.DeclaredDistribution(kind,
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
