"""A person's day and how it drifts over weeks, driven by simulated time only.

Simulated time 0 is midnight of day 0 (the convention of the reference scenario); a
:class:`Window` is a time-of-day range (``23:00``-``07:00`` wraps over midnight) that changes
behaviour while it lasts:

* ``notice_factor`` multiplies the chance of noticing a prompt (asleep: 0.2; out: 0);
* ``duration_factor`` multiplies activity durations (groggy at night, hurried at meals);
* ``defer`` - the person cannot perform anything until the window ends (out of the house):
  work offered meanwhile starts at the end of the window;
* ``probability`` - the window happens on a given day with this chance (out on 2 days of 7:
  ``probability = 0.29``); drawn once per day, in window order, from the user's stream.

A :class:`Drift` changes behaviour slowly with the day index ``d``: the chance of noticing is
multiplied by ``notice_factor_per_day ** d`` (adherence decay) and durations by
``duration_factor_per_day ** d`` (learning), each bounded below by its ``min_*``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from opspec import clock
from opspec.errors import UserModelError
from opspec.usermodels.distributions import ParameterError
from opspec.usermodels.errors import check_probability

if TYPE_CHECKING:
    # a run imports it for its random streams; a check of a user model does not
    import numpy as np

__all__ = ["DAY", "Drift", "Routine", "RoutineState", "RoutineTracker", "Window",
           "parse_time_of_day"]

DAY = 86_400.0


def parse_time_of_day(param: str, value: object) -> float:
    """``"07:30"`` / ``"07:30:15"`` / ``"7:30 pm"`` (read by :mod:`opspec.clock`, as in specs)
    or seconds since midnight -> seconds in [0, 86400]."""
    if isinstance(value, str):
        try:
            return clock.parse_time_of_day(value, error=UserModelError)
        except UserModelError as error:
            raise ParameterError(param, error.message, hint=error.hint) from None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(param, f"must be \"HH:MM\" or seconds since midnight, got {value!r}")
    if not 0 <= value <= DAY:
        raise ParameterError(param, f"must be within one day (0..86400 s), got {value:g}")
    return float(value)


def _factor(param: str, value: float, *, allow_zero: bool = True) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value):
        raise ParameterError(param, f"must be a number, got {value!r}")
    v = float(value)
    if v < 0 or (v == 0 and not allow_zero) or math.isinf(v):
        raise ParameterError(param, f"must be {'>= 0' if allow_zero else '> 0'}, got {v:g}")
    return v


@dataclass(frozen=True, slots=True)
class Window:
    """A daily time-of-day window; ``start``/``end`` in seconds since midnight."""

    name: str
    start: float
    end: float
    notice_factor: float = 1.0
    duration_factor: float = 1.0
    defer: bool = False
    probability: float = 1.0
    source: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "start", parse_time_of_day("start", self.start))
        object.__setattr__(self, "end", parse_time_of_day("end", self.end))
        if self.start == self.end:
            raise ParameterError("end", f"must differ from start ({self.start:g} s)")
        object.__setattr__(self, "notice_factor",
                           check_probability("notice_factor", self.notice_factor))
        object.__setattr__(self, "duration_factor",
                           _factor("duration_factor", self.duration_factor, allow_zero=False))
        object.__setattr__(self, "probability", check_probability("probability",
                                                                  self.probability))

    @property
    def wraps(self) -> bool:
        return self.end < self.start

    def occurrence(self, t: float) -> tuple[int, float] | None:
        """``(start_day, end_time)`` of the occurrence of this window containing absolute time
        ``t``, or ``None``. A wrapping window belongs to the day it starts on."""
        day = math.floor(t / DAY)
        tod = t - day * DAY
        if not self.wraps:
            if self.start <= tod < self.end:
                return day, day * DAY + self.end
            return None
        if tod >= self.start:
            return day, (day + 1) * DAY + self.end
        if tod < self.end:
            return day - 1, day * DAY + self.end
        return None


@dataclass(frozen=True, slots=True)
class Drift:
    """Slow change over days (see the module docstring)."""

    notice_factor_per_day: float = 1.0
    min_notice_factor: float = 0.0
    duration_factor_per_day: float = 1.0
    min_duration_factor: float = 0.0
    source: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "notice_factor_per_day",
                           check_probability("notice_factor_per_day", self.notice_factor_per_day))
        object.__setattr__(self, "min_notice_factor",
                           check_probability("min_notice_factor", self.min_notice_factor))
        object.__setattr__(self, "duration_factor_per_day",
                           _factor("duration_factor_per_day", self.duration_factor_per_day,
                                   allow_zero=False))
        object.__setattr__(self, "min_duration_factor",
                           _factor("min_duration_factor", self.min_duration_factor))

    @property
    def is_identity(self) -> bool:
        return self.notice_factor_per_day == 1.0 and self.duration_factor_per_day == 1.0

    def notice_factor(self, day: int) -> float:
        return max(self.min_notice_factor, self.notice_factor_per_day ** max(day, 0))

    def duration_factor(self, day: int) -> float:
        f = self.duration_factor_per_day ** max(day, 0)
        # A floor applies to learning (f < 1); a growing factor (fatigue) is capped by nothing.
        return max(self.min_duration_factor, f) if f < 1.0 else f


@dataclass(frozen=True, slots=True)
class Routine:
    """Windows plus drift; the empty routine changes nothing."""

    windows: tuple[Window, ...] = ()
    drift: Drift = field(default_factory=Drift)

    @property
    def is_trivial(self) -> bool:
        return not self.windows and self.drift.is_identity


@dataclass(frozen=True, slots=True)
class RoutineState:
    """What the routine does to an activity offered now."""

    notice_factor: float = 1.0           # windows x drift
    duration_factor: float = 1.0         # windows (at the start of performance) x drift
    start_at: float | None = None        # deferred start (end of a ``defer`` window)
    window: str | None = None            # the window lowering notice, for the trace
    drift_notice: float = 1.0            # the drift part of notice_factor


_TRIVIAL = RoutineState()


class RoutineTracker:
    """Per-user run state of a :class:`Routine`: which probabilistic windows happen on which
    day. Draws one uniform per probabilistic window per day, days in increasing order,
    windows in file order, lazily when an offer first needs that day."""

    def __init__(self, routine: Routine, rng: np.random.Generator) -> None:
        self.routine = routine
        self._trivial = routine.is_trivial     # checked on every offer
        self._rng = rng
        self._drawn_through = -2  # last day whose occurrences were drawn
        self._happens: dict[tuple[int, int], bool] = {}

    def _occurs(self, index: int, day: int) -> bool:
        window = self.routine.windows[index]
        if window.probability >= 1.0:
            return True
        if window.probability <= 0.0:
            return False
        if day > self._drawn_through:
            first = max(self._drawn_through + 1, day - 1)
            for d in range(first, day + 1):
                for i, w in enumerate(self.routine.windows):
                    if 0.0 < w.probability < 1.0:
                        self._happens[(i, d)] = float(self._rng.random()) < w.probability
            # Forget days no offer can reach any more (a window spans at most one midnight).
            for key in [k for k in self._happens if k[1] < day - 2]:
                del self._happens[key]
            self._drawn_through = day
        return self._happens.get((index, day), False)

    def _active(self, t: float) -> list[tuple[Window, float]]:
        out = []
        for i, window in enumerate(self.routine.windows):
            occ = window.occurrence(t)
            if occ is not None and self._occurs(i, occ[0]):
                out.append((window, occ[1]))
        return out

    def state(self, now: float) -> RoutineState:
        """The routine's effect on an activity offered at ``now``."""
        if self._trivial:
            return _TRIVIAL
        day = math.floor(now / DAY)
        drift = self.routine.drift
        drift_notice = drift.notice_factor(day)
        active = self._active(now)
        notice = drift_notice
        lowest: tuple[float, str] | None = None
        for window, _ in active:
            notice *= window.notice_factor
            if window.notice_factor < 1.0 and (lowest is None or window.notice_factor < lowest[0]):
                lowest = (window.notice_factor, window.name)
        start = now
        # Out of the house: wait until back (a few rounds cover back-to-back windows).
        for _ in range(8):
            ends = [end for window, end in self._active(start) if window.defer]
            if not ends:
                break
            start = max(ends)
        duration = drift.duration_factor(math.floor(start / DAY))
        for window, _ in self._active(start) if start != now else active:
            duration *= window.duration_factor
        return RoutineState(notice_factor=notice, duration_factor=duration,
                            start_at=start if start > now else None,
                            window=lowest[1] if lowest else None, drift_notice=drift_notice)
