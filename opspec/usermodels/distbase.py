"""The base of every duration distribution and its parameter error: moved to
:mod:`opspec.distributions.base` (one family for the engine and user models); these names
stay importable from here."""

from __future__ import annotations

from opspec.distributions.base import Distribution, ParameterError

__all__ = ["Distribution", "FloatArray", "ParameterError"]  # noqa: F822 - FloatArray: __getattr__


def __getattr__(name: str) -> object:
    """``FloatArray``, made when first read (numpy: :mod:`opspec.distributions.base`)."""
    if name == "FloatArray":
        from opspec.distributions import base

        return base.FloatArray
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
