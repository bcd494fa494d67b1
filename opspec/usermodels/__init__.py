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
* :mod:`~opspec.usermodels.fitting` - estimating a model from recorded traces (read by
  :mod:`~opspec.usermodels.trace_reader`, paired by :mod:`~opspec.usermodels.observations`,
  fitted by :mod:`~opspec.usermodels.duration_family` and
  :mod:`~opspec.usermodels.choice_estimates`, said by :mod:`~opspec.usermodels.fit_report`);
* :mod:`~opspec.usermodels.checking` - checking a model against people it was not fitted on
  (``opspec model-check``: :mod:`~opspec.usermodels.duration_check`,
  :mod:`~opspec.usermodels.rate_check`, :mod:`~opspec.usermodels.predictive_people`,
  :mod:`~opspec.usermodels.check_report`).

The format is documented in ``docs/user-models.md``.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
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

# Each name is imported from its module when first used (PEP 562), not with the package: the
# distributions need NumPy and SciPy (about half a second), and `opspec validate` or the
# parser of every command imports `opspec.usermodels.persons` only.
_HOME = {
    "Distribution": "distributions", "from_model": "distributions",
    "make_distribution": "distributions",
    "dump_user_model": "loader", "load_user_model": "loader", "parse_user_model": "loader",
    "preset_names": "loader", "resolve_preset": "loader",
    "ActivityModel": "model", "Modifier": "model", "UserModel": "model",
    "StochasticUser": "performer",
}


def __getattr__(name: str) -> Any:
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{home}"), name)
    globals()[name] = value
    return value


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
