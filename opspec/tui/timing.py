"""How long the person took to answer, and whether the simulated duration of it is real.

``opspec fit`` estimates a person's durations from the trace: offer to completion, in
simulated time. In a walkthrough that is a real duration only when the simulated clock ran in
real time (1x) all the way from the offer reaching the person to their answer. At 60x a
10-second answer lasts 600 simulated seconds; paused, it lasts none; after a skip (``n``,
``u``, ``w``) or with the help open it is anything. :class:`OfferTimes` keeps, per offer, when
it reached the person (simulated and wall time) and the first reason its simulated duration
stopped being real; :meth:`OfferTimes.answered` turns that into a :class:`Response`, written
with the action to the trace (``walkthrough.action``: ``response_wall_s``, ``usable``,
``why``) — ``opspec fit`` leaves out the durations marked ``usable: false``.

The wall-clock response time (``response_wall_s``) is what the person really took, whatever
the clock did: the end-of-run summary reports it.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from typing import Any

__all__ = ["OfferTimes", "Response"]


@dataclass(frozen=True, slots=True)
class Response:
    """One answer to an offer: who gave it, how long it took in wall seconds (``None``: the
    offer was never shown to the person, e.g. a model's), and whether the simulated duration
    is real (``usable``; ``why`` not). ``omitted``: the answer was not to do it (``x``), which
    has no response time (the time to a decision not to act is no duration of the action)."""

    by: str
    wall_s: float | None
    usable: bool
    why: str | None = None
    label: str = ""
    at: float = 0.0
    omitted: bool = False

    def named(self, label: str, at: float, *, omitted: bool = False) -> Response:
        return replace(self, label=label, at=at, omitted=omitted)

    def trace_data(self) -> dict[str, Any]:
        data: dict[str, Any] = {"usable": self.usable}
        if self.wall_s is not None:
            data["response_wall_s"] = round(self.wall_s, 3)
        if self.why:
            data["why"] = self.why
        return data


@dataclass(slots=True)
class _Shown:
    time: float                 # simulated time the offer reached the person
    wall: float                 # monotonic wall time then
    why: str | None             # first reason the simulated duration is not real


class OfferTimes:
    """See the module docstring. Keys are work-item keys; ``clock`` is the wall clock
    (monotonic seconds; injectable for tests)."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self._clock = clock
        self._shown: dict[int, _Shown] = {}

    def shown(self, key: int, now: float, *, paused: bool) -> None:
        """The offer ``key`` reaches the person at simulated time ``now``."""
        self._shown[key] = _Shown(now, self._clock(), "the clock was paused" if paused
                                  else None)

    def spoil(self, why: str, *, since_before: float | None = None,
              keys: Iterable[int] | None = None) -> None:
        """What waits now (only ``keys``; only offers shown before simulated time
        ``since_before``) has no real simulated duration any more, because ``why``."""
        wanted = None if keys is None else set(keys)
        for key, shown in self._shown.items():
            if wanted is not None and key not in wanted:
                continue
            if since_before is not None and shown.time >= since_before:
                continue                 # no simulated time has passed for it yet
            if shown.why is None:
                shown.why = why

    def forget(self, key: int) -> None:
        self._shown.pop(key, None)

    def answered(self, key: int, now: float, *, by: str, paused: bool,
                 speed: float) -> Response:
        """The offer ``key`` is answered at simulated time ``now`` by ``by`` (``person`` or
        ``model``), the clock being ``paused`` or at ``speed``."""
        shown = self._shown.pop(key, None)
        if shown is None:
            return Response(by, None, False, "never shown to the person")
        why = shown.why
        if why is None and by != "person":
            why = "performed by the user model"
        if why is None and paused:
            why = "the clock was paused"
        if why is None and speed != 1.0 and now > shown.time:
            why = f"the clock ran at {speed:g}x"
        return Response(by, max(0.0, self._clock() - shown.wall), why is None, why)
