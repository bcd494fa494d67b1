"""The performers of a spec's manual user lane: stochastic user models and scripted users.

* :mod:`~opspec.usermodels.distributions` - validated duration distributions (also usable
  for activity durations by the engine, via :func:`from_model`);
* :mod:`~opspec.usermodels.errors` - omission, commission, repetition, delay, busy;
* :mod:`~opspec.usermodels.routine` - daily windows (asleep, out, meals) and drift over days;
* :mod:`~opspec.usermodels.model` - :class:`UserModel`, :class:`ActivityModel`, :class:`Modifier`;
* :mod:`~opspec.usermodels.performer` - :class:`StochasticUser`, the Performer;
* :mod:`~opspec.usermodels.loader` - TOML files and bundled presets;
* :mod:`~opspec.usermodels.scripts` - scripted users (exact actions: ``opspec run --script``,
  spec tests, a walkthrough's recording);
* :mod:`~opspec.usermodels.fitting` - estimating a model from recorded traces.

The format is documented in ``docs/user-models.md``.
"""

from opspec.usermodels.distributions import Distribution, from_model, make_distribution
from opspec.usermodels.loader import (
    dump_user_model,
    load_user_model,
    parse_user_model,
    preset_names,
    resolve_preset,
)
from opspec.usermodels.model import ActivityModel, Modifier, UserModel
from opspec.usermodels.performer import StochasticUser

__all__ = [
    "ActivityModel",
    "Distribution",
    "Modifier",
    "StochasticUser",
    "UserModel",
    "dump_user_model",
    "from_model",
    "load_user_model",
    "make_distribution",
    "parse_user_model",
    "preset_names",
    "resolve_preset",
]
