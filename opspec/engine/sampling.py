"""Samplers for declared distributions (duration text is read by :mod:`opspec.clock`).

A :class:`~opspec.model.Distribution` (BPSim names such as ``LogNormalDistribution`` or
opspec's short names such as ``lognormal``) becomes a *sampler*: a function of a numpy
``Generator`` returning seconds (never negative). Samplers are built once, at compile time;
each activity draws from its own seeded stream (:mod:`opspec.engine.random`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from opspec.model import Distribution

__all__ = ["Sampler", "make_sampler"]

Sampler = Callable[[np.random.Generator], float]


def _p(dist: Distribution, *names: str, default: float | None = None) -> float:
    for name in names:
        value = dist.get(name)
        if value is not None:
            return float(value)
    if default is not None:
        return default
    raise ValueError(f"{dist.kind} needs parameter {' or '.join(names)}")


def make_sampler(dist: Distribution) -> Sampler:
    """A sampler for ``dist``; :class:`ValueError` naming the problem if it cannot be built."""
    kind = dist.kind
    if kind in ("ConstantParameter", "constant"):
        value = max(0.0, _p(dist, "value", "mean"))
        return lambda rng: value
    if kind in ("NormalDistribution", "normal"):
        mean, sd = _p(dist, "mean"), _p(dist, "standardDeviation", "sd", "sigma")
        return lambda rng: max(0.0, mean + sd * float(rng.standard_normal()))
    if kind == "LogNormalDistribution":
        # BPSim: mean and standard deviation of the distribution itself
        mean, sd = _p(dist, "mean"), _p(dist, "standardDeviation")
        sigma2 = math.log(1.0 + (sd / mean) ** 2)
        mu, sigma = math.log(mean) - sigma2 / 2.0, math.sqrt(sigma2)
        return lambda rng: math.exp(mu + sigma * float(rng.standard_normal()))
    if kind == "lognormal":
        if dist.get("mu") is not None:
            mu = _p(dist, "mu")
        else:
            mu = math.log(_p(dist, "median", "mean"))
        sigma = _p(dist, "sigma", "sd", "standardDeviation")
        return lambda rng: math.exp(mu + sigma * float(rng.standard_normal()))
    if kind in ("UniformDistribution", "uniform"):
        low, high = _p(dist, "min", "low"), _p(dist, "max", "high")
        return lambda rng: max(0.0, low + (high - low) * float(rng.random()))
    if kind in ("ExponentialDistribution", "exponential"):
        mean = _p(dist, "mean") if dist.get("mean") is not None else 1.0 / _p(dist, "rate")
        return lambda rng: float(rng.exponential(mean))
    if kind in ("TriangularDistribution", "triangular"):
        low, mode, high = _p(dist, "min", "low"), _p(dist, "mode"), _p(dist, "max", "high")
        return lambda rng: max(0.0, float(rng.triangular(low, mode, high)))
    if kind in ("GammaDistribution", "gamma"):
        shape, scale = _p(dist, "shape"), _p(dist, "scale")
        return lambda rng: float(rng.gamma(shape, scale))
    if kind in ("WeibullDistribution", "weibull"):
        shape, scale = _p(dist, "shape"), _p(dist, "scale")
        return lambda rng: scale * float(rng.weibull(shape))
    if kind == "TruncatedNormalDistribution":
        mean, sd = _p(dist, "mean"), _p(dist, "standardDeviation")
        low, high = _p(dist, "min"), _p(dist, "max")

        def truncated(rng: np.random.Generator) -> float:
            for _ in range(1000):
                x = mean + sd * float(rng.standard_normal())
                if low <= x <= high:
                    return max(0.0, x)
            return max(0.0, min(max(mean, low), high))
        return truncated
    if kind == "exgauss":
        mu, sigma, tau = _p(dist, "mu"), _p(dist, "sigma"), _p(dist, "tau")
        return lambda rng: max(0.0, mu + sigma * float(rng.standard_normal())
                               + float(rng.exponential(tau)))
    raise ValueError(f"unknown distribution {kind!r}")
