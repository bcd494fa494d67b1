"""The interval of a ratio metric over users, chosen by what the spec declares of it, never
by the numbers a run happened to give (docs/evaluation.md, *Which interval each number gets*):

- declared a proportion (``Proportion="true"`` on its ``opspec:Ratio``: each numerator event is
  one of the denominator's trials, at most one per trial, as missed of due doses): Wilson's
  interval on the effective number of trials (``"wilson-neff"``,
  :mod:`opspec.statistics.proportions`). A user whose numerator exceeds its denominator makes
  the declaration false, and :func:`ratio_interval` says so (:class:`FalseProportion`) rather
  than compute an interval capped at 1 for a quantity that is not bounded by it;
- any other ratio: the cluster-robust t interval of ``Σy/Σn`` (``"t"``); for a ratio of two
  counts with fewer than :data:`~opspec.statistics.clustered.RARE_EVENTS` numerator events in
  all (alarms per dose), widened to the exact Poisson interval of those events over the
  ``Σn`` trials (``"t+garwood-rate"``), as a count with few events is: with a handful of events
  the t interval is too narrow, and with none it is [0, 0].

A ratio of 2.5 alarms per dose must not be reported as a proportion with an upper bound of 1
because every user of one small run had one alarm per dose: the method would change between
runs of the same spec, and a published interval with it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from opspec.errors import EvaluationError
from opspec.statistics.clustered import RARE_EVENTS, RatioEstimate, ratio_estimate
from opspec.statistics.intervals import poisson_interval
from opspec.statistics.proportions import proportion_interval

__all__ = ["FalseProportion", "excess", "ratio_interval"]

Pairs = Sequence[tuple[float, float]]


class FalseProportion(EvaluationError):
    """A ratio the spec declares a proportion had more numerator events than trials in some
    user's run: the declaration is false (or the device did what it must not: a dose taken
    twice), and no interval of a proportion is true of it."""


def excess(pairs: Pairs) -> tuple[int, tuple[float, float] | None]:
    """How many users' numerator exceeds their denominator, and the first such ``(y, n)``."""
    over = 0
    first: tuple[float, float] | None = None
    for y, n in pairs:
        if y > n:
            over += 1
            first = first or (y, n)
    return over, first


def _false(name: str, numerator: str, denominator: str, over: int, users: int,
           first: tuple[float, float]) -> FalseProportion:
    y, n = first
    return FalseProportion(
        f"{name} is declared a proportion (Proportion=\"true\" on its opspec:Ratio: each of "
        f"{numerator} is one of {denominator}), but {over} of {users} users had more "
        f"{numerator} than {denominator} (one had {y:g} of {n:g}): the declaration is false, "
        "and a proportion's interval (Wilson's, at most 1) of it would be too, so it is not "
        "summarised",
        hint=f"if at most one {numerator} per {denominator} is what the device must do, the "
        "evaluation found that it does not: read those users' traces; otherwise remove "
        f"Proportion=\"true\" from the opspec:Ratio Name=\"{name}\" (its interval is then a "
        "ratio's, docs/evaluation.md) and evaluate again")


def _few_events(pairs: Pairs, estimate: RatioEstimate, level: float) -> RatioEstimate:
    """``estimate`` widened to the exact Poisson interval of the numerator's events over the
    denominator's trials, when there are fewer than :data:`RARE_EVENTS` of them."""
    events = math.fsum(y for y, _ in pairs)
    trials = math.fsum(n for _, n in pairs)
    if estimate.value is None or events >= RARE_EVENTS or trials <= 0:
        return estimate
    _, low, high = poisson_interval(int(events), trials, level)
    return RatioEstimate(estimate.value,
                         low if estimate.low is None else min(estimate.low, low),
                         high if estimate.high is None else max(estimate.high, high),
                         estimate.users, "t+garwood-rate")


def ratio_interval(pairs: Pairs, *, proportion: bool, of_counts: bool, name: str = "the ratio",
                   numerator: str = "numerator", denominator: str = "denominator",
                   level: float = 0.95) -> RatioEstimate:
    """``Σy/Σn`` over users (each user's ``(numerator, denominator)``) with the interval its
    declaration calls for (the module docstring): ``proportion`` is the spec's
    ``Proportion="true"``, ``of_counts`` whether numerator and denominator are both counts
    (whole events, whole trials). Raises :class:`FalseProportion`, naming ``name`` and its
    ``numerator`` and ``denominator``, when a declared proportion is contradicted by a user."""
    estimate = ratio_estimate(pairs, level)
    if proportion:
        over, first = excess(pairs)
        if first is not None:
            raise _false(name, numerator, denominator, over, len(pairs), first)
        low, high = proportion_interval(pairs, level) if estimate.value is not None else (
            None, None)
        return RatioEstimate(estimate.value, low, high, estimate.users,
                             None if low is None else "wilson-neff")
    return _few_events(pairs, estimate, level) if of_counts else estimate
