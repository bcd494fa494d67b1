"""Duration distributions: one family for activity durations in specs and for user models.

The engine samples an activity's declared ``opspec:Duration`` / CPU demand from these
(:mod:`opspec.engine.sampling`), and user models draw response times, omissions' delays and
the like from them (:mod:`opspec.usermodels`): the same kind and parameters mean the same
distribution and the same draws wherever they are written.

Every distribution is a frozen dataclass whose parameters are checked on construction; a bad
parameter raises :class:`ParameterError` (a :class:`~opspec.errors.UserModelError`) that names
the parameter, so a loader can report ``file: dotted.key.param: must be > 0, got -1``.

Contract shared by all of them:

* ``sample(rng) -> float`` draws one value from the given numpy ``Generator``; the number and
  kind of underlying draws is fixed per distribution (documented on each class), so a run
  consumes its stream in a reproducible order;
* ``sample_many(rng, n) -> numpy.ndarray`` draws ``n`` values at once (vectorised);
* ``mean`` and ``var`` are analytic properties;
* ``cdf(x)`` and ``quantile(q)`` where they are cheap;
* ``scaled(factor)`` returns the distribution of ``factor * X`` (age slowing, learning);
* ``to_params()`` returns the TOML form (``{"kind": ..., ...}``) that :func:`make_distribution`
  reads back.

Build one from a TOML table with :func:`make_distribution`, or from a spec's BPSim-style
declaration with :func:`from_model`. The modules: :mod:`~opspec.distributions.base` (the
contract and the parameter checks), :mod:`~opspec.distributions.parametric` (constant,
lognormal, gamma, Weibull, truncated normal, exponential, ex-Gaussian),
:mod:`~opspec.distributions.bounded` (triangular, uniform, empirical, exponential tail),
:mod:`~opspec.distributions.factory` (the two builders).
"""

from __future__ import annotations

# The public names are each module's own ``__all__``, written once there; base's FloatArray
# is made on first use (its __getattr__, and this module's), so base is not star-imported.
from opspec.distributions import base, bounded, factory, parametric
from opspec.distributions.base import Distribution as Distribution
from opspec.distributions.base import ParameterError as ParameterError
from opspec.distributions.bounded import *  # noqa: F403
from opspec.distributions.factory import *  # noqa: F403
from opspec.distributions.parametric import *  # noqa: F403

__all__: list[str] = []
__all__ += base.__all__
__all__ += bounded.__all__
__all__ += factory.__all__
__all__ += parametric.__all__


def __getattr__(name: str) -> object:
    """``FloatArray``, from :mod:`opspec.distributions.base` when first read (numpy)."""
    if name == "FloatArray":
        return base.FloatArray
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
