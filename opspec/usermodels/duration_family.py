"""Which family describes an activity's durations (``opspec fit``): every family of
:data:`~opspec.usermodels.families.FAMILIES` fitted by maximum likelihood
(:mod:`opspec.usermodels.families`), the best chosen by AIC or BIC; a constant when the
data leave no choice (none, or all equal).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from opspec.usermodels.distributions import Constant, Distribution
from opspec.usermodels.families import FamilyFit, choose, fit_families

__all__ = ["fit_duration", "fit_duration_families"]


def fit_duration(values: Sequence[float], criterion: str = "aic"
                 ) -> tuple[Distribution, str, dict[str, float], str]:
    """The best family of :data:`~opspec.usermodels.families.FAMILIES` by ``criterion`` for
    ``values`` (seconds). Returns ``(distribution, chosen_name, {name: AIC}, note)``.
    All-equal data give a constant."""
    dist, chosen, fits, note = fit_duration_families(values, criterion)
    return dist, chosen, {f.family: f.aic for f in fits}, note


def fit_duration_families(values: Sequence[float], criterion: str = "aic"
                          ) -> tuple[Distribution, str, tuple[FamilyFit, ...], str]:
    """As :func:`fit_duration`, with every family's fit (``()`` when a constant is
    chosen): ``(distribution, chosen_name, fits, note)``."""
    x = np.asarray(values, dtype=float)
    if x.size == 0:
        return Constant(0.0), "constant", (), "no completed performance: duration 0"
    if x.size == 1:
        # one value says nothing of the spread: not "all equal", and no family fits it
        note = ("one duration only: too few to fit a distribution, written as that one value "
                "(record more sessions)")
        return Constant(float(x[0])), "constant", (), note
    if float(np.ptp(x)) < 1e-9:
        return Constant(float(x[0])), "constant", (), "all durations equal"
    fits = tuple(fit_families(x))
    if not fits:
        return (Constant(float(x.mean())), "constant", (),
                "no family could be fitted: the mean is used")
    best = choose(fits, criterion)
    note = "" if np.all(x > 0) else ("zero durations present: only the ex-Gaussian can "
                                     "describe them")
    return best.distribution, best.family, fits, note
