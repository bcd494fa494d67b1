"""Parametric duration distributions: moved to :mod:`opspec.distributions.parametric` (one
family for the engine and user models); these names stay importable from here."""

from __future__ import annotations

from opspec.distributions import parametric as _parametric
from opspec.distributions.parametric import *  # noqa: F403

__all__: list[str] = []
__all__ += _parametric.__all__
