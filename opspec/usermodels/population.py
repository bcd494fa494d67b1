"""A population of simulated users: subgroups with shares, parameters that differ by person.

A plain :class:`~opspec.usermodels.model.UserModel` is one person: every simulated user has
the same parameters and differs from the others only by chance. A :class:`Population` (the
``population`` of a model loaded from a file with ``[vary]``, ``[[correlations]]`` or
``[subgroups]``; ``docs/user-models.md``) makes users different people:

* each user belongs to one :class:`Subgroup` (``independent`` 70 %, ``MCI`` 20 %, ``frail``
  10 %), each a model of its own;
* some parameters of the subgroup's model are drawn once per user from a
  :class:`~opspec.usermodels.population_distributions.PerUserDistribution`, optionally
  correlated through a Gaussian copula (slow and forgetful go together).

:meth:`Population.draw` gives user ``u`` of a run seeded ``S`` their :class:`Individual`:
subgroup, drawn parameters and the resulting model. It draws from a stream of its own,
``named_stream(S, "population", (u,))``, in this order: one uniform picks the subgroup (by
cumulative share, in file order), then one multivariate normal vector of the subgroup's
varied parameters (in the order of the file). The user's behaviour stream
(``user_stream(S, u)``) is not touched, so a model without variation draws exactly what it
drew before populations existed, and a user's parameters depend on ``(S, u)`` only: not on the
number of workers, on chunking, nor on the design (``--compare`` runs the same people).

Parameter paths name a number of the subgroup's model as it is loaded (after its modifiers):
``activities.ID.duration.median`` (any parameter of the duration's distribution, also
``mean`` and ``rate`` where they are not what the model stores), ``activities.ID.omission.probability``,
``…commission.probability``, ``…commission.recovery.PARAM``, ``…repetition.probability``,
``…delay.probability``, ``…delay.duration.PARAM`` (``defaults.…`` likewise),
``routine.windows.NAME.{start,end,notice_factor,duration_factor,probability}``,
``routine.drift.FIELD``, and ``modifier.{duration_factor,notice_factor,tail_fraction}``: a
per-user modifier applied last to the whole model (general slowing, a lower chance of
noticing every prompt).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from opspec.errors import UserModelError
from opspec.toml_lines import located
from opspec.usermodels.distributions import (
    Distribution,
    ParameterError,
    WithExponentialTail,
    make_distribution,
)
from opspec.usermodels.population_distributions import (
    PerUserDistribution,
    copula,
    draw_copula,
)
from opspec.usermodels.routine import DAY, Routine

if TYPE_CHECKING:
    from opspec.usermodels.model import ActivityModel, Modifier, UserModel

__all__ = ["Correlation", "Individual", "Population", "Subgroup", "VariedParameter",
           "dotted", "set_parameter"]

STREAM = "population"

Path = tuple[str, ...]

_MODIFIER_FIELDS = ("duration_factor", "notice_factor", "tail_fraction")
_WINDOW_FIELDS = ("start", "end", "notice_factor", "duration_factor", "probability")
_DRIFT_FIELDS = ("notice_factor_per_day", "min_notice_factor", "duration_factor_per_day",
                 "min_duration_factor")
_PROBABILITY_PARTS = ("omission", "commission", "repetition", "delay")

#: Parameters of each duration kind a person may differ in (besides what ``to_params`` has).
_DURATION_PARAMS: dict[str, tuple[str, ...]] = {
    "constant": ("value",),
    "lognormal": ("median", "mu", "sigma", "mean"),
    "gamma": ("shape", "scale", "rate", "mean"),
    "weibull": ("shape", "scale"),
    "normal": ("mean", "sd", "low", "high"),
    "exponential": ("mean", "rate"),
    "exgauss": ("mu", "sigma", "tau"),
    "triangular": ("low", "mode", "high"),
    "uniform": ("low", "high"),
    "empirical": ("jitter",),
}

WHAT_VARIES = ("activities.ID.duration.PARAM, activities.ID.omission.probability, "
               "activities.ID.commission.probability, activities.ID.commission.recovery.PARAM, "
               "activities.ID.repetition.probability, activities.ID.delay.probability, "
               "activities.ID.delay.duration.PARAM (defaults.… likewise), "
               "routine.windows.NAME.{start,end,notice_factor,duration_factor,probability}, "
               "routine.drift.FIELD, modifier.{duration_factor,notice_factor,tail_fraction}")


def dotted(path: Path) -> str:
    """``("activities", "walk", "duration", "median")`` -> ``activities.walk.duration.median``
    (a part that is not a bare TOML key is quoted)."""
    import re

    return ".".join(p if re.fullmatch(r"[A-Za-z0-9_-]+", p) else '"' + p.replace(
        '"', '\\"') + '"' for p in path)


# ------------------------------------------------------------------------- the parameters


def _duration_with(dist: Distribution, param: str, value: float) -> Distribution:
    """``dist`` with one parameter set to ``value``; the others as the model has them."""
    if isinstance(dist, WithExponentialTail):
        if param == "tau":
            return WithExponentialTail(dist.base, value)
        return WithExponentialTail(_duration_with(dist.base, param, value), dist.tau)
    params = dist.to_params()
    kind = str(params.get("kind"))
    allowed = _DURATION_PARAMS.get(kind, ())
    if param not in allowed:
        raise ParameterError(param, f"is not a parameter of this {kind} duration",
                             hint="it has: " + (", ".join(allowed) or "nothing to vary"))
    if kind == "lognormal":
        sigma = float(params["sigma"])
        mu = math.log(float(params["median"])) if "median" in params else float(params["mu"])
        if param == "sigma":
            sigma = value
        elif param == "median":
            mu = math.log(value) if value > 0 else math.nan
        elif param == "mean":
            mu = math.log(value) - sigma**2 / 2 if value > 0 else math.nan
        else:
            mu = value
        if math.isnan(mu):
            raise ParameterError(param, f"must be > 0, got {value:g}")
        return make_distribution({"kind": "lognormal", "mu": mu, "sigma": sigma})
    if kind == "gamma" and param in ("rate", "mean"):
        if value <= 0:
            raise ParameterError(param, f"must be > 0, got {value:g}")
        scale = 1 / value if param == "rate" else value / float(params["shape"])
        return make_distribution({**params, "scale": scale})
    if kind == "exponential" and param == "rate":
        if value <= 0:
            raise ParameterError(param, f"must be > 0, got {value:g}")
        return make_distribution({**params, "mean": 1 / value})
    return make_distribution({**params, param: value})


def _activity_with(activity: ActivityModel, rest: Path, value: float, key: str
                   ) -> ActivityModel:
    if not rest:
        raise _bad_path(key, "names an activity, not one of its numbers")
    part, tail = rest[0], rest[1:]
    if part == "duration":
        if len(tail) != 1:
            raise _bad_path(key, "a duration varies by one of its parameters, e.g. "
                            f"{key if tail else key + '.median'}")
        return replace(activity, duration=_duration_with(activity.duration, tail[0], value))
    if part in _PROBABILITY_PARTS:
        current = getattr(activity, part)
        if current is None:
            raise _bad_path(key, f"the activity has no {part} to vary",
                            hint=f"give it one in the model ({part} = 0.01), then vary it")
        if tail == ("probability",):
            return replace(activity, **{part: replace(current, probability=value)})
        if part == "commission" and len(tail) == 2 and tail[0] == "recovery":
            return replace(activity, commission=replace(
                current, recovery=_duration_with(current.recovery, tail[1], value)))
        if part == "delay" and len(tail) == 2 and tail[0] == "duration":
            return replace(activity, delay=replace(
                current, duration=_duration_with(current.duration, tail[1], value)))
    raise _bad_path(key, "is not a number of the model a person can differ in")


def _routine_with(routine: Routine, rest: Path, value: float, key: str) -> Routine:
    if len(rest) == 3 and rest[0] == "windows" and rest[2] in _WINDOW_FIELDS:
        names = [w.name for w in routine.windows]
        if rest[1] not in names:
            raise _bad_path(key, f"the model has no routine window {rest[1]!r}",
                            hint="its windows: " + (", ".join(names) or "none"))
        if rest[2] in ("start", "end"):
            value = value % DAY          # a drawn time of day wraps around midnight
        change: dict[str, Any] = {rest[2]: value}
        windows = tuple(replace(w, **change) if w.name == rest[1] else w
                        for w in routine.windows)
        return replace(routine, windows=windows)
    if len(rest) == 2 and rest[0] == "drift" and rest[1] in _DRIFT_FIELDS:
        drift: dict[str, Any] = {rest[1]: value}
        return replace(routine, drift=replace(routine.drift, **drift))
    raise _bad_path(key, "is not a number of the model a person can differ in")


def _bad_path(key: str, message: str, hint: str = "") -> ParameterError:
    return ParameterError(key, message, hint=hint or f"a person can differ in: {WHAT_VARIES}")


def set_parameter(model: UserModel, path: Path, value: float) -> UserModel:
    """``model`` with the number at ``path`` set to ``value`` (a :class:`ParameterError`
    whose ``param`` is the dotted path when the path names nothing, or the value is not
    allowed there). ``modifier.*`` paths are not set here: see :meth:`Subgroup.individual`."""
    key = dotted(path)
    try:
        return _set(model, path, value, key)
    except ParameterError as error:
        if error.param == key:
            raise
        raise ParameterError(key, error.detail, hint=error.hint) from None


def _set(model: UserModel, path: Path, value: float, key: str) -> UserModel:
    head, rest = path[0], path[1:]
    if head == "activities" and rest:
        found = model.activities.get(rest[0])
        if found is None:
            raise _bad_path(key, f"the model has no activity {rest[0]!r}",
                            hint="its activities: " + ", ".join(model.activities))
        activities = dict(model.activities)
        activities[rest[0]] = _activity_with(found, rest[1:], value, key)
        return replace(model, activities=activities)
    if head == "defaults":
        if model.default is None:
            raise _bad_path(key, "the model has no [defaults] to vary")
        return replace(model, default=_activity_with(model.default, rest, value, key))
    if head == "routine":
        return replace(model, routine=_routine_with(model.routine, rest, value, key))
    raise _bad_path(key, "is not a number of the model a person can differ in")


# ---------------------------------------------------------------------------- the people


@dataclass(frozen=True, eq=False)
class VariedParameter:
    """One number of the model that differs by person: its ``path`` and distribution."""

    path: Path
    distribution: PerUserDistribution
    source: str | None = None

    @property
    def name(self) -> str:
        return dotted(self.path)

    @property
    def is_modifier(self) -> bool:
        return self.path[0] == "modifier"


@dataclass(frozen=True, slots=True)
class Correlation:
    """A stated correlation between two varied parameters (``kind``: spearman, kendall or
    gaussian) and the Gaussian copula's ``r`` it gives."""

    first: str
    second: str
    kind: str
    value: float
    r: float
    source: str | None = None


