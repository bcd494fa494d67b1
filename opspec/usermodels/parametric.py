"""Parametric duration distributions: moved to :mod:`opspec.distributions.parametric` (one
family for the engine and user models); these names stay importable from here."""

from __future__ import annotations

from opspec.distributions.parametric import (
    Constant,
    ExGaussian,
    Exponential,
    Gamma,
    LogNormal,
    TruncatedNormal,
    Weibull,
)

__all__ = ["Constant", "ExGaussian", "Exponential", "Gamma", "LogNormal", "TruncatedNormal",
           "Weibull"]
