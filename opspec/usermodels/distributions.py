"""Duration distributions for user models: the family of :mod:`opspec.distributions`.

The same classes serve activity durations in the engine and user models (one family, one
home: :mod:`opspec.distributions`); this module keeps the names user-model code imports.
"""

from __future__ import annotations

from opspec.distributions import (
    KINDS,
    Constant,
    Distribution,
    Empirical,
    ExGaussian,
    Exponential,
    Gamma,
    LogNormal,
    ParameterError,
    Triangular,
    TruncatedNormal,
    Uniform,
    Weibull,
    WithExponentialTail,
    from_model,
    make_distribution,
)

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
