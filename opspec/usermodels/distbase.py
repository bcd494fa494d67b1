"""The base of every duration distribution and its parameter error: moved to
:mod:`opspec.distributions.base` (one family for the engine and user models); these names
stay importable from here."""

from __future__ import annotations

from opspec.distributions.base import Distribution, FloatArray, ParameterError

__all__ = ["Distribution", "FloatArray", "ParameterError"]
