"""The room world's inner loop: the robot driving straight (or standing) between two device
operations, step by step.

Plain float arithmetic over plain fields, so that the compiled build (``opspec._native``)
compiles it with the engine: the same IEEE operations in the same order as from source, so
the same floats and the same traces either way (tests/engine/test_native_every_spec.py).
The loop stops and hands back to :class:`~opspec.worlds.room.RoomWorld` at the few steps that
need the world itself: one that may cover new cells (``COVER``) and the first step of a
contact (``COLLISION``), both traced there; it is then run again to go on.
"""

from __future__ import annotations

import math
from typing import Final

__all__ = ["COLLISION", "COVER", "DONE", "STEP_S", "Straight", "cover", "distance_ahead"]

#: integration step: 5 cm at 1 m/s, well under the robot's size
STEP_S: Final = 0.05

DONE: Final = 0          # reached the time asked for
COVER: Final = 1         # moved to where cells of ``key`` may still be uncovered
COLLISION: Final = 2     # a contact began at this step

Key = tuple[int, int, int, int]
Cells = tuple[tuple[int, int], ...]
#: a box as the range finder meets it: its sides, then the 1e-9 tolerance
#: ``ray_to_box_along`` puts around them (y0 - 1e-9, y1 + 1e-9, x0 - 1e-9, x1 + 1e-9)
RayBox = tuple[float, float, float, float, float, float, float, float]


class Straight:
    """The state of one straight drive: ``t`` the world's time, the robot's ``x``, ``y``
    and ``heading``; ``after`` is ``wrap_angle(heading)``, which the next step sets the
    heading to, and ``settled`` says it equals ``heading`` bit for bit (wrapping no longer
    changes it); ``in_contact`` and ``bumped`` as the room's. After a ``COVER`` or
    ``COLLISION`` stop, ``t_step`` is the time at that step's start (the world's time while
    it is handled) and ``key`` the cell range of the robot's reach."""

    def __init__(self, inside: tuple[float, float, float, float],
                 grown: list[tuple[float, float, float, float]], reach: float,
                 cell: float) -> None:
        self.x_lo = inside[0]
        self.x_hi = inside[1]
        self.y_lo = inside[2]
        self.y_hi = inside[3]
        self.grown = grown
        self.reach = reach
        self.cell = cell
        self.t = 0.0
        self.t_step = 0.0
        self.x = 0.0
        self.y = 0.0
        self.heading = 0.0
        self.after = 0.0
        self.settled = False
        self.in_contact = False
        self.bumped = False
        self.key: Key = (0, 0, 0, 0)

    def start(self, t: float, x: float, y: float, heading: float, after: float,
              settled: bool, in_contact: bool) -> None:
        self.t = t
        self.x = x
        self.y = y
        self.heading = heading
        self.after = after
        self.settled = settled
        self.in_contact = in_contact
        self.bumped = False

    def run(self, now: float, v: float, stop: bool, uncovered: dict[Key, Cells]) -> int:
        """Steps at speed ``v`` until ``now`` (``DONE``) or a step the world must see.
        ``uncovered``: the room's cells not yet covered per cell range (ranges not in it
        have not been looked at)."""
        limit = now - 1e-12
        t = self.t
        x = self.x
        y = self.y
        heading = self.heading
        after = self.after
        settled = self.settled
        in_contact = self.in_contact
        reach = self.reach
        cell = self.cell
        cos_h = math.cos(heading)
        sin_h = math.sin(heading)
        code = DONE
        while t < limit:
            rest = now - t
            dt = STEP_S if rest > STEP_S else rest      # min(STEP_S, now - t)
            nx = x + v * dt * cos_h
            ny = y + v * dt * sin_h
            if not settled:
                heading = after
                cos_h = math.cos(heading)
                sin_h = math.sin(heading)
                after = math.atan2(math.sin(heading), math.cos(heading))    # wrap_angle
                settled = after == heading and (
                    math.copysign(1.0, after) == math.copysign(1.0, heading))
            if nx == x and ny == y:
                if stop:
                    in_contact = False
                t += dt
                continue
            free = self.x_lo <= nx <= self.x_hi and self.y_lo <= ny <= self.y_hi
            if free:
                for gx0, gx1, gy0, gy1 in self.grown:
                    if gx0 <= nx <= gx1 and gy0 <= ny <= gy1:
                        free = False
                        break
            if free:
                x = nx
                y = ny
                in_contact = False
                key = (int((x - reach) // cell), int((x + reach) // cell),
                       int((y - reach) // cell), int((y + reach) // cell))
                cells = uncovered.get(key)
                if cells is None or len(cells) > 0:
                    self.key = key
                    code = COVER
            else:
                self.bumped = True
                if not in_contact:
                    in_contact = True
                    code = COLLISION
            if code != DONE:
                self.t_step = t
                t += dt
                break
            t += dt
        self.t = t
        self.x = x
        self.y = y
        self.heading = heading
        self.after = after
        self.settled = settled
        self.in_contact = in_contact
        return code


def distance_ahead(x: float, y: float, heading: float, boxes: tuple[RayBox, ...]) -> float:
    """``ray_to_box_along`` to the room's walls from inside (``boxes[0]``), then to each
    obstacle's faces from outside, the nearest of them: the same arithmetic in one loop (the
    range finder of :class:`~opspec.worlds.room.RoomWorld`)."""
    dx = math.cos(heading)
    dy = math.sin(heading)
    along_x = abs(dx) > 1e-12
    along_y = abs(dy) > 1e-12
    best = math.inf
    inside = True
    for x0, y0, x1, y1, y0_lo, y1_hi, x0_lo, x1_hi in boxes:
        if not inside and x0 <= x <= x1 and y0 <= y <= y1:
            best = 0.0 if 0.0 < best else best      # min(best, 0.0): touching an obstacle
            continue
        nearest = math.inf
        if along_x:
            t = (x0 - x) / dx
            if t > 1e-9 and y0_lo <= y + t * dy <= y1_hi and t < nearest:
                nearest = t
            t = (x1 - x) / dx
            if t > 1e-9 and y0_lo <= y + t * dy <= y1_hi and t < nearest:
                nearest = t
        if along_y:
            t = (y0 - y) / dy
            if t > 1e-9 and x0_lo <= x + t * dx <= x1_hi and t < nearest:
                nearest = t
            t = (y1 - y) / dy
            if t > 1e-9 and x0_lo <= x + t * dx <= x1_hi and t < nearest:
                nearest = t
        if inside:
            best = nearest
            inside = False
        elif nearest < best:
            best = nearest
    return best


def cover(cells: Cells, x: float, y: float, cell: float, reach: float,
          covered: set[tuple[int, int]]) -> tuple[list[tuple[int, int]], Cells]:
    """The robot at ``x``, ``y`` covers those of ``cells`` whose centre is within ``reach``
    plus half a cell: they are added to ``covered``; returned are the newly covered ones, in
    the order of ``cells`` (the room traces them in that order), and the ``cells`` still not
    covered."""
    limit = reach ** 2 + (cell / 2) ** 2
    new: list[tuple[int, int]] = []
    for c in cells:
        cx, cy = c
        centre_x = (cx + 0.5) * cell
        centre_y = (cy + 0.5) * cell
        if (centre_x - x) ** 2 + (centre_y - y) ** 2 <= limit and c not in covered:
            covered.add(c)
            new.append(c)
    return new, tuple([c for c in cells if c not in covered])