@dataclass(frozen=True, eq=False)
class Individual:
    """One simulated person: their ``subgroup`` (None without subgroups), the ``parameters``
    drawn for them (dotted path -> value, in file order) and the ``model`` they follow."""

    subgroup: str | None
    parameters: Mapping[str, float]
    model: UserModel

    def performer(self, rng: np.random.Generator, *, trace_decisions: bool = True) -> Any:
        return self.model.performer(rng, trace_decisions=trace_decisions)


@dataclass(frozen=True, eq=False)
class Subgroup:
    """A named part of the population: its ``share`` of users, its ``model`` and the
    parameters that differ by person within it (with their copula ``correlation`` matrix,
    in the order of ``varied``)."""

    name: str | None
    share: float
    model: UserModel
    varied: tuple[VariedParameter, ...] = ()
    correlations: tuple[Correlation, ...] = ()
    correlation: npt.NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 0)))
    description: str = ""
    source: str | None = None

    law: Any = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if self.correlation.shape != (len(self.varied), len(self.varied)):
            object.__setattr__(self, "correlation", np.eye(len(self.varied)))
        object.__setattr__(self, "law", copula(self.correlation))

    def individual(self, values: Mapping[str, float]) -> Individual:
        """The person of this subgroup with the drawn ``values`` (dotted path -> value)."""
        model = self.model
        modifier: dict[str, Any] = {}
        for varied in self.varied:
            value = values[varied.name]
            if varied.is_modifier:
                modifier[varied.path[1]] = value
            else:
                model = set_parameter(model, varied.path, value)
        if modifier:
            from opspec.usermodels.model import Modifier

            try:
                model = model.with_modifier(Modifier(name="this person", **modifier))
            except ParameterError as error:
                raise ParameterError(f"modifier.{error.param}", error.detail,
                                     hint=error.hint) from None
        return Individual(self.name, MappingProxyType(dict(values)), model)

    def draw_values(self, rng: np.random.Generator) -> dict[str, float]:
        """One person's values of the varied parameters (one copula draw from ``rng``)."""
        if not self.varied:
            return {}
        z = draw_copula(self.law, rng)
        return {v.name: v.distribution.from_normal(float(z[i]))
                for i, v in enumerate(self.varied)}


