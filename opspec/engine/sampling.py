"""Samplers for an activity's declared distributions (duration, CPU demand).

A spec declares them in BPSim style (:class:`~opspec.model.DeclaredDistribution`: ``LogNormalDistribution
(mean=2, standardDeviation=0.5)``, ``ConstantParameter(3)``…, or opspec's short names such as
``lognormal``); :func:`make_sampler` builds the distribution of :mod:`opspec.distributions` —
the family user models draw from too, so one kind and its parameters mean one distribution
everywhere — and returns its ``sample``: a function of a numpy ``Generator`` returning seconds,
never negative. Samplers are built once, at compile time; each activity draws from its own
seeded stream (:mod:`opspec.engine.random`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from opspec.errors import with_hint
from opspec.model import DeclaredDistribution

if TYPE_CHECKING:   # NumPy only when a spec declares a distribution (`opspec validate` never)
    import numpy as np

__all__ = ["Sampler", "make_sampler"]

Sampler = Callable[["np.random.Generator"], float]


def make_sampler(dist: DeclaredDistribution) -> Sampler:
    """A sampler for ``dist``; :class:`ValueError` naming the problem if it cannot be built."""
    # imported here: the family needs scipy, which a spec without distributions never loads
    from opspec.distributions import (
        ExGaussian,
        ParameterError,
        TruncatedNormal,
        WithExponentialTail,
        from_model,
    )

    try:
        family = from_model(dist)
    except ParameterError as error:
        raise ValueError(with_hint(f"{dist.kind}: {error.message}", error.hint)) from None
    sample = family.sample
    if isinstance(family, (ExGaussian, TruncatedNormal, WithExponentialTail)):
        # these may draw below 0 (a truncated normal may be declared with min < 0): a
        # duration is never negative
        return lambda rng: max(0.0, sample(rng))
    return sample
