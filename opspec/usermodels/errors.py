"""Human error models of a user lane, as immutable parameters.

These are the *kinds of error* a simulated person makes, following the usual human-error
taxonomy (Swain & Guttmann's omission/commission; Reason's slips and lapses):

* :class:`Omission` - a prompt is not noticed, or a step is forgotten: the offered activity is
  omitted and that instance of the lane ends there;
* :class:`Commission` - a wrong action: at a choice, a wrong alternative is picked (the spec
  models what the wrong action does, e.g. ``press_wrong_button``); at a plain activity, a
  slip that is noticed and repaired, costing a recovery time;
* :class:`Repetition` - the action is performed twice (its duration is drawn twice);
* :class:`ExtraDelay` - now and then the person starts late (distraction, finishing
  something else);
* :class:`Busy` - a person already engaged in one instance of the lane ignores prompts of
  other instances (a user on the way to the dispenser does not react to the next alarm).

They are data: :class:`~opspec.usermodels.performer.StochasticUser` applies them. Probabilities
are validated here (``[0, 1]``) and raise :class:`~opspec.usermodels.distributions.ParameterError`
naming the parameter.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from opspec.usermodels.distributions import Constant, Distribution, ParameterError

__all__ = [
    "Busy",
    "Commission",
    "ExtraDelay",
    "Omission",
    "Repetition",
    "check_probability",
]


def check_probability(param: str, value: object) -> float:
    """``value`` as a float in [0, 1], or :class:`ParameterError` naming ``param``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(param, f"must be a probability (a number in [0, 1]), got {value!r}")
    p = float(value)
    if not 0.0 <= p <= 1.0:
        raise ParameterError(param, f"must be a probability in [0, 1], got {p:g}",
                             hint="write a fraction: 15 % is 0.15")
    return p


@dataclass(frozen=True, slots=True)
class _Chance:
    """An error that happens with ``probability``, checked on construction (a number in
    [0, 1]); the first field of each kind below."""

    probability: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "probability", check_probability("probability",
                                                                  self.probability))


@dataclass(frozen=True, slots=True)
class Omission(_Chance):
    """With ``probability`` the prompt is not noticed / the step is forgotten."""

    reason: str = "not noticed"
    source: str | None = None


@dataclass(frozen=True, slots=True)
class Commission(_Chance):
    """A wrong action with ``probability``.

    At a choice: a wrong alternative is picked - one of ``alternatives`` (empty: every offered
    alternative except the intended one), uniformly - at most ``max_per_instance`` times per
    instance of the lane; the ``recovery`` time (noticing the mistake) is added before the
    next pick of the same choice. At a plain activity: a slip repaired on the spot, its
    ``recovery`` time added to the activity's duration.
    """

    recovery: Distribution = field(default_factory=lambda: Constant(0.0))
    alternatives: tuple[str, ...] = ()
    max_per_instance: int = 1
    source: str | None = None

    def __post_init__(self) -> None:
        _Chance.__post_init__(self)
        if (isinstance(self.max_per_instance, bool) or not isinstance(self.max_per_instance, int)
                or self.max_per_instance < 1):
            raise ParameterError("max_per_instance",
                                 f"must be an integer >= 1, got {self.max_per_instance!r}")
        object.__setattr__(self, "alternatives", tuple(self.alternatives))


@dataclass(frozen=True, slots=True)
class Repetition(_Chance):
    """With ``probability`` the action is done twice (a second duration is drawn)."""

    source: str | None = None


@dataclass(frozen=True, slots=True)
class ExtraDelay(_Chance):
    """With ``probability`` the person starts late by a draw of ``duration``."""

    duration: Distribution
    source: str | None = None


@dataclass(frozen=True, slots=True)
class Busy:
    """Which activities make the person *engaged* in their lane instance.

    An instance becomes engaged when one of ``engaged`` is offered to the person, and is
    released when the instance is offered (or completes) an activity outside ``engaged``,
    completes one of ``release_after``, has its work item omitted or withdrawn, or ends
    (completes an engaged activity and offers nothing next at the same moment). While any
    instance is engaged, offers from *other* instances are omitted with reason ``"busy"`` -
    all of them, or only those whose activity is in ``ignore`` when it is given.
    """

    engaged: frozenset[str]
    ignore: frozenset[str] | None = None
    release_after: frozenset[str] = frozenset()
    source: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "engaged", _ids("engaged", self.engaged))
        if self.ignore is not None:
            object.__setattr__(self, "ignore", _ids("ignore", self.ignore))
        object.__setattr__(self, "release_after", _ids("release_after", self.release_after))
        if not self.engaged:
            raise ParameterError("engaged", "must list at least one activity id",
                                 hint='for example engaged = ["walk_to_dispenser"]')

    def ignores(self, activity: str) -> bool:
        return self.ignore is None or activity in self.ignore


def _ids(param: str, values: Iterable[object]) -> frozenset[str]:
    if isinstance(values, str):
        raise ParameterError(param, "must be a list of activity ids, got a single string",
                             hint=f'write {param} = ["{values}"]')
    out = []
    for value in values:
        if not isinstance(value, str) or not value:
            raise ParameterError(param, f"must hold activity ids (strings), got {value!r}")
        out.append(value)
    return frozenset(out)
