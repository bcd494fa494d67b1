"""The user model: per manual activity a duration and error parameters, plus a routine.

A :class:`UserModel` is immutable data (usually loaded from TOML by
:func:`opspec.usermodels.loader.load_user_model`); :meth:`UserModel.performer` turns it into a
:class:`~opspec.usermodels.performer.StochasticUser` bound to one user's random stream.
A :class:`Modifier` (age slowing, a heavier slow tail, lower adherence) transforms a model.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import TYPE_CHECKING

from opspec.errors import Diagnostic, Severity, SourceLocation, UserModelError
from opspec.toml_lines import located
from opspec.usermodels.distributions import (
    Constant,
    Distribution,
    ParameterError,
    WithExponentialTail,
)
from opspec.usermodels.errors import Busy, Commission, ExtraDelay, Omission, Repetition
from opspec.usermodels.routine import Routine

if TYPE_CHECKING:
    import numpy as np

    from opspec.usermodels.performer import StochasticUser
    from opspec.usermodels.population import Individual, Population

__all__ = ["ActivityModel", "Modifier", "UserModel"]


@dataclass(frozen=True, slots=True)
class ActivityModel:
    """How the person performs one manual activity (or answers one choice).

    ``prompt`` marks activities whose noticing depends on the routine and adherence drift
    (hearing an alarm); it defaults to true when ``omission`` is given. For choices, either
    ``intended`` (with an optional ``commission``) or ``probabilities`` (a fixed chance per
    alternative, renormalised over the offered alternatives) says what is picked.
    """

    duration: Distribution = field(default_factory=lambda: Constant(0.0))
    omission: Omission | None = None
    prompt: bool = False
    commission: Commission | None = None
    repetition: Repetition | None = None
    delay: ExtraDelay | None = None
    intended: str | None = None
    probabilities: tuple[tuple[str, float], ...] = ()
    source: str | None = None
    #: written without a duration (so it takes no time): a manual activity's is warned of
    untimed: bool = field(default=False, compare=False, repr=False)

    def __post_init__(self) -> None:
        if self.probabilities:
            total = sum(p for _, p in self.probabilities)
            if not math.isclose(total, 1.0, abs_tol=1e-6):
                raise ParameterError("probabilities", f"must add up to 1, got {total:g}")
            if self.intended is not None:
                raise ParameterError("probabilities", "cannot be combined with intended",
                                     hint="use intended + commission, or probabilities")

    @property
    def is_choice_model(self) -> bool:
        return self.intended is not None or bool(self.probabilities)

    def choice_ids(self) -> set[str]:
        """Alternative ids this model names (for validation against the spec)."""
        ids = {name for name, _ in self.probabilities}
        if self.intended:
            ids.add(self.intended)
        if self.commission:
            ids.update(self.commission.alternatives)
        return ids


@dataclass(frozen=True, slots=True)
class Modifier:
    """A transformation of a model, applied to every activity:

    * ``duration_factor`` multiplies durations (general slowing);
    * ``tail_fraction`` adds an exponential slow tail whose mean is that fraction of each
      activity's mean duration (activities with mean 0 are left alone);
    * ``notice_factor`` multiplies the chance of noticing each prompt (``1 - omission``).
    """

    name: str = "modifier"
    duration_factor: float = 1.0
    tail_fraction: float = 0.0
    notice_factor: float = 1.0
    source: str | None = None

    def __post_init__(self) -> None:
        for param in ("duration_factor", "tail_fraction", "notice_factor"):
            value = getattr(self, param)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
                    math.isfinite(value) and value >= 0):
                raise ParameterError(param, f"must be a number >= 0, got {value!r}")
        if self.duration_factor == 0:
            raise ParameterError("duration_factor", "must be > 0, got 0")
        if self.notice_factor > 1:
            raise ParameterError("notice_factor", f"must be in [0, 1], got {self.notice_factor:g}")

    @property
    def is_identity(self) -> bool:
        return (self.duration_factor == 1.0 and self.tail_fraction == 0.0
                and self.notice_factor == 1.0)

    def apply_to(self, activity: ActivityModel) -> ActivityModel:
        duration = activity.duration
        if self.duration_factor != 1.0:
            duration = duration.scaled(self.duration_factor)
        if self.tail_fraction > 0.0 and duration.mean > 0.0:
            duration = WithExponentialTail(duration, self.tail_fraction * duration.mean)
        omission = activity.omission
        if omission is not None and self.notice_factor != 1.0:
            omission = replace(omission,
                               probability=1.0 - (1.0 - omission.probability) * self.notice_factor)
        return replace(activity, duration=duration, omission=omission)


@dataclass(frozen=True, slots=True, eq=False)
class UserModel:
    """A complete user model. ``activities`` maps activity ids (manual activities and
    choices) to their models; ``default`` covers activities not listed (``None``: every
    manual activity must be listed). ``path`` says where it was loaded from, for messages.

    ``population`` (a file with ``[vary]``, ``[[correlations]]`` or ``[subgroups]``) makes
    the simulated users different people: :meth:`individual` is user ``u``'s own model. This
    model's own activities are then the typical person's (the file without its variation).
    """

    name: str
    activities: Mapping[str, ActivityModel]
    default: ActivityModel | None = None
    busy: Busy | None = None
    routine: Routine = field(default_factory=Routine)
    modifiers: tuple[Modifier, ...] = ()
    description: str = ""
    source: str = ""
    path: str = "<python>"
    population: Population | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "activities", MappingProxyType(dict(self.activities)))

    @property
    def varies(self) -> bool:
        """Whether simulated users differ in their parameters (a population)."""
        return self.population is not None

    def individual(self, seed: int, user: int) -> Individual:
        """User ``user`` of a run seeded ``seed``: their subgroup, drawn parameters and model
        (this model itself, unchanged, when there is no population)."""
        if self.population is None:
            from opspec.usermodels.population import Individual

            return Individual(None, MappingProxyType({}), self)
        return self.population.draw(seed, user)

    def activity(self, activity_id: str) -> ActivityModel:
        """The model of ``activity_id`` (falling back to ``default``)."""
        found = self.activities.get(activity_id, self.default)
        if found is None:
            raise UserModelError(
                f"activity {activity_id!r} is not covered by user model {self.name!r}",
                location=located(self.path, "activities"),
                hint=f"add [activities.{activity_id}] with a duration, or a [defaults] table")
        return found

    def covers(self, activity_id: str) -> bool:
        return self.default is not None or activity_id in self.activities

    def validate_against(
        self,
        manual_activity_ids: Iterable[str],
        *,
        choices: Mapping[str, Iterable[str]] | None = None,
    ) -> list[Diagnostic]:
        """Check the model against a spec's user lane before any simulation starts.

        ``manual_activity_ids`` are the manual activities the model performs; ``choices`` maps
        each deferred-choice id to its alternative ids. Raises :class:`UserModelError` when an
        activity or choice is not covered (naming the file, the missing ids and the fix) or a
        choice model names an alternative the spec does not offer. Returns warnings for
        activities in the model that the spec does not have (usually typos) and for choices
        the model leaves to chance (no ``intended`` or ``probabilities``).
        """
        manual = list(dict.fromkeys(manual_activity_ids))
        choice_map = {k: list(v) for k, v in (choices or {}).items()}
        if self.population is not None:
            # every subgroup's model must cover the lane; warnings once each
            found: dict[str, Diagnostic] = {}
            for group in self.population.subgroups:
                for warning in group.model.validate_against(manual, choices=choice_map):
                    found.setdefault(str(warning), warning)
            return list(found.values())
        missing = [a for a in [*manual, *choice_map] if not self.covers(a)]
        if missing and not self.activities and self.default is None and self.modifiers:
            raise UserModelError(
                f"{self.name!r} is a modifier (it changes a model) and covers no activity",
                location=SourceLocation(self.path),
                hint=f"combine it with a base model, e.g. --user-model "
                f"SPEC.users.toml,{self.name}")
        if missing:
            import difflib

            ids = ", ".join(missing)
            # a table the spec has no activity for, named like a missing one: a typo
            strays = [a for a in self.activities if a not in manual and a not in choice_map]
            named = [(stray, close[0]) for stray in strays
                     for close in [difflib.get_close_matches(stray, missing, n=1)] if close]
            typos = [f"[activities.{stray}] is not an activity of the spec: did you mean "
                     f"{close}?" for stray, close in named]
            raise UserModelError(
                f"user model {self.name!r} does not cover manual "
                f"activit{'y' if len(missing) == 1 else 'ies'} of the spec: {ids}"
                + "".join(f"; {typo}" for typo in typos),
                # at the likely typo's table, where the fix is made
                location=located(self.path, f"activities.{named[0][0]}" if named
                                 else "activities"),
                hint="add " + " ".join(f"[activities.{a}]" for a in missing)
                + " with at least a duration, or a [defaults] table")
        for choice_id, alternatives in choice_map.items():
            model = self.activity(choice_id)
            unknown = sorted(model.choice_ids() - set(alternatives))
            if unknown:
                raise UserModelError(
                    f"choice {choice_id!r} has no alternative {', '.join(map(repr, unknown))}",
                    location=located(self.path, f"activities.{choice_id}"),
                    hint="the spec offers: " + ", ".join(alternatives))
        # alternatives are performed by their choice: a model may give them a duration (the
        # time to carry out that pick), but need not
        known = set(manual) | set(choice_map) | {a for alts in choice_map.values() for a in alts}
        warnings = []
        for choice_id, alternatives in choice_map.items():
            model = self.activity(choice_id)
            if model.intended is None and not model.probabilities and len(alternatives) > 1:
                key = f"activities.{choice_id}" if choice_id in self.activities else "defaults"
                warnings.append(Diagnostic(
                    located(self.path, key),
                    Severity.WARNING, "random-choice",
                    f"choice {choice_id!r}: the model names no intended alternative, so it "
                    f"picks one of {', '.join(alternatives)} uniformly at random (and no pick "
                    "counts as wrong)",
                    hint=f"give [activities.{choice_id}] intended = \"{alternatives[0]}\" "
                    "(and a commission for wrong picks) or probabilities, in a model file"))
        for activity_id in self.activities:
            if activity_id not in known:
                warnings.append(Diagnostic(
                    located(self.path, f"activities.{activity_id}"),
                    Severity.WARNING, "unused-user-activity",
                    f"activity {activity_id!r} is not a manual activity or choice of the spec",
                    hint="check the spelling against the spec's activity ids"))
        if self.busy is not None:
            # ignore and release_after too: a misspelt id there silently never matches
            for busy_key, busy_ids in (("engaged", self.busy.engaged),
                                       ("ignore", self.busy.ignore or frozenset()),
                                       ("release_after", self.busy.release_after)):
                for activity_id in sorted(busy_ids - known):
                    warnings.append(Diagnostic(
                        located(self.path, f"busy.{busy_key}"), Severity.WARNING,
                        "unused-user-activity",
                        f"busy.{busy_key} names {activity_id!r}, which the spec's user lane lacks",
                        hint="check the spelling against the spec's activity ids"))
        warnings.extend(self._untimed(manual, choice_map))
        return warnings

    def _untimed(self, manual: list[str], choices: Mapping[str, list[str]]) -> list[Diagnostic]:
        """Warnings for manual activities of the spec whose table (or the ``[defaults]`` they
        fall back to) gives no duration: they take no time, which a forgotten or misspelt
        ``duration`` line does silently. Noticing a prompt (an activity with an omission)
        takes no time as a rule, and a choice's alternatives need no duration."""
        found = []
        picked = {a for alternatives in choices.values() for a in alternatives}
        for activity_id in manual:
            if activity_id in choices or activity_id in picked:
                continue
            written = activity_id in self.activities
            model = self.activities.get(activity_id, self.default)
            if model is None or not model.untimed or model.prompt:
                continue
            table = f"activities.{activity_id}" if written else "defaults"
            found.append(Diagnostic(
                located(self.path, table), Severity.WARNING, "no-duration",
                f"activity {activity_id!r} has no duration in [{table}], so it takes no time",
                hint=f"write duration = 0.0 in [{table}] if it takes no time, or a "
                'distribution: duration = { kind = "lognormal", median = 20, sigma = 0.4 }'))
        return found

    def with_modifier(self, modifier: Modifier) -> UserModel:
        """This model with ``modifier`` applied to every activity (and the default). A
        population's people get it after their parameters are drawn (a drawn median is then
        slowed like any other)."""
        population = self.population
        if population is not None:
            population = population.then(modifier)
        if modifier.is_identity:
            return replace(self, modifiers=(*self.modifiers, modifier), population=population)
        return replace(
            self,
            population=population,
            activities={k: modifier.apply_to(v) for k, v in self.activities.items()},
            default=modifier.apply_to(self.default) if self.default else None,
            modifiers=(*self.modifiers, modifier),
            name=self.name if self.name == modifier.name else f"{self.name}+{modifier.name}",
        )

    def performer(self, rng: np.random.Generator, *, trace_decisions: bool = True
                  ) -> StochasticUser:
        """A performer of this model drawing from ``rng`` (one stream per simulated user)."""
        from opspec.usermodels.performer import StochasticUser

        return StochasticUser(self, rng, trace_decisions=trace_decisions)

    def performer_for(self, seed: int, user: int, *, trace_decisions: bool = True
                      ) -> StochasticUser:
        """The performer of user ``user`` in a run seeded ``seed``: their own model
        (:meth:`individual`) drawing from ``user_stream(seed, user)``, as every run does."""
        from opspec.engine.random import user_stream

        return self.individual(seed, user).model.performer(user_stream(seed, user),
                                                           trace_decisions=trace_decisions)