@dataclass(frozen=True, eq=False)
class Population:
    """Subgroups (one, named None, when the file declares none) with shares adding up to 1."""

    subgroups: tuple[Subgroup, ...]
    path: str = "<python>"
    #: modifiers composed on top of the population (``population.toml,older-adults``):
    #: applied to each person after their parameters are drawn
    after: tuple[Modifier, ...] = ()

    @property
    def names(self) -> tuple[str | None, ...]:
        return tuple(s.name for s in self.subgroups)

    @property
    def parameters(self) -> tuple[str, ...]:
        """Every varied parameter of any subgroup (dotted), in file order."""
        return tuple(dict.fromkeys(v.name for s in self.subgroups for v in s.varied))

    def subgroup(self, u: float) -> Subgroup:
        """The subgroup of a person whose uniform draw is ``u`` (cumulative shares)."""
        total = 0.0
        for group in self.subgroups:
            total += group.share
            if u < total:
                return group
        return self.subgroups[-1]           # u within rounding of 1

    def draw(self, seed: int, user: int) -> Individual:
        """User ``user`` of a run seeded ``seed`` (see the module docstring for the stream)."""
        from opspec.engine.random import named_stream

        rng = named_stream(seed, STREAM, (user,))
        group = self.subgroup(float(rng.random()))
        values = group.draw_values(rng)
        try:
            person = group.individual(values)
            if not self.after:
                return person
            model = person.model
            for modifier in self.after:
                model = model.with_modifier(modifier)
            return Individual(person.subgroup, person.parameters, model)
        except ParameterError as error:     # a draw on the edge of what a parameter allows
            raise UserModelError(
                f"user {user}: drawn {error.param} is not allowed: {error.detail}",
                location=located(self.path, f"vary.{error.param}"),
                hint="give the per-user distribution a support inside what the parameter "
                "allows (a beta for a probability, a lognormal or gamma for a scale)"
            ) from None

    def then(self, modifier: Modifier) -> Population:
        """This population with ``modifier`` applied to each person after the draw."""
        return replace(self, after=(*self.after, modifier))

    def map_models(self, change: Callable[[UserModel], UserModel]) -> Population:
        """This population with ``change`` applied to every subgroup's model (a modifier
        composed on top: ``population.toml,older-adults``)."""
        return replace(self, subgroups=tuple(replace(s, model=change(s.model))
                                             for s in self.subgroups))
