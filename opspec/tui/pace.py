"""The pace the walkthrough's clock really keeps, for the status line.

The engine runs in slices between key presses (:mod:`opspec.tui.app`): a spec with many events
per simulated second (the vacuum cleaner's sensing loops) cannot be simulated at the speed
asked, and the clock falls behind it rather than leaving keys unread. The status line then
says so (``600x (really 83x)``) instead of claiming the speed asked.
"""

from __future__ import annotations

from collections import deque

__all__ = ["Pace"]

WINDOW_S = 2.0        # wall seconds of running measured before the pace is said
SHORT_OF = 0.9        # said when the clock keeps less than this share of the speed asked


class Pace:
    """Wall and simulated seconds of the last ticks the clock ran at a given speed."""

    def __init__(self) -> None:
        self._ticks: deque[tuple[float, float]] = deque()
        self._speed: float | None = None

    def ran(self, wall_s: float, sim_s: float, speed: float) -> None:
        """A tick ran the clock ``sim_s`` in ``wall_s`` at ``speed`` asked."""
        if speed != self._speed:
            self.reset()
            self._speed = speed
        self._ticks.append((wall_s, sim_s))
        while sum(w for w, _ in self._ticks) - self._ticks[0][0] >= WINDOW_S:
            self._ticks.popleft()

    def reset(self) -> None:
        """Paused, skipping, waiting for a device: what follows is measured afresh."""
        self._ticks.clear()
        self._speed = None

    def shown(self) -> str:
        """`` (really 83x)`` when the clock keeps well short of the speed asked, else ""."""
        wall = sum(w for w, _ in self._ticks)
        if self._speed is None or wall < WINDOW_S * SHORT_OF:
            return ""
        rate = sum(s for _, s in self._ticks) / wall
        return f" (really {rate:.3g}x)" if rate < self._speed * SHORT_OF else ""
