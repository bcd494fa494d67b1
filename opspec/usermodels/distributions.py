"""Duration distributions for user models: the family of :mod:`opspec.distributions`.

The same classes serve activity durations in the engine and user models (one family, one
home: :mod:`opspec.distributions`); this module keeps the names user-model code imports.
"""

from __future__ import annotations

from opspec import distributions as _family
from opspec.distributions import *  # noqa: F403

__all__ = list(_family.__all__)
